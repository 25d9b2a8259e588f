#include "keyplace/eval/localization.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

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

namespace {

// `scans` when it is strictly increasing, else a sorted copy without repeats in `storage`.
const std::vector<int>& IncreasingScans(const std::vector<int>& scans, std::vector<int>& storage) {
  if (std::adjacent_find(scans.begin(), scans.end(), std::greater_equal<>()) == scans.end()) {
    return scans;
  }
  storage = scans;
  std::sort(storage.begin(), storage.end());
  storage.erase(std::unique(storage.begin(), storage.end()), storage.end());
  return storage;
}

}  // namespace

bool IsSelfMatch(SelfMatchRule rule, const std::vector<int>& query_scans,
                 const std::vector<int>& place_scans) {
  if (rule == SelfMatchRule::kNone) return false;
  std::vector<int> query_storage;
  std::vector<int> place_storage;
  const std::vector<int>& query = IncreasingScans(query_scans, query_storage);
  const std::vector<int>& place = IncreasingScans(place_scans, place_storage);
  if (rule == SelfMatchRule::kSameScans) return query == place;
  auto q = query.begin();
  auto p = place.begin();
  while (q != query.end() && p != place.end()) {
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
