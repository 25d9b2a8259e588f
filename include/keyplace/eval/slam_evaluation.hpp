#pragma once
// A whole SLAM run on a log and its evaluation (paper Section 6.2.2): the loops by submap overlap
// (Figure 10) and against ground truth, the map (Table IX), RPE / ATE against corrected poses
// (Figures 11-12) and the errors of Kümmerle et al.'s relations, for SLAM and for its ICP
// odometry. `keyplace slam` prints and writes what these return.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/result_fields.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/grid_agreement.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/loop_overlap.hpp"
#include "keyplace/eval/relation_error.hpp"
#include "keyplace/eval/slam_loop_evaluation.hpp"
#include "keyplace/eval/trajectory_error.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

/// The order the scans are given to SLAM: by logger timestamp (stable, so equal stamps keep file
/// order; Intel's raw log is not in time order by its other stamps) or as the file lists them.
enum class ProcessingOrder { kLogger, kFile };

/// "logger" | "file"; throws std::invalid_argument naming the accepted values.
ProcessingOrder ParseProcessingOrder(const std::string& text);
std::string ToString(ProcessingOrder order);

/// The indices of `scans` in processing order.
std::vector<std::size_t> ProcessingSequence(const std::vector<LogScan>& scans,
                                            ProcessingOrder order);

/// A finished SLAM run on a log.
struct SlamRun {
  std::unique_ptr<OnlineSlam> slam;  // after Finish()
  // slam->map() with the log's provenance (source_log, source_hash, source_scans) and pose
  // source "slam"; `configuration` is left to the caller (it knows the whole Config).
  GlobalMap map;
  std::vector<OnlineSlam::ScanPose> trajectory;  // slam->Trajectory(): processing order
  ProcessingOrder order = ProcessingOrder::kLogger;
  std::size_t scans = 0;  // scans of the log given to SLAM
  // LogInputs::seconds_keypoints, or with keypoints_beside_slam the extraction's wall time, spent
  // while SLAM ran (part of seconds_slam then).
  double seconds_keypoints = 0.0;
  bool keypoints_beside_slam = false;
  double seconds_slam = 0.0;  // AddScan of every scan and Finish
};

/// Runs OnlineSlam over every scan of `inputs` (scan_index = index into inputs.log.scans; the
/// odometry pose of the log, inputs.keypoints) in `order`, then Finish(). With inputs.keypoints
/// empty the keypoints are extracted (FLIRT with `features`) on threads of their own while SLAM
/// runs, ahead of it in `order`: the same run, in the time of the slower of the two instead of
/// their sum. `progress` (done, total) is called after each scan. Throws std::invalid_argument
/// when the config is invalid or the inputs hold keypoints for other scans than theirs.
SlamRun RunSlamOnLog(const LogInputs& inputs, const SlamConfig& config, const FlirtConfig& features,
                     ProcessingOrder order, const ProgressCallback& progress = {});

/// The occupancy grid of the scans of `inputs` at the SLAM trajectory's final poses (`run` made
/// from `inputs`). Throws std::invalid_argument as BuildOccupancyGrid.
OccupancyGrid SlamOccupancyGrid(const SlamRun& run, const LogInputs& inputs,
                                const OccupancyGridConfig& config);

/// Loop precisions: the share of detected loops whose overlap is at least 10 % / 30 %.
struct LoopPrecisions {
  double overlap_10 = 0.0;  // all cells
  double overlap_30 = 0.0;
  double used_overlap_30 = 0.0;  // of the loops used in the final graph
  double cells_0_2m_10 = 0.0;    // on 0.2 m cells
  double cells_0_2m_30 = 0.0;
  double common_area_10 = 0.0;  // over the area both submaps observed
  double common_area_30 = 0.0;
  double matched_ransac_30 = 0.0;  // before refinement and partner choice
};

/// Accuracy of the trajectory against the ground-truth poses.
struct SlamAccuracy {
  std::size_t truth_pairs = 0;  // scans with a corrected pose
  AteSeries ate;                // SLAM, after SE(2) alignment
  AteSeries ate_icp;            // ICP odometry
  std::vector<RpePoint> rpe;    // SLAM, at SlamRpeDeltas()
};

/// The index intervals of the RPE curve (scans): 1, 2, 5, 10, ..., 2000.
std::vector<std::size_t> SlamRpeDeltas();

/// Points of the trajectory figure (paper Figure 10, left): with ground truth in its frame (the
/// estimate aligned by the ATE alignment), else in the SLAM frame.
struct SlamFigurePoints {
  std::vector<Eigen::Vector2d> estimated;   // paired scans with truth, else every scan
  std::vector<Eigen::Vector2d> truth;       // empty without truth
  std::vector<Eigen::Vector2d> loops_used;  // the query submap origin of every used loop
};

struct SlamEvaluation {
  LoopEvaluation loops;
  LoopPrecisions precision;
  OverlapHistogram histogram;         // of loops.overlap
  OverlapHistogram histogram_common;  // of loops.overlap_common
  // Loops whose overlap is below 1 % (the paper rejects such matches: minimal overlap 0.01).
  std::size_t loops_below_1_percent = 0;
  MappingStats mapping;  // of the SLAM map (Table IX)
  // Everything (keypoints, ICP, mapping, recognition, optimisation) per submap.
  double seconds_per_submap = 0.0;
  bool has_truth = false;
  int truth_max_gap_scans = 0;                       // EvaluationConfig::truth_max_gap_scans used
  std::optional<SlamAccuracy> accuracy;              // with ground truth
  std::optional<RelationErrorReport> relations;      // with relations: SLAM
  std::optional<RelationErrorReport> relations_icp;  // ... and ICP odometry
  SlamFigurePoints figure;
};

/// The figures of a run and of its evaluation: the keys of `keyplace slam --json` and the
/// properties of Python's SlamRun / SlamEvaluation. A loop precision is missing without loops, a
/// figure against ground truth without truth.
const ResultFields<SlamRun>& SlamRunFields();
const ResultFields<SlamEvaluation>& SlamEvaluationFields();

/// Evaluates `run`. `truth` (may be null): the ground truth of the log's scans (indexed like
/// inputs.log.scans); `relations` (may be null): relations to evaluate by timestamp.
SlamEvaluation EvaluateSlam(const SlamRun& run, const GroundTruth* truth,
                            const std::vector<Relation>* relations,
                            const EvaluationConfig& config = {});

/// The SLAM grid against the reference grid of the scans of `inputs` that have a truth pose, at
/// those poses, through the ATE alignment of `accuracy` (docs/NAVIGATION.md, "Checking the grid").
GridAgreement EvaluateSlamGrid(const OccupancyGrid& slam_grid, const LogInputs& inputs,
                               const GroundTruth& truth, const SlamAccuracy& accuracy,
                               const OccupancyGridConfig& config, double tolerance_m);

}  // namespace keyplace
