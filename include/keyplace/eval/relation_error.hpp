#pragma once
// Trajectory accuracy: the relation metric of Kümmerle et al. (2009) and drift against corrected
// (SLAM-optimised) poses.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/io/relations.hpp"

namespace keyplace {

/// A robot pose of an evaluated trajectory, keyed by the scan's ipc timestamp.
struct TimedPose {
  double timestamp_s = 0.0;
  Pose2 pose;  // T_world_robot, any fixed world frame
};

/// Mean, standard deviation (population, divide by n) and maximum of a set of pose errors.
struct ErrorStats {
  std::size_t count = 0;
  double translation_mean_m = 0.0;
  double translation_std_m = 0.0;
  double translation_max_m = 0.0;
  double rotation_mean_deg = 0.0;
  double rotation_std_deg = 0.0;
  double rotation_max_deg = 0.0;
};

/// Accumulates errors into ErrorStats.
ErrorStats Summarize(const std::vector<double>& translation_errors_m,
                     const std::vector<double>& rotation_errors_deg);

/// The error of an estimated relative pose against the true one: epsilon = delta* ^-1 * delta;
/// translation = |t(epsilon)| (m, equal to |t(delta) - t(delta*)|), rotation = |wrap(theta)|.
struct PoseError {
  double translation_m = 0.0;
  double rotation_deg = 0.0;
};
PoseError RelativePoseError(const Pose2& estimated_T_a_b, const Pose2& true_T_a_b);

struct RelationErrorConfig {
  // Relations with |t_b - t_a| below this are "local", the others "loop" (s).
  double local_max_dt_s = 5.0;
  // A relation stamp matches the trajectory pose with the nearest stamp when they differ by at
  // most this (s): relation files written with 5 decimals (10 us) must match logs with 6.
  double stamp_tolerance_s = 1e-4;
  // No error is given (RelationErrorReport::refusal) when fewer than this fraction of the
  // relations inside the trajectory's time span matched: the file belongs to another log, or
  // its stamps were written differently.
  double min_matched_fraction = 0.95;
};

/// The relation settings of the evaluation section (evaluation.local_relation_max_dt_s, ...).
RelationErrorConfig RelationConfigFrom(const EvaluationConfig& config);

struct RelationErrorItem {
  std::size_t relation_index = 0;  // into the relation vector
  double dt_s = 0.0;               // |t_b - t_a|
  bool local = false;
  PoseError error;
};

struct RelationErrorReport {
  std::size_t relations = 0;         // relations given
  std::size_t trajectory_poses = 0;  // poses of the trajectory evaluated
  // Relations with a stamp outside the trajectory's first..last stamp (e.g. a slice of the log):
  // not evaluated, and not held against the matched fraction.
  std::size_t outside_span = 0;
  std::size_t matched = 0;    // both stamps matched a trajectory stamp
  std::size_t unmatched = 0;  // inside the span, at least one stamp unmatched (not evaluated)
  // Trajectory poses whose stamp equals an earlier one (the first one is used).
  std::size_t duplicate_timestamps = 0;
  // Why the errors below must not be reported (empty: they may): too few relations matched.
  // The statistics are still computed over the matched ones.
  std::string refusal;
  ErrorStats all;
  ErrorStats local;
  ErrorStats loop;
  std::vector<RelationErrorItem> items;  // one per matched relation, in relation order
};

/// Kümmerle et al. (2009): for every relation (a, b) with true relative pose delta*, the
/// estimated delta = T_a^-1 T_b is compared with delta*. Each relation stamp is matched to the
/// trajectory pose with the nearest stamp, within config.stamp_tolerance_s (ties and repeated
/// stamps: the earlier pose). Throws std::invalid_argument naming an invalid config field.
RelationErrorReport EvaluateRelations(const std::vector<TimedPose>& trajectory,
                                      const std::vector<Relation>& relations,
                                      const RelationErrorConfig& config = {});

/// Steps of the window of DriftReport::window_heading_max_deg.
inline constexpr std::size_t kDriftWindowSteps = 5;

/// Drift of a trajectory against corrected poses, through raw -> corrected index pairs.
struct DriftReport {
  std::size_t pairs = 0;  // index pairs used
  // Relative pose error between consecutive corrected scans (pairs sorted by corrected index):
  // estimated vs corrected relative motion. Local drift per corrected step.
  ErrorStats consecutive;
  // The worst heading error of the relative motion across kDriftWindowSteps consecutive steps
  // (a lost turn shows here even when the next scans register well again), and the raw index of
  // the window's first scan; nullopt with kDriftWindowSteps pairs or fewer.
  std::optional<double> window_heading_max_deg;
  std::size_t window_start_raw_index = 0;
  // Absolute trajectory error after the least-squares SE(2) alignment (no scale) of the
  // estimated positions onto the corrected positions.
  double ate_rmse_m = 0.0;
  double ate_mean_m = 0.0;
  double ate_max_m = 0.0;
  double ate_rotation_rmse_deg = 0.0;
  Pose2 T_corrected_estimate;  // the alignment
};

/// `estimate_by_raw_index[i]` is the estimated robot pose of raw scan i (file order),
/// `corrected_by_corrected_index[j]` the corrected robot pose of corrected scan j. Throws
/// std::invalid_argument naming raw_index / corrected_index when a pair is out of range.
DriftReport EvaluateDrift(const std::vector<Pose2>& estimate_by_raw_index,
                          const std::vector<Pose2>& corrected_by_corrected_index,
                          const std::vector<IndexPair>& pairs);

}  // namespace keyplace
