#pragma once
// Reader for CARMEN text logs (plain or gzip-compressed), and the log structure every command
// reads: ReadCarmenLog also reads a ROS 1 bag (ros1_bag.hpp) or a ROS 2 bag (ros2_bag.hpp) into
// it, told apart by content.

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace {

struct OdometryMessage {
  Pose2 pose;                // robot pose in the odometry frame
  double tv_mps = 0.0;       // translational velocity
  double rv_radps = 0.0;     // rotational velocity
  double timestamp_s = 0.0;  // ipc_timestamp
  double logger_timestamp_s = 0.0;
};

/// VERTEX2 id x y theta: a node of the corrected pose graph.
struct GraphVertex {
  long id = 0;
  Pose2 pose;
};

/// EDGE2 from to dx dy dtheta + information matrix (TORO order I_xx I_xy I_yy I_tt I_xt I_yt).
struct GraphEdge {
  long from = 0;
  long to = 0;
  Pose2 T_from_to;
  double information[6] = {0, 0, 0, 0, 0, 0};
  bool loop = false;  // listed after a "#LOOP EDGES" comment
};

/// How the beams of a FLASER / RLASER line, which states no angles, spread over its field of
/// view. An even count keeps FLIRTLib's convention: each beam owns a sector, n steps of fov / n
/// from -fov / 2 (CARMEN's 180- and 360-beam logs, FLIRTLib's reference output). An odd count
/// (181, 361) is a SICK scanner at 1 or 0.5 degrees whose first and last beams lie at -fov / 2
/// and +fov / 2: n - 1 steps of fov / (n - 1). Spreading 361 such beams by fov / 361 shrinks
/// every step by 0.3 % and leaves the last beam 0.5 degrees short of +90.
enum class FlaserSpacing { kFovOverBeams, kFovOverBeamsMinusOne };
FlaserSpacing FlaserSpacingOf(std::size_t beams);
/// The steps of the field of view between first and one-past-last beam: n or n - 1.
double FlaserSteps(std::size_t beams);
/// Bearing of beam i of a FLASER line of `beams` beams over fov_rad, by FlaserSpacingOf(beams).
double FlaserBeamAngle(std::size_t i, std::size_t beams, double fov_rad);
/// "fov/n" or "fov/(n-1)".
std::string ToString(FlaserSpacing spacing);

/// A scan as a CARMEN log gives it: the sensor data plus what the log writes beside it.
struct LogScan : LaserScan {
  double logger_timestamp_s = 0.0;  // logger_timestamp (the monotonic one for Intel raw)
  // Robot pose in the odometry frame (raw logs), when the log carries one.
  std::optional<Pose2> odometry_pose;
  // SLAM-corrected robot pose (corrected logs), when the log carries one.
  std::optional<Pose2> corrected_pose;
  // The laser pose exactly as the log writes it, in the log's frame (corrected or odometry).
  // Recomposing robot pose * T_robot_laser differs from it by a few ulps, which is enough to
  // flip near-equal edge lengths in FLIRT's spanning trees.
  Pose2 logged_laser_pose;
  // 1-based line number of the laser line in its file; for a bag, the 1-based number of the
  // message on the scan topic.
  std::size_t line = 0;
};

/// A topic of a bag: name, message type and how many messages it holds.
struct LogTopic {
  std::string name;
  std::string type;
  std::size_t messages = 0;
};

struct CarmenLog {
  std::string path;
  // "CARMEN log", "ROS 1 bag" or "ROS 2 bag"; for a bag the topics it holds (every one, not only
  // those read).
  std::string format = "CARMEN log";
  std::vector<LogTopic> topics;
  std::vector<LogScan> scans;  // FLASER / RLASER / ROBOTLASER1 in file order
  std::vector<OdometryMessage> odometry;
  std::vector<GraphVertex> vertices;
  std::vector<GraphEdge> edges;
  std::map<std::string, std::string> params;       // PARAM name -> value
  std::map<std::string, std::size_t> line_counts;  // per message type, plus "#comment", "unknown"
  std::size_t lines = 0;
  // "crc32:<hex>:<bytes>" of the file's bytes (compressed ones for a .gz), taken while reading:
  // a pipe cannot be read a second time. Maps record it as source_hash. Empty for a log built
  // in memory.
  std::string fingerprint;
  std::uint64_t file_bytes = 0;  // bytes read from the file (compressed ones for a .gz)
  // Beams per scan over all scans, and the first scan's field of view (first to last bearing plus
  // one step): counted as the scans are read, so known also when their beams are not kept.
  std::size_t beams_total = 0;
  std::size_t beams_per_scan_min = 0;
  std::size_t beams_per_scan_max = 0;
  double first_scan_field_of_view_rad = 0.0;
  // FLASER lines read with each beam spacing (FlaserSpacing): even beam counts fov / n, odd ones
  // fov / (n - 1). Both 0 for a log without FLASER lines (ROBOTLASER1 and bags state their angles).
  std::size_t flaser_scans_fov_over_beams = 0;
  std::size_t flaser_scans_fov_over_beams_minus_one = 0;
  std::size_t invalid_beams = 0;    // beams marked invalid because of NaN/inf/negative values
  std::size_t no_return_beams = 0;  // beams at or beyond max range (normal "no echo")
  // True when the scans' poses are SLAM-corrected (VERTEX2 or NEFF lines present): they are then
  // stored in LogScan::corrected_pose instead of odometry_pose.
  bool corrected = false;
  // Damage the reader worked around, one sentence each, naming file and line (the library never
  // prints: callers show them).
  std::vector<std::string> warnings;
  // The last line had no end of line and did not parse (a logger cut off, e.g. by power loss):
  // it was dropped.
  bool truncated_last_line = false;
  // Malformed lines skipped with CarmenReadOptions::skip_bad_lines: how many, and the first
  // kMaxListedSkippedLines of their line numbers.
  std::size_t skipped_lines = 0;
  std::vector<std::size_t> skipped_line_numbers;
  static constexpr std::size_t kMaxListedSkippedLines = 10;
};

struct CarmenReadOptions {
  // "no return" threshold for FLASER/RLASER lines, which carry no max range of their own (m).
  // ROBOTLASER1 lines use their own max_range field. Ranges >= this are invalid.
  double flaser_max_range_m = 80.0;
  // Positions (x, y of laser, robot, ODOM and VERTEX2 poses, EDGE2 dx, dy) beyond +-this are
  // errors: such a pose is a corrupt line, not a place. 1e7 m keeps UTM (northing < 1e7 m) and
  // earth-centred coordinates; a double still resolves 2 nm there.
  double max_coordinate_m = 1e7;
  // Overrides the decision taken from the file content (VERTEX2 / NEFF lines) when set.
  enum class PoseKind { kAuto, kCorrected, kOdometry } pose_kind = PoseKind::kAuto;
  // Skip malformed lines (counted in CarmenLog::skipped_lines, with a warning) instead of
  // stopping at the first one.
  bool skip_bad_lines = false;
  // false: each scan's ranges, bearings and validity flags are counted and then released, so a
  // summary of a log (keyplace info) holds about 200 bytes per scan instead of 17 per beam. The
  // scans then have size() 0; only their stamps and poses are kept.
  bool keep_beams = true;
  // How a ROS 1 or ROS 2 bag becomes a log (topics, frames, laser pose); unused for CARMEN logs.
  BagInputConfig bag;
};

/// Reads a CARMEN log, or a ROS 1 bag (a regular file starting with "#ROSBAG V2.0", whatever
/// its name) with ReadRos1Bag(path, options.bag), or a ROS 2 bag (a directory, a metadata.yaml,
/// an MCAP file or an SQLite *.db3 file: IsRos2Bag) with ReadRos2Bag(path, options.bag). Throws
/// std::invalid_argument naming file, line and field on malformed input (unless
/// options.skip_bad_lines), std::runtime_error when the file cannot be opened or its compressed
/// data are truncated. A last line without end of line that does not parse is dropped with a
/// warning (CarmenLog::warnings): what a logger killed mid-line leaves. The file is opened once and
/// read once, front to back, so it may be a pipe, a FIFO or /dev/fd/N; an SQLite file (a map) is an
/// error saying so.
CarmenLog ReadCarmenLog(const std::string& path, const CarmenReadOptions& options = {});

/// ReadCarmenLog, and throws std::invalid_argument naming the file when it holds no laser scan
/// (a wrong file is reported instead of giving empty results).
CarmenLog ReadCarmenLogWithScans(const std::string& path, const CarmenReadOptions& options = {});

}  // namespace keyplace
