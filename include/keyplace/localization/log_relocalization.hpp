#pragma once
// A log or bag relocalized as a robot would be, without ground truth: the Relocalizer is fed every
// scan with its odometry pose from the first to the last, and what it said at each scan is kept
// (status, pose, confidence), with the first fix as the /initialpose a robot would publish. This
// is `keyplace relocalize` on a log without corrected poses or --truth; the benchmark with truth
// is eval/relocalization.hpp.

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace {

/// What the Relocalizer said at one scan.
struct RelocalizedScan {
  std::size_t scan = 0;  // index in the log file
  double stamp_s = 0.0;
  double odometry_m = 0.0;  // odometry path from the first scan fed
  FixStatus status = FixStatus::kSearching;
  bool new_fix = false;
  bool lost = false;
  bool answered = false;  // an answer came with this scan (a query's, found or not, or a search's)
  Pose2 T_world_robot;    // valid when status is kFixed
  double confidence = 0.0;
  double update_seconds = 0.0;  // wall time of the Relocalizer's AddScan
};

struct LogRelocalization {
  std::vector<RelocalizedScan> scans;  // one per scan of the inputs, in their order
  // The index in `scans` of the first fix, and the fix as /initialpose (map frame "map").
  std::optional<std::size_t> first_fix;
  std::optional<InitialPose> first_fix_pose;
  std::size_t fixes = 0;   // fixes declared (the first and new ones after a loss)
  std::size_t losses = 0;  // fixes given up
  std::size_t answers = 0;
  double update_seconds_mean = 0.0;
  double update_seconds_max = 0.0;
  // Searches of the whole map run within the updates, and the time they took (part of theirs).
  long long map_searches = 0;
  double map_search_seconds = 0.0;
};

/// Feeds every scan of `inputs` (its poses are the odometry, its keypoints the scans') to a
/// Relocalizer of `map` built with `config`; `progress(done, total)` after each scan. Throws
/// std::invalid_argument when the inputs have no poses or keypoints for their scans, or for an
/// invalid config (naming the field).
LogRelocalization RelocalizeLog(const GlobalMap& map, const LogInputs& inputs,
                                const LocalizerConfig& config,
                                const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace keyplace
