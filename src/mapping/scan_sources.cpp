#include "keyplace/mapping/scan_sources.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

namespace keyplace {

PoseSource ParsePoseSource(const std::string& text) {
  if (text == "corrected") return PoseSource::kCorrected;
  if (text == "odometry") return PoseSource::kOdometry;
  if (text == "icp") return PoseSource::kIcp;
  throw std::invalid_argument("pose source '" + text + "' is not one of: corrected, odometry, icp");
}

std::string ToString(PoseSource source) {
  switch (source) {
    case PoseSource::kCorrected:
      return "corrected";
    case PoseSource::kOdometry:
      return "odometry";
    case PoseSource::kIcp:
      return "icp";
  }
  return "?";
}

Pose2 LogLaserPose(const LogScan& scan) { return scan.logged_laser_pose; }

std::vector<Pose2> ScanPoses(const CarmenLog& log, PoseSource source,
                             const ScanOdometryConfig& icp_config,
                             const ProgressCallback& progress) {
  std::vector<Pose2> poses;
  poses.reserve(log.scans.size());
  if (source == PoseSource::kIcp) {
    ScanOdometry odometry(icp_config);
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      poses.push_back(odometry.Add(log.scans[i], log.scans[i].odometry_pose).T_world_robot);
      if (progress) progress(i + 1, log.scans.size());
    }
    return poses;
  }
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    const LogScan& scan = log.scans[i];
    const auto& pose = source == PoseSource::kCorrected ? scan.corrected_pose : scan.odometry_pose;
    if (!pose) {
      throw std::invalid_argument(log.path + ": scan " + std::to_string(i) + " (line " +
                                  std::to_string(scan.line) + ") has no " + ToString(source) +
                                  " pose; this log holds " +
                                  (log.corrected ? "corrected" : "odometry") + " poses");
    }
    poses.push_back(*pose);
  }
  if (progress) progress(log.scans.size(), log.scans.size());
  return poses;
}

std::vector<std::vector<Keypoint>> ExtractKeypoints(const CarmenLog& log,
                                                    const FlirtExtractor& extractor,
                                                    const ProgressCallback& progress) {
  std::vector<std::vector<Keypoint>> keypoints(log.scans.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, log.scans.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        keypoints[i] = extractor.Extract(log.scans[i], LogLaserPose(log.scans[i]));
                      }
                    });
  if (progress) progress(log.scans.size(), log.scans.size());
  return keypoints;
}

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

LogInputs PrepareLogInputs(const std::string& path, const LogInputOptions& options,
                           const StageProgress& progress) {
  auto start = std::chrono::steady_clock::now();
  LogInputs inputs;
  inputs.log = ReadCarmenLogWithScans(path, options.reading);
  std::vector<LogScan>& scans = inputs.log.scans;
  inputs.file_scans = scans.size();
  const std::size_t end = std::min(options.end_scan, scans.size());
  const std::size_t begin = std::min(options.first_scan, end);
  scans.erase(scans.begin() + static_cast<std::ptrdiff_t>(end), scans.end());
  scans.erase(scans.begin(), scans.begin() + static_cast<std::ptrdiff_t>(begin));
  if (scans.empty()) {
    throw std::invalid_argument(path + ": no scan in the range " + std::to_string(begin) + ":" +
                                std::to_string(end));
  }
  inputs.first_scan = begin;
  inputs.source_log = std::filesystem::path(path).filename().string();
  inputs.source_hash = inputs.log.fingerprint;  // the log is read once: it may be a pipe
  inputs.seconds_read = SecondsSince(start);

  start = std::chrono::steady_clock::now();
  inputs.pose_source =
      options.poses.value_or(inputs.log.corrected ? PoseSource::kCorrected : PoseSource::kIcp);
  if (options.compute_poses) {
    const std::string pose_stage = "poses (" + ToString(inputs.pose_source) + ")";
    inputs.poses = ScanPoses(inputs.log, inputs.pose_source, options.odometry,
                             [&](std::size_t done, std::size_t total) {
                               if (progress) progress(pose_stage, done, total);
                             });
    inputs.start_at_origin = options.start_at_origin;
    if (options.start_at_origin) {
      const Pose2 T_first_world = inputs.poses.front().inverse();
      for (Pose2& pose : inputs.poses) pose = T_first_world * pose;
    }
    inputs.seconds_poses = SecondsSince(start);
  }

  if (options.keypoints) {
    start = std::chrono::steady_clock::now();
    const FlirtExtractor extractor(options.features);
    inputs.keypoints =
        ExtractKeypoints(inputs.log, extractor, [&](std::size_t done, std::size_t total) {
          if (progress) progress("keypoints", done, total);
        });
    inputs.seconds_keypoints = SecondsSince(start);
  }
  return inputs;
}

LogMap MapLog(const LogInputs& inputs, const MappingConfig& config,
              const std::function<void(std::size_t)>& progress) {
  LogMap result;
  result.map = BuildGlobalMap({inputs.log.scans, inputs.poses, inputs.keypoints}, config,
                              &result.timings, progress);
  // The mapper numbers the scans of the cut log; a map names scans of the whole file, so that a
  // map of scans A:B and queries of scans C:D of one log apply the self-match rule to the same
  // numbers (the time-split protocol).
  const int offset = static_cast<int>(inputs.first_scan);
  if (offset != 0) {
    for (Submap& submap : result.map.submaps) {
      for (int& index : submap.scan_indices) index += offset;
      for (StableKeypoint& keypoint : submap.keypoints) keypoint.scan_index += offset;
    }
  }
  result.map.source_log = inputs.source_log;
  result.map.source_hash = inputs.source_hash;
  // A map in its first scan's frame is not in its log's frame: say so wherever it is read, so
  // that the log's own poses are not taken for its truth without a word.
  result.map.pose_source =
      ToString(inputs.pose_source) + (inputs.start_at_origin ? " (first-scan frame)" : "");
  result.stats = ComputeStats(result.map);
  const std::vector<double>& seconds = result.timings.submap_seconds;
  if (!seconds.empty()) {
    double sum = 0.0;
    for (const double s : seconds) sum += s;
    result.seconds_per_submap_mapping = sum / static_cast<double>(seconds.size());
  }
  if (result.stats.submaps > 0) {
    result.seconds_per_submap =
        result.seconds_per_submap_mapping + (inputs.seconds_poses + inputs.seconds_keypoints) /
                                                static_cast<double>(result.stats.submaps);
  }
  return result;
}

OccupancyGrid LogOccupancyGrid(const LogInputs& inputs, const OccupancyGridConfig& config) {
  if (inputs.poses.size() != inputs.log.scans.size()) {
    throw std::invalid_argument(inputs.source_log +
                                ": an occupancy grid needs a pose for every scan");
  }
  std::vector<const LaserScan*> scans;
  scans.reserve(inputs.log.scans.size());
  for (const LogScan& scan : inputs.log.scans) scans.push_back(&scan);
  return BuildOccupancyGrid(scans, inputs.poses, config);
}

}  // namespace keyplace
