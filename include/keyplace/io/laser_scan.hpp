#pragma once
// One 2D laser scan: the sensor data, in the laser frame. Where it came from (a log line, the
// poses a log writes beside it) is LogScan's business (carmen_log.hpp).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// Most beams per scan the library takes (the CARMEN reader, FLIRT): twice the ~4000 of the
/// densest common 2D lidars. FLIRT's memory grows with the pairs of beams within its kernel
/// cutoff; at this count it stays below about 650 MiB per thread (docs/RELIABILITY.md).
constexpr std::size_t kMaxScanBeams = 8192;

struct LaserScan {
  std::vector<double> ranges_m;    // one per beam, as written in the log
  std::vector<double> angles_rad;  // beam bearing in the laser frame, same length as ranges_m
  // 1 when the beam returned a usable range (finite, >= 0, < max_range_m), 0 otherwise.
  std::vector<std::uint8_t> valid;
  double max_range_m = 0.0;  // readings at or beyond this are "no return"

  double timestamp_s = 0.0;  // acquisition time (s)

  // Mounting of the laser on the robot: laser pose = robot pose * T_robot_laser.
  Pose2 T_robot_laser;

  std::size_t size() const { return ranges_m.size(); }
  std::size_t CountValid() const;

  /// Endpoint of beam i in the laser frame (uses the raw range even for invalid beams).
  Eigen::Vector2d Endpoint(std::size_t i) const;
  /// Endpoints of the valid beams only, in the laser frame.
  std::vector<Eigen::Vector2d> ValidEndpoints() const;
};

/// A scan from its beams, for callers that have them from elsewhere (a driver, Python): a beam is
/// valid when its range is finite, > 0 and < max_range_m, as the log readers decide. Throws
/// std::invalid_argument when ranges and angles differ in size, there are more than
/// kMaxScanBeams beams, an angle is not finite or max_range_m is not positive.
LaserScan MakeLaserScan(std::vector<double> ranges_m, std::vector<double> angles_rad,
                        double max_range_m, double timestamp_s = 0.0,
                        const Pose2& T_robot_laser = Pose2());

}  // namespace keyplace
