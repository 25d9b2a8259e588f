#pragma once
// Ground truth for scans the corrected log leaves out. A raw log has many more scans than its
// corrected counterpart (FR101: 4758 against 292), so most submaps of a raw log hold no scan with
// a corrected pose. A scan a few positions away from one that has it gets that pose moved by the
// odometry between the two, which over a few scans is accurate to centimetres — far below the
// 0.5 m / 10 deg at which a loop counts as wrong.

#include <optional>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct PropagatedTruth {
  Pose2 T_world_robot;  // in the frame of the corrected poses
  int source = -1;      // position of the scan whose corrected pose it comes from
  int gap = 0;          // |source - position|: 0 when the scan has a corrected pose itself
};

/// For every position k of a scan sequence (processing order): the corrected pose of the nearest
/// position n with |n - k| <= `max_gap` that has one (`corrected[n]`), moved by the odometry:
/// corrected[n] * Between(odometry[n], odometry[k]). The earlier position wins a tie; nullopt
/// when none is that close. Throws std::invalid_argument when the two vectors differ in length or
/// `max_gap` is negative.
std::vector<std::optional<PropagatedTruth>> PropagateTruth(
    const std::vector<std::optional<Pose2>>& corrected, const std::vector<Pose2>& odometry,
    int max_gap);

}  // namespace keyplace
