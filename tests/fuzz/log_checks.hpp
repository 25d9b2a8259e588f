#pragma once
// What every log a reader accepts guarantees (carmen_log.hpp, laser_scan.hpp,
// docs/RELIABILITY.md), checked by the harnesses of the CARMEN, ROS 1 and ROS 2 readers.

#include <cmath>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace::fuzz {

inline bool Finite(const Pose2& pose) {
  return std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta);
}

// Beams within the cap with one angle and one validity flag each, finite angles within physical
// limits (a start within +-2 pi and at most one turn of beams: issue 31's angle_increment 1e30),
// finite poses, valid beams with usable ranges.
inline void CheckLog(const CarmenLog& log) {
  for (const LogScan& scan : log.scans) {
    const std::string where = "scan of line " + std::to_string(scan.line);
    if (scan.size() > kMaxScanBeams) Finding(where + ": more beams than kMaxScanBeams");
    if (scan.angles_rad.size() != scan.size() || scan.valid.size() != scan.size()) {
      Finding(where + ": ranges, angles and valid flags differ in length");
    }
    for (std::size_t i = 0; i < scan.size(); ++i) {
      if (!std::isfinite(scan.angles_rad[i])) Finding(where + ": a beam angle is not finite");
      if (!(std::abs(scan.angles_rad[i]) <= 4.0 * M_PI + 1e-6)) {
        Finding(where + ": a beam angle beyond +-4 pi (a start within +-2 pi, one turn of beams)");
      }
      const double range = scan.ranges_m[i];
      if (scan.valid[i] != 0 &&
          !(std::isfinite(range) && range >= 0.0 && range < scan.max_range_m)) {
        Finding(where + ": a beam marked valid has an unusable range");
      }
    }
    if (!Finite(scan.logged_laser_pose) || !Finite(scan.T_robot_laser) ||
        (scan.odometry_pose && !Finite(*scan.odometry_pose)) ||
        (scan.corrected_pose && !Finite(*scan.corrected_pose))) {
      Finding(where + ": a pose is not finite");
    }
  }
  for (const OdometryMessage& odometry : log.odometry) {
    if (!Finite(odometry.pose)) Finding("an odometry pose is not finite");
  }
  if (log.skipped_line_numbers.size() > CarmenLog::kMaxListedSkippedLines) {
    Finding("more skipped line numbers listed than kMaxListedSkippedLines");
  }
}

}  // namespace keyplace::fuzz
