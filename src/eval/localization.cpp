#include "keyplace/eval/localization.hpp"

#include <algorithm>
#include <cmath>

namespace keyplace {

bool IsCorrectPose(const Pose2& estimate, const Pose2& truth, double max_translation_m,
                   double max_rotation_deg) {
  const double translation = std::hypot(estimate.x - truth.x, estimate.y - truth.y);
  const double rotation_deg = std::abs(WrapAngle(estimate.theta - truth.theta)) * 180.0 / M_PI;
  return translation <= max_translation_m && rotation_deg <= max_rotation_deg;
}

std::vector<PrPoint> PrecisionRecallCurve(const std::vector<RankedAnswer>& answers,
                                          std::size_t n_queries) {
  std::vector<const RankedAnswer*> ranked;
  for (const RankedAnswer& answer : answers) {
    if (answer.answered) ranked.push_back(&answer);
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const RankedAnswer* a, const RankedAnswer* b) {
    return a->score > b->score;
  });
  std::vector<PrPoint> curve;
  std::size_t accepted = 0;
  std::size_t correct = 0;
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    ++accepted;
    if (ranked[i]->correct) ++correct;
    if (i + 1 < ranked.size() && ranked[i + 1]->score == ranked[i]->score) continue;
    PrPoint point;
    point.threshold = ranked[i]->score;
    point.accepted = accepted;
    point.correct = correct;
    point.precision = static_cast<double>(correct) / static_cast<double>(accepted);
    point.recall =
        n_queries > 0 ? static_cast<double>(correct) / static_cast<double>(n_queries) : 0.0;
    curve.push_back(point);
  }
  return curve;
}

double PrecisionAtMaxRecall(const std::vector<PrPoint>& curve) {
  double max_recall = -1.0;
  double precision = 0.0;
  for (const PrPoint& point : curve) {
    if (point.recall > max_recall) {
      max_recall = point.recall;
      precision = point.precision;
    } else if (point.recall == max_recall) {
      precision = std::max(precision, point.precision);
    }
  }
  return precision;
}

double RecallAtPrecision(const std::vector<PrPoint>& curve, double min_precision) {
  double recall = 0.0;
  for (const PrPoint& point : curve) {
    if (point.precision >= min_precision) recall = std::max(recall, point.recall);
  }
  return recall;
}

}  // namespace keyplace

namespace keyplace {

bool IsSelfMatch(SelfMatchRule rule, std::vector<int> query_scans, std::vector<int> place_scans) {
  if (rule == SelfMatchRule::kNone) return false;
  std::sort(query_scans.begin(), query_scans.end());
  query_scans.erase(std::unique(query_scans.begin(), query_scans.end()), query_scans.end());
  std::sort(place_scans.begin(), place_scans.end());
  place_scans.erase(std::unique(place_scans.begin(), place_scans.end()), place_scans.end());
  if (rule == SelfMatchRule::kSameScans) return query_scans == place_scans;
  auto q = query_scans.begin();
  auto p = place_scans.begin();
  while (q != query_scans.end() && p != place_scans.end()) {
    if (*q == *p) return true;
    if (*q < *p) {
      ++q;
    } else {
      ++p;
    }
  }
  return false;
}

}  // namespace keyplace
