#pragma once
// Trajectory accuracy: the relation metric of Kümmerle et al. (2009) and drift against corrected
// (SLAM-optimised) poses.

#include <cstddef>
#include <vector>

#include "keyplace/common/pose2.hpp"
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
};

struct RelationErrorItem {
  std::size_t relation_index = 0;  // into the relation vector
  double dt_s = 0.0;               // |t_b - t_a|
  bool local = false;
  PoseError error;
};

struct RelationErrorReport {
  std::size_t relations = 0;  // relations given
  std::size_t matched = 0;    // both stamps found in the trajectory
  std::size_t unmatched = 0;  // at least one stamp missing (not evaluated)
  // Trajectory poses whose timestamp key repeats an earlier one (the first one is used).
  std::size_t duplicate_timestamps = 0;
  ErrorStats all;
  ErrorStats local;
  ErrorStats loop;
  std::vector<RelationErrorItem> items;  // one per matched relation, in relation order
};

/// Kümmerle et al. (2009): for every relation (a, b) with true relative pose delta*, the
/// estimated delta = T_a^-1 T_b is compared with delta*. Timestamps are matched exactly by
/// TimestampKey (integer microseconds). Throws std::invalid_argument for a negative
/// local_max_dt_s.
RelationErrorReport EvaluateRelations(const std::vector<TimedPose>& trajectory,
                                      const std::vector<Relation>& relations,
                                      const RelationErrorConfig& config = {});

/// Drift of a trajectory against corrected poses, through raw -> corrected index pairs.
struct DriftReport {
  std::size_t pairs = 0;  // index pairs used
  // Relative pose error between consecutive corrected scans (pairs sorted by corrected index):
  // estimated vs corrected relative motion. Local drift per corrected step.
  ErrorStats consecutive;
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
