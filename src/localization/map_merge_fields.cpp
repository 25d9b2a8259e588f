// The figures of MergeResult and SubmapRecognition (docs in keyplace/localization/map_merge.hpp).

#include "keyplace/localization/map_merge.hpp"

namespace keyplace {

const ResultFields<MergeResult>& MergeResultFields() {
  using R = MergeResult;
  static const ResultFields<R> fields = [] {
    ResultFields<R> table;
    table.Count("submaps_queried", &R::queried, "B submaps with keypoints, each recognised in A")
        .Add("recognised", "", "B submaps recognised in A (accepted answers)",
             [](const R& r) -> ResultValue { return CountValue(r.recognitions.size()); })
        .Count("agreeing", &R::agreeing, "recognitions in the largest group agreeing on T_a_b")
        .Add("submaps_merged", "", "submaps of the merged map (A's, then B's)",
             [](const R& r) -> ResultValue { return CountValue(r.merged.submaps.size()); });
    return table;
  }();
  return fields;
}

const ResultFields<SubmapRecognition>& SubmapRecognitionFields() {
  using R = SubmapRecognition;
  static const ResultFields<R> fields = [] {
    ResultFields<R> table;
    table.Integer("submap_b", &R::submap_b, "id of the B submap (in B)")
        .Integer("submap_a", &R::submap_a, "id of the A submap it matched")
        .Number("confidence", &R::confidence, "", "in [0, 1]")
        .Switch("agrees", &R::agrees,
                "in the largest agreeing group (the one the transform was fitted to)");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
