#pragma once
// The loop evaluation of a SLAM run (docs/SLAM.md, "Evaluation choices"): every detected loop's
// overlap rates and its check against ground truth, and their aggregates.

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/eval/truth_propagation.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/submap.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

/// A corrected pose for every scan (indexed by scan_index, `corrected_of.size()` entries) that
/// lies within `max_gap_scans` (processing order, the order of `trajectory`) of a scan with one:
/// `corrected_of[scan_index]` is the index into `corrected_poses` or -1; the ICP poses of
/// `trajectory` carry the pose over the gap (PropagateTruth). All nullopt when `corrected_poses`
/// is empty.
std::vector<std::optional<PropagatedTruth>> TruthOfEveryScan(
    const std::vector<OnlineSlam::ScanPose>& trajectory, const std::vector<int>& corrected_of,
    const std::vector<Pose2>& corrected_poses, int max_gap_scans);

/// How many correct and wrong loops (by ground truth) each overlap rate passes at a threshold.
struct OverlapTest {
  double threshold = 0.0;
  std::size_t all_cells_correct = 0;
  std::size_t all_cells_wrong = 0;
  std::size_t common_correct = 0;
  std::size_t common_wrong = 0;
};

struct LoopEvaluation {
  // One entry per loop, in the order of the loops evaluated (OnlineSlam::loops()).
  std::vector<double> overlap;                         // all cells, loop partner, final T_ref_cur
  std::vector<double> overlap_coarse;                  // the same on 0.2 m cells
  std::vector<double> overlap_common;                  // over the area both submaps observed
  std::vector<double> overlap_matched_ransac;          // all cells, matched submap, RANSAC estimate
  std::vector<int> truth;                              // -1 not checkable, 0 wrong, 1 correct
  std::vector<double> truth_error_m, truth_error_deg;  // -1 when not checkable
  std::vector<double> truth_error_ransac_m, truth_error_ransac_deg;  // -1 when not checkable
  std::vector<bool> used;                                            // in the final graph

  std::vector<double> overlap_used;  // `overlap` of the loops used in the final graph
  std::size_t used_count = 0;
  std::size_t truth_evaluated = 0;
  std::size_t truth_correct = 0;
  std::size_t truth_wrong = 0;
  double truth_mean_gap_scans = 0.0;  // of the checked origins to their corrected scans
  // Means over the loops where both the final loop and the RANSAC estimate can be checked.
  std::size_t paired_loops = 0;
  double paired_final_m = 0.0, paired_final_deg = 0.0;
  double paired_ransac_m = 0.0, paired_ransac_deg = 0.0;
  std::vector<OverlapTest> overlap_tests;  // thresholds 0.1, 0.2, ..., 0.5

  double precision_truth() const {
    return truth_evaluated > 0 ? static_cast<double>(truth_correct) / truth_evaluated : 0.0;
  }
};

/// The observed area of a submap by id (OnlineSlam::ObservedArea).
using ObservedAreaOf = std::function<const OccupancySummary&(int submap)>;

/// Evaluates `loops` on the submaps of `map`: overlaps of the partner (all cells, 0.2 m cells,
/// common observed area) and of the matched submap under the RANSAC estimate; with a corrected
/// pose for both submap origins (their first scans, `truth_of_scan` indexed by scan index), the
/// loop transform's error and correctness (IsCorrectPose: 0.5 m, 10 deg). `used[k]`: loop k is
/// an enabled edge of the final graph. `truth_of_scan` empty or without poses leaves the
/// ground-truth fields at -1 / 0. Throws std::invalid_argument when `used` and `loops` differ in
/// size or a loop names a submap outside `map`.
LoopEvaluation EvaluateLoops(const std::vector<LoopClosure>& loops, const std::vector<bool>& used,
                             const GlobalMap& map, const ObservedAreaOf& observed_area,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan);

/// The same for every loop of `slam`, on `map` (its submaps, as slam.map()).
LoopEvaluation EvaluateLoops(const OnlineSlam& slam, const GlobalMap& map,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan);

}  // namespace keyplace
