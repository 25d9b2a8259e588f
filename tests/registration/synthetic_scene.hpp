#pragma once
// Synthetic 2D worlds for registration tests: polygons of wall segments and a ray caster that
// turns a sensor pose into a LaserScan (optionally with range noise and outliers).

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace::testing {

struct Segment {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
};

/// A closed polygon as segments.
inline std::vector<Segment> Polygon(const std::vector<Eigen::Vector2d>& corners) {
  std::vector<Segment> segments;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    segments.push_back({corners[i], corners[(i + 1) % corners.size()]});
  }
  return segments;
}

/// An irregular room (about 10 x 7 m, no two walls the same, one alcove) with a pillar: every
/// pose is fully constrained.
inline std::vector<Segment> IrregularRoom() {
  std::vector<Segment> world = Polygon(
      {{-4.0, -3.0}, {5.0, -3.5}, {6.0, 1.0}, {3.0, 1.2}, {3.0, 3.5}, {-2.0, 4.0}, {-5.0, 1.0}});
  const std::vector<Segment> pillar = Polygon({{0.5, 0.5}, {1.1, 0.6}, {1.0, 1.1}, {0.4, 1.0}});
  world.insert(world.end(), pillar.begin(), pillar.end());
  return world;
}

/// Two parallel walls y = +-half_width, 200 m long: featureless along x.
inline std::vector<Segment> Corridor(double half_width_m = 1.0) {
  return {{{-100.0, -half_width_m}, {100.0, -half_width_m}},
          {{-100.0, half_width_m}, {100.0, half_width_m}}};
}

struct ScanOptions {
  int beams = 360;
  double fov_rad = 2.0 * M_PI;  // 2 pi: full circle; M_PI: -90..+90 deg
  double max_range_m = 20.0;
  double range_noise_m = 0.0;     // Gaussian sigma
  double outlier_fraction = 0.0;  // beams replaced by a random shorter range
};

/// A front laser: `beams` beams over -90..+90 deg with Gaussian range noise.
inline ScanOptions FrontLaser(int beams, double range_noise_m) {
  ScanOptions options;
  options.beams = beams;
  options.fov_rad = M_PI;
  options.range_noise_m = range_noise_m;
  return options;
}

/// Ray-casts `world` from the laser pose T_world_laser.
inline LaserScan CastScan(const std::vector<Segment>& world, const Pose2& T_world_laser,
                          const ScanOptions& options, std::mt19937* rng = nullptr) {
  LaserScan scan;
  scan.max_range_m = options.max_range_m;
  const bool full = options.fov_rad >= 2.0 * M_PI - 1e-9;
  const double start = full ? -M_PI : -options.fov_rad / 2.0;
  const double step = options.fov_rad / options.beams;
  std::normal_distribution<double> noise(0.0,
                                         options.range_noise_m > 0 ? options.range_noise_m : 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < options.beams; ++i) {
    const double angle = start + i * step;
    const double world_angle = T_world_laser.theta + angle;
    const Eigen::Vector2d origin = T_world_laser.translation();
    const Eigen::Vector2d dir(std::cos(world_angle), std::sin(world_angle));
    double best = std::numeric_limits<double>::infinity();
    for (const Segment& s : world) {
      const Eigen::Vector2d e = s.b - s.a;
      const double denom = dir.x() * e.y() - dir.y() * e.x();
      if (std::abs(denom) < 1e-12) continue;
      const Eigen::Vector2d w = s.a - origin;
      const double t = (w.x() * e.y() - w.y() * e.x()) / denom;
      const double u = (w.x() * dir.y() - w.y() * dir.x()) / denom;
      if (t > 1e-9 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
    }
    double range = best;
    bool valid = std::isfinite(range) && range < options.max_range_m;
    if (valid && rng != nullptr && options.range_noise_m > 0.0) range += noise(*rng);
    if (valid && rng != nullptr && options.outlier_fraction > 0.0 &&
        uniform(*rng) < options.outlier_fraction) {
      range = range * uniform(*rng);  // something in front of the wall
    }
    if (!valid) range = options.max_range_m;
    scan.ranges_m.push_back(range);
    scan.angles_rad.push_back(angle);
    scan.valid.push_back(valid ? 1 : 0);
  }
  return scan;
}

/// Valid endpoints of a scan in the laser frame (what the ICP consumes).
inline std::vector<Eigen::Vector2d> Endpoints(const LaserScan& scan) {
  std::vector<Eigen::Vector2d> points;
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    if (!scan.valid[i]) continue;
    points.emplace_back(scan.ranges_m[i] * std::cos(scan.angles_rad[i]),
                        scan.ranges_m[i] * std::sin(scan.angles_rad[i]));
  }
  return points;
}

inline double RadToDeg(double rad) { return rad * 180.0 / M_PI; }
inline double DegToRad(double deg) { return deg * M_PI / 180.0; }

}  // namespace keyplace::testing
