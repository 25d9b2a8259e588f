#pragma once
// A simulated square-loop world for SLAM tests: a square corridor with clutter, driven round with
// drifting odometry (tests/slam, tests/eval).

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/slam/online_slam.hpp"
#include "registration/synthetic_scene.hpp"

namespace keyplace::testing {

// Corridor between the squares of half-sides 8 m and 4.5 m (3.5 m wide), clutter boxes along both
// walls at random positions and sizes (seeded), so that every place looks different.
inline std::vector<Segment> SquareCorridorWorld() {
  std::vector<Segment> world = Polygon({{-8, -8}, {8, -8}, {8, 8}, {-8, 8}});
  const std::vector<Segment> inner = Polygon({{-4.5, -4.5}, {4.5, -4.5}, {4.5, 4.5}, {-4.5, 4.5}});
  world.insert(world.end(), inner.begin(), inner.end());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> size(0.2, 0.6);
  std::uniform_real_distribution<double> gap(0.6, 1.6);
  std::uniform_real_distribution<double> turn(-0.6, 0.6);
  for (int side = 0; side < 4; ++side) {
    const double c = std::cos(side * M_PI / 2), s = std::sin(side * M_PI / 2);
    for (double wall : {-7.6, -4.9}) {  // outer wall (inside) and inner wall (outside)
      double u = -6.5;
      while (u < 6.5) {
        const double w = size(rng), h = size(rng), a = turn(rng);
        std::vector<Eigen::Vector2d> box;
        for (const auto& corner : {Eigen::Vector2d(-w / 2, -h / 2), Eigen::Vector2d(w / 2, -h / 2),
                                   Eigen::Vector2d(w / 2, h / 2), Eigen::Vector2d(-w / 2, h / 2)}) {
          const Eigen::Vector2d local(u + std::cos(a) * corner.x() - std::sin(a) * corner.y(),
                                      wall + std::sin(a) * corner.x() + std::cos(a) * corner.y());
          box.emplace_back(c * local.x() - s * local.y(), s * local.x() + c * local.y());
        }
        const std::vector<Segment> box_segments = Polygon(box);
        world.insert(world.end(), box_segments.begin(), box_segments.end());
        u += gap(rng);
      }
    }
  }
  return world;
}

// True poses along the corridor centre line (half-side 6.25 m), counter-clockwise from (0, -6.25)
// heading +x; 0.15 m steps, turning on the spot at the corners.
inline std::vector<Pose2> SquareLoopPath(double laps) {
  const double half = 6.25, step = 0.15;
  std::vector<Pose2> path;
  Pose2 pose(0.0, -half, 0.0);
  const double side = 2 * half;
  double travelled = 0.0, along_side = half;  // start in the middle of the first side
  const double total = laps * 4 * side;
  while (travelled < total) {
    path.push_back(pose);
    if (along_side + step > side) {
      const double rest = side - along_side;
      pose = pose * Pose2(rest, 0.0, 0.0);
      for (int k = 1; k <= 3; ++k) path.push_back(pose * Pose2(0.0, 0.0, k * M_PI / 6));
      pose = pose * Pose2(step - rest, 0.0, M_PI / 2);
      along_side = step - rest;
    } else {
      pose = pose * Pose2(step, 0.0, 0.0);
      along_side += step;
    }
    travelled += step;
  }
  return path;
}

/// A simulated drive: the true poses and the scans with drifting odometry (scan i at 0.1 i s).
struct SimulatedRun {
  std::vector<Pose2> truth;
  std::vector<LogScan> scans;
};

/// `range_noise_m`: the standard deviation of the range noise (0.005 m: a SICK LMS; a few
/// centimetres: a cheaper scanner, whose keypoints recur less from scan to scan).
inline SimulatedRun Simulate(double laps, double range_noise_m = 0.005) {
  SimulatedRun run;
  run.truth = SquareLoopPath(laps);
  const std::vector<Segment> world = SquareCorridorWorld();
  ScanOptions options;
  options.beams = 360;
  options.max_range_m = 15.0;
  options.range_noise_m = range_noise_m;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  Pose2 odometry = run.truth.front();
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    if (i > 0) {
      const Pose2 step = Between(run.truth[i - 1], run.truth[i]);
      // Drift: 3 % too long, heading bias 0.4 deg per metre, small noise.
      const double d = TranslationNorm(step);
      odometry = odometry * Pose2(1.03 * step.x + 0.002 * noise(rng), step.y + 0.002 * noise(rng),
                                  step.theta + d * 0.4 * M_PI / 180 + 0.001 * noise(rng));
    }
    LogScan scan;
    static_cast<LaserScan&>(scan) = CastScan(world, run.truth[i], options, &rng);
    scan.odometry_pose = odometry;
    scan.timestamp_s = scan.logger_timestamp_s = 0.1 * static_cast<double>(i);
    scan.logged_laser_pose = odometry;
    run.scans.push_back(std::move(scan));
  }
  return run;
}

/// No ICP (every correction is "too large", so the pose is the odometry prediction): the
/// odometry drift stays in the estimate until a loop removes it.
inline SlamConfig SimulationConfig() {
  SlamConfig config;
  config.odometry.max_correction_translation_m = 1e-12;  // no ICP: odometry drift stays
  config.odometry.max_correction_rotation_rad = 1e-12;
  return config;
}

}  // namespace keyplace::testing
