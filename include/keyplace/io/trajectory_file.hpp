#pragma once
// Trajectories in the TUM RGB-D format (`timestamp tx ty tz qx qy qz qw`, one pose per line),
// which evo and most trajectory tools read.

#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// One pose of a trajectory: T_world_robot at a time.
struct TrajectoryPose {
  double timestamp_s = 0.0;
  Pose2 T_world_robot;
};

/// How a command writes a trajectory: keyplace's own TSV (its columns per command) or TUM.
enum class TrajectoryFormat { kTsv, kTum };

/// "tsv" or "tum"; std::invalid_argument naming the accepted names otherwise.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);

/// One TUM line without its newline: the planar pose at z = 0, its heading as the rotation about
/// z (qx = qy = 0, qz = sin(theta / 2), qw = cos(theta / 2)); every number in the shortest text
/// that reads back as the same double.
std::string TumLine(const TrajectoryPose& pose);

/// Writes `poses` as a TUM file (a `#` header line naming the columns, then one TumLine each),
/// atomically: a failure leaves `path` as it was and throws std::runtime_error naming it.
void WriteTumTrajectory(const std::string& path, const std::vector<TrajectoryPose>& poses);

}  // namespace keyplace
