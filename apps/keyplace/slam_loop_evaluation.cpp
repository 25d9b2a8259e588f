#include "slam_loop_evaluation.hpp"

#include <cmath>
#include <numeric>
#include <ostream>

#include <fmt/core.h>

#include "keyplace/eval/localization.hpp"
#include "keyplace/eval/loop_overlap.hpp"
#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

double Deg(double rad) { return rad * 180.0 / M_PI; }

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
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
    const int c = corrected_of[pose.scan_index];
    corrected_in_order.push_back(c >= 0 ? std::optional<Pose2>(corrected_poses[c]) : std::nullopt);
    icp_in_order.push_back(pose.T_world_robot_icp);
  }
  const std::vector<std::optional<PropagatedTruth>> propagated =
      PropagateTruth(corrected_in_order, icp_in_order, max_gap_scans);
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    truth_of_scan[trajectory[k].scan_index] = propagated[k];
  }
  return truth_of_scan;
}

LoopEvaluation EvaluateLoops(const OnlineSlam& slam, const GlobalMap& map,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan) {
  const std::vector<LoopClosure>& loops = slam.loops();
  LoopEvaluation e;
  const std::size_t n = loops.size();
  e.truth.assign(n, -1);
  e.truth_error_m.assign(n, -1.0);
  e.truth_error_deg.assign(n, -1.0);
  e.truth_error_ransac_m.assign(n, -1.0);
  e.truth_error_ransac_deg.assign(n, -1.0);

  // The corrected pose of a submap's origin (its first scan), when known.
  auto origin_truth = [&](int submap) -> const std::optional<PropagatedTruth>* {
    const std::size_t scan = static_cast<std::size_t>(map.submaps[submap].first_scan());
    return scan < truth_of_scan.size() && truth_of_scan[scan] ? &truth_of_scan[scan] : nullptr;
  };
  // The corrected relative pose of two submap origins, when both are known.
  auto truth_between = [&](int ref_id, int cur_id) -> std::optional<Pose2> {
    const auto* ref = origin_truth(ref_id);
    const auto* cur = origin_truth(cur_id);
    if (ref == nullptr || cur == nullptr) return std::nullopt;
    return Between((*ref)->T_world_robot, (*cur)->T_world_robot);
  };

  std::vector<double> gaps, paired_final_m, paired_final_deg, paired_ransac_m, paired_ransac_deg;
  for (std::size_t k = 0; k < n; ++k) {
    const LoopClosure& loop = loops[k];
    const OccupancySummary& ref = map.submaps[loop.reference_submap].occupancy;
    const OccupancySummary& cur = map.submaps[loop.query_submap].occupancy;
    e.overlap.push_back(OccupancyOverlap(ref, cur, loop.T_ref_cur));
    e.overlap_coarse.push_back(OccupancyOverlap(ref, cur, loop.T_ref_cur, 0.2));
    e.overlap_common.push_back(CommonAreaOverlap(ref, cur, slam.ObservedArea(loop.reference_submap),
                                                 slam.ObservedArea(loop.query_submap),
                                                 loop.T_ref_cur));
    // Diagnostic: the overlap before refinement and partner choice (matched submap, RANSAC).
    e.overlap_matched_ransac.push_back(OccupancyOverlap(map.submaps[loop.matched_submap].occupancy,
                                                        cur, loop.T_matched_cur_ransac));
    if (slam.LoopUsed(loop)) {
      ++e.used;
      e.overlap_used.push_back(e.overlap.back());
    }

    if (const auto truth = truth_between(loop.reference_submap, loop.query_submap)) {
      const Pose2 error = Between(*truth, loop.T_ref_cur);
      e.truth_error_m[k] = TranslationNorm(error);
      e.truth_error_deg[k] = std::abs(Deg(error.theta));
      e.truth[k] = IsCorrectPose(loop.T_ref_cur, *truth) ? 1 : 0;  // 0.5 m, 10 deg (DESIGN.md)
      gaps.push_back((*origin_truth(loop.reference_submap))->gap);
      gaps.push_back((*origin_truth(loop.query_submap))->gap);
      ++e.truth_evaluated;
      ++(e.truth[k] == 1 ? e.truth_correct : e.truth_wrong);
    }
    // The same check of place recognition's own estimate: the accuracy the refinement adds.
    if (const auto truth = truth_between(loop.matched_submap, loop.query_submap)) {
      const Pose2 error = Between(*truth, loop.T_matched_cur_ransac);
      e.truth_error_ransac_m[k] = TranslationNorm(error);
      e.truth_error_ransac_deg[k] = std::abs(Deg(error.theta));
      if (e.truth[k] >= 0) {
        paired_final_m.push_back(e.truth_error_m[k]);
        paired_final_deg.push_back(e.truth_error_deg[k]);
        paired_ransac_m.push_back(e.truth_error_ransac_m[k]);
        paired_ransac_deg.push_back(e.truth_error_ransac_deg[k]);
      }
    }
  }
  e.truth_mean_gap_scans = Mean(gaps);
  e.paired_loops = paired_final_m.size();
  e.paired_final_m = Mean(paired_final_m);
  e.paired_final_deg = Mean(paired_final_deg);
  e.paired_ransac_m = Mean(paired_ransac_m);
  e.paired_ransac_deg = Mean(paired_ransac_deg);

  // Both overlap rates as tests of loop correctness, scored on the loops ground truth can check.
  for (double threshold : {0.1, 0.2, 0.3, 0.4, 0.5}) {
    OverlapTest test;
    test.threshold = threshold;
    for (std::size_t k = 0; k < n; ++k) {
      if (e.truth[k] < 0) continue;
      const bool correct = e.truth[k] == 1;
      if (e.overlap[k] >= threshold) ++(correct ? test.all_cells_correct : test.all_cells_wrong);
      if (e.overlap_common[k] >= threshold) ++(correct ? test.common_correct : test.common_wrong);
    }
    e.overlap_tests.push_back(test);
  }
  return e;
}

void WriteLoopsTsv(const std::string& path, const OnlineSlam& slam, const GlobalMap& map,
                   const LoopEvaluation& e) {
  const std::vector<LoopClosure>& loops = slam.loops();
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "query_submap\tquery_first_scan\treference_submap\treference_first_scan\tx_m\ty_m\t"
           "theta_rad\tpairs\tconsensus\tgamma\tconfidence\toverlap\toverlap_0_2m\t"
           "path_between_m\tgate_m\tgate_deg\taccepted\tused\ttruth_correct\ttruth_error_m\t"
           "matched_submap\tref_x_m\tref_y_m\tref_theta_rad\toverlap_matched_ransac\trefined\t"
           "refine_correction_m\trefine_correction_deg\tinlier_ratio_initial\tinlier_ratio\t"
           "point_overlap\trefine_status\ttruth_error_deg\ttruth_error_ransac_m\t"
           "truth_error_ransac_deg\toverlap_common\n";
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const LoopClosure& l = loops[k];
      out << fmt::format(
          "{}\t{}\t{}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{}\t{:.4f}\t{:.4f}\t{:.4f}\t{:.4f}\t"
          "{:.2f}\t{:.3f}\t{:.2f}\t{}\t{}\t{}\t{:.3f}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.4f}\t{}\t"
          "{:.4f}\t{:.3f}\t{:.4f}\t{:.4f}\t{:.4f}\t{}\t{:.3f}\t{:.3f}\t{:.3f}\t{:.4f}\n",
          l.query_submap, map.submaps[l.query_submap].first_scan(), l.reference_submap,
          map.submaps[l.reference_submap].first_scan(), l.T_ref_cur.x, l.T_ref_cur.y,
          l.T_ref_cur.theta, l.pairs, l.consensus, l.gamma, l.confidence, e.overlap[k],
          e.overlap_coarse[k], l.path_between_m, l.gate_translation_m, Deg(l.gate_rotation_rad),
          l.accepted ? 1 : 0, slam.LoopUsed(l) ? 1 : 0, e.truth[k], e.truth_error_m[k],
          l.matched_submap, l.T_matched_cur_ransac.x, l.T_matched_cur_ransac.y,
          l.T_matched_cur_ransac.theta, e.overlap_matched_ransac[k], l.refined ? 1 : 0,
          l.refine_correction_m, Deg(l.refine_correction_rad), l.refine_inlier_ratio_initial,
          l.refine_inlier_ratio, l.point_overlap, ToString(l.refine_status), e.truth_error_deg[k],
          e.truth_error_ransac_m[k], e.truth_error_ransac_deg[k], e.overlap_common[k]);
    }
  });
}

}  // namespace keyplace::cli
