#pragma once
// What mapping needs per scan of a log: a robot pose from the chosen source and FLIRT keypoints.

#include <functional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/registration/scan_odometry.hpp"

namespace keyplace {

/// Where the pose of each scan comes from: the log's corrected poses, its raw odometry, or ICP
/// scan odometry initialised by the raw odometry (paper: libpointmatcher ICP; ours: registration).
enum class PoseSource { kCorrected, kOdometry, kIcp };

/// "corrected" | "odometry" | "icp"; throws std::invalid_argument naming the accepted values.
PoseSource ParsePoseSource(const std::string& text);
std::string ToString(PoseSource source);

/// Progress callback: (done, total).
using ProgressCallback = std::function<void(std::size_t, std::size_t)>;

/// T_world_robot of every scan. Throws std::invalid_argument when the log has no poses of the
/// requested kind (e.g. corrected poses from a raw log), naming the log and the first such scan.
std::vector<Pose2> ScanPoses(const CarmenLog& log, PoseSource source,
                             const ScanOdometryConfig& icp_config = {},
                             const ProgressCallback& progress = {});

/// FLIRT keypoints of every scan (laser frame), computed in parallel. The duplicate-suppression
/// box of FLIRTLib is oriented by the laser pose the log gives (as FLIRTLib does).
std::vector<std::vector<Keypoint>> ExtractKeypoints(const CarmenLog& log,
                                                    const FlirtExtractor& extractor,
                                                    const ProgressCallback& progress = {});

/// The laser pose the log writes for a scan, exactly as written (LaserScan::logged_laser_pose).
Pose2 LogLaserPose(const LaserScan& scan);

}  // namespace keyplace
