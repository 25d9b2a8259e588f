#include "keyplace/eval/slam_loop_evaluation.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "keyplace/eval/localization.hpp"
#include "keyplace/eval/loop_overlap.hpp"

namespace keyplace {
namespace {

double Deg(double rad) { return rad * 180.0 / M_PI; }

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

void CheckSubmap(int id, const GlobalMap& map) {
  if (id < 0 || static_cast<std::size_t>(id) >= map.submaps.size()) {
    throw std::invalid_argument("EvaluateLoops: loop names submap " + std::to_string(id) +
                                " of a map with " + std::to_string(map.submaps.size()));
  }
}

// The corrected pose of a submap's origin (its first scan), when known.
const PropagatedTruth* OriginTruth(const GlobalMap& map, int submap,
                                   const std::vector<std::optional<PropagatedTruth>>& truth) {
  const std::size_t scan = static_cast<std::size_t>(map.submaps[submap].first_scan());
  return scan < truth.size() && truth[scan] ? &*truth[scan] : nullptr;
}

// Sums of the per-loop errors that become the means of LoopEvaluation.
struct ErrorSums {
  std::vector<double> gaps, final_m, final_deg, ransac_m, ransac_deg;
};

void AddOverlaps(const LoopClosure& loop, bool used, const GlobalMap& map,
                 const ObservedAreaOf& observed_area, LoopEvaluation& e) {
  const OccupancySummary& ref = map.submaps[loop.reference_submap].occupancy;
  const OccupancySummary& cur = map.submaps[loop.query_submap].occupancy;
  e.overlap.push_back(OccupancyOverlap(ref, cur, loop.T_ref_cur));
  e.overlap_coarse.push_back(OccupancyOverlap(ref, cur, loop.T_ref_cur, 0.2));
  e.overlap_common.push_back(CommonAreaOverlap(ref, cur, observed_area(loop.reference_submap),
                                               observed_area(loop.query_submap), loop.T_ref_cur));
  // Diagnostic: the overlap before refinement and partner choice (matched submap, RANSAC).
  e.overlap_matched_ransac.push_back(
      OccupancyOverlap(map.submaps[loop.matched_submap].occupancy, cur, loop.T_matched_cur_ransac));
  e.used.push_back(used);
  if (used) {
    ++e.used_count;
    e.overlap_used.push_back(e.overlap.back());
  }
}

// Checks loop k (final transform and RANSAC estimate) against the corrected origin poses.
void CheckAgainstTruth(std::size_t k, const LoopClosure& loop, const GlobalMap& map,
                       const std::vector<std::optional<PropagatedTruth>>& truth_of_scan,
                       LoopEvaluation& e, ErrorSums& sums) {
  const PropagatedTruth* cur = OriginTruth(map, loop.query_submap, truth_of_scan);
  if (cur == nullptr) return;
  if (const PropagatedTruth* ref = OriginTruth(map, loop.reference_submap, truth_of_scan)) {
    const Pose2 truth = Between(ref->T_world_robot, cur->T_world_robot);
    const Pose2 error = Between(truth, loop.T_ref_cur);
    e.truth_error_m[k] = TranslationNorm(error);
    e.truth_error_deg[k] = std::abs(Deg(error.theta));
    e.truth[k] = IsCorrectPose(loop.T_ref_cur, truth) ? 1 : 0;  // 0.5 m, 10 deg (DESIGN.md)
    sums.gaps.push_back(ref->gap);
    sums.gaps.push_back(cur->gap);
    ++e.truth_evaluated;
    ++(e.truth[k] == 1 ? e.truth_correct : e.truth_wrong);
  }
  // The same check of place recognition's own estimate: the accuracy the refinement adds.
  if (const PropagatedTruth* matched = OriginTruth(map, loop.matched_submap, truth_of_scan)) {
    const Pose2 truth = Between(matched->T_world_robot, cur->T_world_robot);
    const Pose2 error = Between(truth, loop.T_matched_cur_ransac);
    e.truth_error_ransac_m[k] = TranslationNorm(error);
    e.truth_error_ransac_deg[k] = std::abs(Deg(error.theta));
    if (e.truth[k] >= 0) {
      sums.final_m.push_back(e.truth_error_m[k]);
      sums.final_deg.push_back(e.truth_error_deg[k]);
      sums.ransac_m.push_back(e.truth_error_ransac_m[k]);
      sums.ransac_deg.push_back(e.truth_error_ransac_deg[k]);
    }
  }
}

// Both overlap rates as tests of loop correctness, scored on the loops ground truth can check.
std::vector<OverlapTest> OverlapTests(const LoopEvaluation& e) {
  std::vector<OverlapTest> tests;
  for (double threshold : {0.1, 0.2, 0.3, 0.4, 0.5}) {
    OverlapTest test;
    test.threshold = threshold;
    for (std::size_t k = 0; k < e.truth.size(); ++k) {
      if (e.truth[k] < 0) continue;
      const bool correct = e.truth[k] == 1;
      if (e.overlap[k] >= threshold) ++(correct ? test.all_cells_correct : test.all_cells_wrong);
      if (e.overlap_common[k] >= threshold) ++(correct ? test.common_correct : test.common_wrong);
    }
    tests.push_back(test);
  }
  return tests;
}

}  // namespace

std::vector<std::optional<PropagatedTruth>> TruthOfEveryScan(
    const std::vector<OnlineSlam::ScanPose>& trajectory, const std::vector<int>& corrected_of,
    const std::vector<Pose2>& corrected_poses, int max_gap_scans) {
  std::vector<std::optional<PropagatedTruth>> truth_of_scan(corrected_of.size());
  if (corrected_poses.empty()) return truth_of_scan;
  std::vector<std::optional<Pose2>> corrected_in_order;
  std::vector<Pose2> icp_in_order;
  for (const OnlineSlam::ScanPose& pose : trajectory) {
    const int c = corrected_of.at(static_cast<std::size_t>(pose.scan_index));
    corrected_in_order.push_back(c >= 0 ? std::optional<Pose2>(corrected_poses.at(c))
                                        : std::nullopt);
    icp_in_order.push_back(pose.T_world_robot_icp);
  }
  const std::vector<std::optional<PropagatedTruth>> propagated =
      PropagateTruth(corrected_in_order, icp_in_order, max_gap_scans);
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    truth_of_scan[static_cast<std::size_t>(trajectory[k].scan_index)] = propagated[k];
  }
  return truth_of_scan;
}

LoopEvaluation EvaluateLoops(const std::vector<LoopClosure>& loops, const std::vector<bool>& used,
                             const GlobalMap& map, const ObservedAreaOf& observed_area,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan) {
  if (used.size() != loops.size()) {
    throw std::invalid_argument("EvaluateLoops: " + std::to_string(used.size()) +
                                " used flags for " + std::to_string(loops.size()) + " loops");
  }
  LoopEvaluation e;
  const std::size_t n = loops.size();
  e.truth.assign(n, -1);
  e.truth_error_m.assign(n, -1.0);
  e.truth_error_deg.assign(n, -1.0);
  e.truth_error_ransac_m.assign(n, -1.0);
  e.truth_error_ransac_deg.assign(n, -1.0);
  ErrorSums sums;
  for (std::size_t k = 0; k < n; ++k) {
    const LoopClosure& loop = loops[k];
    for (int id : {loop.query_submap, loop.reference_submap, loop.matched_submap}) {
      CheckSubmap(id, map);
    }
    AddOverlaps(loop, used[k], map, observed_area, e);
    CheckAgainstTruth(k, loop, map, truth_of_scan, e, sums);
  }
  e.truth_mean_gap_scans = Mean(sums.gaps);
  e.paired_loops = sums.final_m.size();
  e.paired_final_m = Mean(sums.final_m);
  e.paired_final_deg = Mean(sums.final_deg);
  e.paired_ransac_m = Mean(sums.ransac_m);
  e.paired_ransac_deg = Mean(sums.ransac_deg);
  e.overlap_tests = OverlapTests(e);
  return e;
}

LoopEvaluation EvaluateLoops(const OnlineSlam& slam, const GlobalMap& map,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan) {
  std::vector<bool> used;
  for (const LoopClosure& loop : slam.loops()) used.push_back(slam.LoopUsed(loop));
  return EvaluateLoops(
      slam.loops(), used, map,
      [&slam](int submap) -> const OccupancySummary& { return slam.ObservedArea(submap); },
      truth_of_scan);
}

}  // namespace keyplace
