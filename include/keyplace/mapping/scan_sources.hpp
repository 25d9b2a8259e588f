#pragma once
// What mapping needs per scan of a log: a robot pose from the chosen source and FLIRT keypoints.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
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

/// The laser pose the log writes for a scan, exactly as written (LogScan::logged_laser_pose).
Pose2 LogLaserPose(const LogScan& scan);

/// What to prepare from a log.
struct LogInputOptions {
  CarmenReadOptions reading;        // how the log is read (e.g. skip_bad_lines)
  std::optional<PoseSource> poses;  // default: corrected when the log has them, else icp
  ScanOdometryConfig odometry;      // for PoseSource::kIcp
  FlirtConfig features;
  // Keep only the scans [first_scan, end_scan) of the file (clamped), before anything else.
  std::size_t first_scan = 0;
  std::size_t end_scan = static_cast<std::size_t>(-1);
  bool keypoints = true;  // false: leave LogInputs::keypoints empty
  // false: leave LogInputs::poses empty, for callers that estimate the poses themselves (SLAM)
  bool compute_poses = true;
  // true: the poses are expressed in the frame of the first kept scan's pose, as a robot whose
  // own frame starts where the session starts (a map of one session of a multi-session set).
  bool start_at_origin = false;
  // Non-empty: a directory (created if missing) that keeps the ICP poses and the keypoints of
  // this log between runs, keyed by the code that computes them (a hash of its sources taken by
  // the build), the log's content (CarmenLog::fingerprint), the scan range and every setting
  // they depend on (reading, bag input, odometry, features); a later preparation with the same
  // key reads them instead of computing them. Entries are files of native doubles and floats,
  // the results bit for bit, checked by a checksum against damage, not against tampering: the
  // directory must be as trusted as the code.
  std::string cache_dir;
};

/// Progress of a preparation stage ("poses (icp)", "keypoints"): (stage, done, total).
using StageProgress = std::function<void(const std::string&, std::size_t, std::size_t)>;

/// A log read and prepared for mapping and place recognition: its scans, a pose per scan and
/// the FLIRT keypoints of every scan, with where they came from.
struct LogInputs {
  CarmenLog log;  // scans cut to the requested range; log.warnings: damage the reader skipped
  PoseSource pose_source = PoseSource::kCorrected;
  std::vector<Pose2> poses;                      // T_world_robot of every scan (if computed)
  std::vector<std::vector<Keypoint>> keypoints;  // laser frame
  std::string source_log;                        // file name of the log
  std::string source_hash;                       // CarmenLog::fingerprint of the log
  std::size_t first_scan = 0;                    // index in the file of scans[0]
  std::size_t file_scans = 0;                    // scans in the file (before the cut)
  bool start_at_origin = false;                  // poses in the first kept scan's frame
  double seconds_read = 0.0;
  double seconds_poses = 0.0;
  double seconds_keypoints = 0.0;
  bool poses_from_cache = false;      // read from LogInputOptions::cache_dir
  bool keypoints_from_cache = false;  // read from LogInputOptions::cache_dir
  // Cache entries found damaged (named, with what was wrong) and computed again, or that could
  // not be written.
  std::vector<std::string> cache_warnings;
};

/// Reads `path` (throws std::invalid_argument when it holds no laser scan), cuts it to the range,
/// computes the poses and the keypoints, or reads them from options.cache_dir (throws
/// std::invalid_argument naming it when it cannot be made or is not writable; an entry that
/// cannot be written later is a cache warning). `progress` may be empty.
LogInputs PrepareLogInputs(const std::string& path, const LogInputOptions& options = {},
                           const StageProgress& progress = {});

/// The occupancy grid of the inputs' scans at their poses (inputs.poses, which must be computed).
/// Throws std::invalid_argument as BuildOccupancyGrid, or when the poses were not computed.
OccupancyGrid LogOccupancyGrid(const LogInputs& inputs, const OccupancyGridConfig& config);

/// A log's global map (Algorithm 2) with its provenance and the mapping criteria of Section 5.1.
struct LogMap {
  GlobalMap map;  // source_log, source_hash, pose_source set from the inputs; file scan indices
  MappingStats stats;
  GlobalMappingTimings timings;
  double seconds_per_submap_mapping = 0.0;  // mean time to build a submap (keypoints given)
  // ... plus each submap's share of the pose estimation and keypoint extraction.
  double seconds_per_submap = 0.0;
};

/// Builds the map of `inputs` with `config`; `progress` (may be empty) gets the next scan index
/// (of the cut log). The map's scan indices (Submap::scan_indices, StableKeypoint::scan_index)
/// are scans of the whole file: offset by inputs.first_scan.
LogMap MapLog(const LogInputs& inputs, const MappingConfig& config,
              const std::function<void(std::size_t)>& progress = {});

}  // namespace keyplace
