#include "keyplace/mapping/scan_sources.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

Pose2 LogLaserPose(const LaserScan& scan) { return scan.logged_laser_pose; }

std::vector<Pose2> ScanPoses(const CarmenLog& log, PoseSource source,
                             const ScanOdometryConfig& icp_config,
                             const ProgressCallback& progress) {
  std::vector<Pose2> poses;
  poses.reserve(log.scans.size());
  if (source == PoseSource::kIcp) {
    ScanOdometry odometry(icp_config);
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      poses.push_back(odometry.Add(log.scans[i]).T_world_robot);
      if (progress) progress(i + 1, log.scans.size());
    }
    return poses;
  }
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    const LaserScan& scan = log.scans[i];
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

}  // namespace keyplace
