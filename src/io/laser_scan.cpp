#include "keyplace/io/laser_scan.hpp"

#include <cmath>

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

}  // namespace keyplace
