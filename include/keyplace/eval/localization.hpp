#pragma once
// Global-localization figures (paper Section 5.2, Eqs. 11-12, and Section 6.3): correctness of a
// pose estimate, precision / recall, and the precision-recall curve with P_GL and P_CL.

#include <cstddef>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// Correct when the translation error is <= max_translation_m and the rotation error is
/// <= max_rotation_deg (paper: 0.5 m and 10 deg).
bool IsCorrectPose(const Pose2& estimate, const Pose2& truth, double max_translation_m = 0.5,
                   double max_rotation_deg = 10.0);

/// One query's outcome for the curve: whether it produced an answer, whether the answer is
/// correct, and the score the answers are ranked by (higher = more trusted).
struct RankedAnswer {
  bool answered = false;
  bool correct = false;
  double score = 0.0;
};

struct PrPoint {
  double threshold = 0.0;  // answers with score >= threshold are accepted
  std::size_t accepted = 0;
  std::size_t correct = 0;
  double precision = 1.0;  // 1 when nothing is accepted
  double recall = 0.0;
};

/// The precision-recall curve over `n_queries` queries: one point per distinct score of the
/// answers, by decreasing score (ties enter together). Recall divides by `n_queries`.
std::vector<PrPoint> PrecisionRecallCurve(const std::vector<RankedAnswer>& answers,
                                          std::size_t n_queries);

/// P_GL: the precision at the maximum recall of the curve (the highest such precision).
double PrecisionAtMaxRecall(const std::vector<PrPoint>& curve);

/// P_CL: the highest recall among the points whose precision is >= min_precision (0 if none).
double RecallAtPrecision(const std::vector<PrPoint>& curve, double min_precision = 0.95);

}  // namespace keyplace

#include <vector>

namespace keyplace {

/// Which map places count as self-matches of a query (and are skipped). kSameScans: places built
/// from exactly the query's scans (the paper's rule, Section 5.2). kSharedScan: places sharing
/// any scan with the query (the honest variant). kNone: nothing is skipped.
enum class SelfMatchRule { kNone, kSameScans, kSharedScan };

/// `query_scans` and `place_scans` are scan indices of the same log (for raw queries: the
/// corrected indices of the query's scans that have one). Order and duplicates do not matter;
/// lists already increasing are read as they are (no copy: the check runs for every place of a
/// map, per query).
bool IsSelfMatch(SelfMatchRule rule, const std::vector<int>& query_scans,
                 const std::vector<int>& place_scans);

}  // namespace keyplace
