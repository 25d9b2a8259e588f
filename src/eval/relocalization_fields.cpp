// The figures of RelocalizationSummary (docs in keyplace/eval/relocalization.hpp).

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
        .Count("lost_signals", &S::lost_signals, "fixes given up (lost)")
        .Count("lost_on_correct_track", &S::lost_on_correct_track, "... while the fix was right")
        .Count("lost_on_wrong_track", &S::lost_on_wrong_track, "... while the fix was wrong");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
