// The figures of RelocalizationSummary, StartRecord and FixEvent (docs in
// keyplace/eval/relocalization.hpp).

#include <cmath>

#include "keyplace/eval/relocalization.hpp"

namespace keyplace {

const ResultFields<RelocalizationSummary>& RelocalizationSummaryFields() {
  using S = RelocalizationSummary;
  static const ResultFields<S> fields = [] {
    ResultFields<S> table;
    table.Count("starts", &S::starts, "starts run (capped to the scans with a truth pose)")
        .Count("starts_with_revisit", &S::starts_with_revisit,
               "starts whose path passes a map scan the localizer may match before giving up")
        .Count("fixed", &S::fixed, "starts with a first fix")
        .Count("fixed_with_revisit", &S::fixed_with_revisit, "... of the starts with a revisit")
        .Number("fixed_fraction", &S::fixed_fraction, "",
                "fixed_with_revisit / starts_with_revisit")
        .Count("starts_with_room", &S::starts_with_room,
               "starts with a revisit and at least revisit_room_m of path left after it")
        .Count("fixed_with_room", &S::fixed_with_room, "... of them with a first fix")
        .Number("fixed_fraction_with_room", &S::fixed_fraction_with_room, "",
                "fixed_with_room / starts_with_room")
        .Count("fixes", &S::fixes, "fixes reported and checked")
        .Count("wrong_fixes", &S::wrong_fixes, "fixes more than 0.5 m or 10 deg off the truth")
        .Number("wrong_fix_rate", &S::wrong_fix_rate, "", "wrong_fixes / fixes")
        .Count("wrong_first_fixes", &S::wrong_first_fixes, "starts whose first fix was wrong")
        .Switch("wrong_fix_confident", &S::wrong_fix_confident,
                "a wrong fix had a confidence at or above the confident bar")
        .Number("wrong_fix_confidence_max", &S::wrong_fix_confidence_max, "",
                "highest confidence of a wrong fix (0 without one)")
        .Number("distance_to_fix_median_m", &S::distance_to_fix_median_m, "m",
                "odometry distance from the start to its first fix, median over fixed starts")
        .Number("distance_to_fix_p90_m", &S::distance_to_fix_p90_m, "m", "... 90th percentile")
        .Number("scans_to_fix_median", &S::scans_to_fix_median, "",
                "scans from the start to its first fix, median")
        .Number("distance_after_revisit_median_m", &S::distance_after_revisit_median_m, "m",
                "from the first scan the map has seen to the first fix, median")
        .Number("distance_after_revisit_p90_m", &S::distance_after_revisit_p90_m, "m",
                "... 90th percentile")
        .Number("update_seconds_mean", &S::update_seconds_mean, "s",
                "time of one update (AddScan with keypoints given), mean")
        .Number("update_seconds_max", &S::update_seconds_max, "s", "... maximum")
        .Count("map_searches", &S::map_searches, "searches of the whole map run in the updates")
        .Number("map_search_seconds_mean", &S::map_search_seconds_mean, "s",
                "time of one search of the whole map, mean")
        .Number("update_seconds_mean_without_search", &S::update_seconds_mean_without_search, "s",
                "time of one update without the searches of the whole map, mean (a robot's "
                "node runs them on a thread of their own)")
        .Count("lost_signals", &S::lost_signals, "fixes given up (lost)")
        .Count("lost_on_correct_track", &S::lost_on_correct_track, "... while the fix was right")
        .Count("lost_on_wrong_track", &S::lost_on_wrong_track, "... while the fix was wrong");
    return table;
  }();
  return fields;
}

const ResultFields<StartRecord>& StartRecordFields() {
  using R = StartRecord;
  static const ResultFields<R> fields = [] {
    ResultFields<R> table;
    table.Integer("start_scan", &R::start_scan, "query-log scan the start began at")
        .Integer("end_scan", &R::end_scan, "one past the last scan fed")
        .Switch("revisit", &R::revisit,
                "its path before the cap passes a map scan the localizer may match")
        .Number("distance_to_revisit_m", &R::distance_to_revisit_m, "m",
                "odometry distance to the first such scan")
        .Number("room_after_revisit_m", &R::room_after_revisit_m, "m",
                "odometry distance from that scan to where the start stops without a fix")
        .Switch("fixed", &R::fixed, "the relocalizer reported a fix")
        .Integer("scans_to_fix", &R::scans_to_fix, "scans fed up to and including the first fix")
        .Number("distance_to_fix_m", &R::distance_to_fix_m, "m",
                "odometry distance from the start to the first fix")
        .Switch("first_fix_checked", &R::first_fix_checked,
                "a truth pose was near enough to check the first fix")
        .Switch("first_fix_correct", &R::first_fix_correct,
                "the first fix was within 0.5 m and 10 deg of the truth")
        .Integer("answers", &R::answers, "queries answered")
        .Integer("answers_accepted", &R::answers_accepted,
                 "... of them accepted by the place recognizer")
        .Integer("answers_weak", &R::answers_weak, "... of them not accepted but weak")
        .Add("fixes_reported", "", "fixes reported (the list is `fixes`)",
             [](const R& r) -> ResultValue { return CountValue(r.fixes.size()); })
        .Integer("wrong_fixes", &R::wrong_fixes, "fixes more than 0.5 m or 10 deg off the truth")
        .Integer("lost", &R::lost, "'lost' signals")
        .Integer("lost_on_correct_track", &R::lost_on_correct_track, "... while the fix was right")
        .Integer("lost_on_wrong_track", &R::lost_on_wrong_track, "... while the fix was wrong")
        .Number("update_seconds_mean", &R::update_seconds_mean, "s",
                "time of one update (AddScan with keypoints given), mean")
        .Number("update_seconds_max", &R::update_seconds_max, "s", "... maximum")
        .Integer("map_searches", &R::map_searches, "searches of the whole map run in the updates")
        .Number("map_search_seconds", &R::map_search_seconds, "s", "... the time they took");
    return table;
  }();
  return fields;
}

const ResultFields<FixEvent>& FixEventFields() {
  using R = FixEvent;
  static const ResultFields<R> fields = [] {
    ResultFields<R> table;
    table.Integer("scan", &R::scan, "query-log scan the fix was reported at")
        .Integer("checked_scan", &R::checked_scan,
                 "the scan it was checked at (the nearest with a truth pose)")
        .Switch("first", &R::first, "the start's first fix")
        .Switch("correct", &R::correct, "within 0.5 m and 10 deg of the truth")
        .Number("confidence", &R::confidence, "", "in [0, 1]")
        .Add("error_m", "m", "distance from the truth at checked_scan",
             [](const R& f) -> ResultValue {
               return TranslationNorm(Between(f.truth, f.T_world_robot));
             })
        .Add("error_deg", "deg", "heading error at checked_scan", [](const R& f) -> ResultValue {
          return std::abs(Between(f.truth, f.T_world_robot).theta) * 180.0 / M_PI;
        });
    return table;
  }();
  return fields;
}

}  // namespace keyplace
