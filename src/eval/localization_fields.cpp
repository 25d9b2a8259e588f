// The figures of LocalizationSummary (docs in keyplace/eval/global_localization.hpp).

#include "keyplace/eval/global_localization.hpp"

namespace keyplace {

const ResultFields<LocalizationSummary>& LocalizationSummaryFields() {
  using S = LocalizationSummary;
  static const ResultFields<S> fields = [] {
    ResultFields<S> table;
    table.Count("n_pos", &S::n_pos, "queries evaluated")
        .Count("n_acc", &S::n_acc, "accepted answers")
        .Count("n_cor", &S::n_cor, "correct accepted answers (within the evaluation thresholds)")
        .Count("n_verified", &S::n_verified, "queries with a verified candidate")
        .Count("n_ambiguous", &S::n_ambiguous,
               "queries refused as ambiguous (two places verified, far apart)")
        .Count("n_ambiguous_wrong", &S::n_ambiguous_wrong,
               "... whose best candidate would have been wrong")
        .Number("precision", &S::precision, "", "n_cor / n_acc (0 when nothing was accepted)")
        .Number("recall", &S::recall, "", "n_cor / n_pos")
        .Count("n_revisitable", &S::n_revisitable, "queries whose place the map has seen")
        .Count("n_cor_revisitable", &S::n_cor_revisitable, "... answered correctly")
        .Number("recall_revisitable", &S::recall_revisitable, "",
                "n_cor_revisitable / n_revisitable")
        .Number("scans_mean", &S::scans_mean, "", "mean scans of the correctly answered queries")
        .Number("scans_mean_all_queries", &S::scans_mean_all_queries, "",
                "mean scans of all queries")
        .Number("seconds_per_query_mean", &S::seconds_per_query_mean, "s",
                "mean recognition time per query")
        .Number("seconds_submap_building_mean", &S::seconds_submap_building_mean, "s",
                "mean time to build a query submap")
        .Add("rank_by", "", "what the curve ranks the answers by",
             [](const S& summary) -> ResultValue { return ToString(summary.rank_by); })
        .Number("p_gl", &S::p_gl, "", "precision at the maximum recall of the curve")
        .Number("p_cl", &S::p_cl, "", "highest recall at precision >= 0.95");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
