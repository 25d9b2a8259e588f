#include "keyplace/localization/log_relocalization.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

namespace keyplace {
namespace {

void CheckInputs(const LogInputs& inputs) {
  const std::size_t scans = inputs.log.scans.size();
  if (inputs.poses.size() != scans || inputs.keypoints.size() != scans) {
    throw std::invalid_argument(
        inputs.source_log + ": relocalizing needs a pose and keypoints for " + "each of its " +
        std::to_string(scans) + " scans (" + std::to_string(inputs.poses.size()) + " poses, " +
        std::to_string(inputs.keypoints.size()) + " keypoint sets)");
  }
}

}  // namespace

LogRelocalization RelocalizeLog(const GlobalMap& map, const LogInputs& inputs,
                                const LocalizerConfig& config,
                                const std::function<void(std::size_t, std::size_t)>& progress) {
  CheckInputs(inputs);
  Relocalizer relocalizer(map, config);
  LogRelocalization run;
  const std::size_t scans = inputs.log.scans.size();
  run.scans.reserve(scans);
  double odometry_m = 0.0;
  double seconds_sum = 0.0;
  for (std::size_t k = 0; k < scans; ++k) {
    if (k > 0) odometry_m += TranslationNorm(Between(inputs.poses[k - 1], inputs.poses[k]));
    const auto begin = std::chrono::steady_clock::now();
    const RelocalizationUpdate update =
        relocalizer.AddScan(inputs.log.scans[k], inputs.poses[k], inputs.keypoints[k]);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    RelocalizedScan scan;
    scan.scan = inputs.first_scan + k;
    scan.stamp_s = inputs.log.scans[k].timestamp_s;
    scan.odometry_m = odometry_m;
    scan.status = update.status;
    scan.new_fix = update.new_fix;
    scan.lost = update.lost;
    scan.answered = update.answer.has_value() || update.map_search_answer.has_value();
    if (update.status == FixStatus::kFixed) {
      scan.T_world_robot = update.T_world_robot;
      scan.confidence = update.confidence;
    }
    scan.update_seconds = seconds;
    if (update.new_fix) {
      ++run.fixes;
      if (!run.first_fix) {
        run.first_fix = k;
        run.first_fix_pose = InitialPoseOf(update);
      }
    }
    if (update.lost) ++run.losses;
    if (scan.answered) ++run.answers;
    seconds_sum += seconds;
    run.update_seconds_max = std::max(run.update_seconds_max, seconds);
    run.scans.push_back(scan);
    if (progress) progress(k + 1, scans);
  }
  if (scans > 0) run.update_seconds_mean = seconds_sum / static_cast<double>(scans);
  run.map_searches = relocalizer.map_search().searches();
  run.map_search_seconds = relocalizer.map_search().search_s();
  return run;
}

}  // namespace keyplace
