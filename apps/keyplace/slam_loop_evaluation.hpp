#pragma once
// The loop evaluation of `keyplace slam`: every detected loop's overlap rates and its check
// against ground truth, their aggregates, and the loops TSV (docs/SLAM.md, "Evaluation choices").

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/eval/truth_propagation.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace::cli {

/// A corrected pose for every scan of the log (indexed by file index) that lies within
/// `max_gap_scans` (processing order) of a scan with one: `corrected_of[file index]` is the index
/// into `corrected_poses` or -1; the ICP poses of `trajectory` carry the pose over the gap.
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
  // One entry per loop, in the order of OnlineSlam::loops().
  std::vector<double> overlap;                         // all cells, loop partner, final T_ref_cur
  std::vector<double> overlap_coarse;                  // the same on 0.2 m cells
  std::vector<double> overlap_common;                  // over the area both submaps observed
  std::vector<double> overlap_matched_ransac;          // all cells, matched submap, RANSAC estimate
  std::vector<int> truth;                              // -1 not checkable, 0 wrong, 1 correct
  std::vector<double> truth_error_m, truth_error_deg;  // -1 when not checkable
  std::vector<double> truth_error_ransac_m, truth_error_ransac_deg;  // -1 when not checkable

  std::vector<double> overlap_used;  // `overlap` of the loops used in the final graph
  std::size_t used = 0;
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

/// Evaluates every loop of `slam` on `map` (its submaps, as slam.map()); `truth_of_scan` empty
/// or with no pose leaves the ground-truth fields at -1 / 0.
LoopEvaluation EvaluateLoops(const OnlineSlam& slam, const GlobalMap& map,
                             const std::vector<std::optional<PropagatedTruth>>& truth_of_scan);

/// One TSV row per loop under a header naming the columns; written atomically.
void WriteLoopsTsv(const std::string& path, const OnlineSlam& slam, const GlobalMap& map,
                   const LoopEvaluation& evaluation);

}  // namespace keyplace::cli
