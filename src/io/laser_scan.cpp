#include "keyplace/io/laser_scan.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace keyplace {

std::size_t LaserScan::CountValid() const {
  std::size_t count = 0;
  for (const auto v : valid) count += v != 0 ? 1 : 0;
  return count;
}

Eigen::Vector2d LaserScan::Endpoint(std::size_t i) const {
  return {ranges_m[i] * std::cos(angles_rad[i]), ranges_m[i] * std::sin(angles_rad[i])};
}

std::vector<Eigen::Vector2d> LaserScan::ValidEndpoints() const {
  std::vector<Eigen::Vector2d> points;
  points.reserve(ranges_m.size());
  for (std::size_t i = 0; i < ranges_m.size(); ++i) {
    if (valid[i] != 0) points.push_back(Endpoint(i));
  }
  return points;
}

LaserScan MakeLaserScan(std::vector<double> ranges_m, std::vector<double> angles_rad,
                        double max_range_m, double timestamp_s, const Pose2& T_robot_laser) {
  if (ranges_m.size() != angles_rad.size()) {
    throw std::invalid_argument("scan: " + std::to_string(ranges_m.size()) + " ranges but " +
                                std::to_string(angles_rad.size()) + " angles");
  }
  if (ranges_m.size() > kMaxScanBeams) {
    throw std::invalid_argument("scan: " + std::to_string(ranges_m.size()) +
                                " beams, more than the " + std::to_string(kMaxScanBeams) +
                                " the library takes");
  }
  if (!(max_range_m > 0.0)) {
    throw std::invalid_argument("scan: max_range_m must be positive, got " +
                                std::to_string(max_range_m));
  }
  for (std::size_t i = 0; i < angles_rad.size(); ++i) {
    if (!std::isfinite(angles_rad[i])) {
      throw std::invalid_argument("scan: angle of beam " + std::to_string(i) + " is not finite");
    }
  }
  LaserScan scan;
  scan.valid.assign(ranges_m.size(), 0);
  for (std::size_t i = 0; i < ranges_m.size(); ++i) {
    const double range = ranges_m[i];
    scan.valid[i] = std::isfinite(range) && range > 0.0 && range < max_range_m ? 1 : 0;
  }
  scan.ranges_m = std::move(ranges_m);
  scan.angles_rad = std::move(angles_rad);
  scan.max_range_m = max_range_m;
  scan.timestamp_s = timestamp_s;
  scan.T_robot_laser = T_robot_laser;
  return scan;
}

}  // namespace keyplace
