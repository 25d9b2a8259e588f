#pragma once
// Simulated drives through synthetic worlds for the localization tests: two identical rooms
// joined by a corridor that tells them apart, waypoint paths, and the scans and keypoints of a
// drive.

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "registration/synthetic_scene.hpp"

namespace keyplace::testing {

inline void Append(std::vector<Segment>& world, const std::vector<Segment>& more) {
  world.insert(world.end(), more.begin(), more.end());
}

// A small box of random size and turn centred at `centre`.
inline std::vector<Segment> Box(const Eigen::Vector2d& centre, std::mt19937& rng) {
  std::uniform_real_distribution<double> size(0.2, 0.45);
  std::uniform_real_distribution<double> turn(-0.6, 0.6);
  const double w = size(rng), h = size(rng), a = turn(rng);
  std::vector<Eigen::Vector2d> corners;
  for (const auto& c : {Eigen::Vector2d(-w, -h), Eigen::Vector2d(w, -h), Eigen::Vector2d(w, h),
                        Eigen::Vector2d(-w, h)}) {
    corners.push_back(centre + Eigen::Vector2d(std::cos(a) * c.x() - std::sin(a) * c.y(),
                                               std::sin(a) * c.x() + std::cos(a) * c.y()) /
                                   2.0);
  }
  return Polygon(corners);
}

// An 8 x 8 m room centred at (ox, 0) with boxes along its walls (the same seed: the same room),
// a 1.5 m door in its north wall and a 3 m stub up to the corridor.
inline std::vector<Segment> Room(double ox) {
  std::vector<Segment> world = {{{ox - 4, -4}, {ox + 4, -4}},    {{ox + 4, -4}, {ox + 4, 4}},
                                {{ox - 4, -4}, {ox - 4, 4}},     {{ox - 4, 4}, {ox - 0.75, 4}},
                                {{ox + 0.75, 4}, {ox + 4, 4}},   {{ox - 0.75, 4}, {ox - 0.75, 7}},
                                {{ox + 0.75, 4}, {ox + 0.75, 7}}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> gap(0.7, 1.4);
  for (int side = 0; side < 4; ++side) {
    const double c = std::cos(side * M_PI / 2), s = std::sin(side * M_PI / 2);
    for (double u = -3.2; u < 3.2; u += gap(rng)) {
      const Eigen::Vector2d local(u, -3.55);  // along the south wall, turned to each side
      const Eigen::Vector2d centre(c * local.x() - s * local.y(), s * local.x() + c * local.y());
      if (centre.y() > 3.0 && std::abs(centre.x()) < 1.5) continue;  // keep the door free
      Append(world, Box(centre + Eigen::Vector2d(ox, 0), rng));
    }
  }
  return world;
}

// Rooms at x = -10 and x = +10 (one a translated copy of the other), a corridor y in [7, 9] from
// x = -14 to 14 with boxes only in its middle (x in [-7, 7]): the only place that differs.
inline std::vector<Segment> TwoRooms() {
  std::vector<Segment> world = Room(-10.0);
  Append(world, Room(10.0));
  Append(world, {{{-14, 7}, {-10.75, 7}},
                 {{-9.25, 7}, {9.25, 7}},
                 {{10.75, 7}, {14, 7}},
                 {{-14, 9}, {14, 9}},
                 {{-14, 7}, {-14, 9}},
                 {{14, 7}, {14, 9}}});
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> gap(0.6, 1.3);
  for (const double wall_y : {7.25, 8.75}) {
    for (double x = -7.0; x < 7.0; x += gap(rng)) Append(world, Box({x, wall_y}, rng));
  }
  return world;
}

// True poses through `waypoints` (the robot starts at the first, facing the second): 0.15 m steps,
// turning on the spot at each waypoint in 15 degree steps.
inline std::vector<Pose2> Drive(const std::vector<Eigen::Vector2d>& waypoints) {
  std::vector<Pose2> poses;
  Eigen::Vector2d d = waypoints[1] - waypoints[0];
  Pose2 pose(waypoints[0].x(), waypoints[0].y(), std::atan2(d.y(), d.x()));
  for (std::size_t w = 1; w < waypoints.size(); ++w) {
    d = waypoints[w] - waypoints[w - 1];
    const double heading = std::atan2(d.y(), d.x());
    const double turn = WrapAngle(heading - pose.theta);
    const int turn_steps = static_cast<int>(std::ceil(std::abs(turn) / (M_PI / 12)));
    for (int k = 1; k <= turn_steps; ++k) {
      poses.emplace_back(pose.x, pose.y, pose.theta + turn * k / turn_steps);
    }
    pose = Pose2(pose.x, pose.y, heading);
    const int steps = static_cast<int>(std::round(d.norm() / 0.15));
    for (int k = 1; k <= steps; ++k) {
      const Eigen::Vector2d p = waypoints[w - 1] + d * k / steps;
      poses.emplace_back(p.x(), p.y(), heading);
    }
    pose = poses.back();
  }
  return poses;
}

struct SimulatedDrive {
  std::vector<Pose2> truth;
  std::vector<LogScan> scans;
  std::vector<std::vector<Keypoint>> keypoints;
};

// A full-circle laser of 10 m, 5 mm range noise: the drives of the two rooms.
inline ScanOptions RoomLaser() {
  ScanOptions options;
  options.max_range_m = 10.0;
  options.range_noise_m = 0.005;
  return options;
}

inline SimulatedDrive Simulate(const std::vector<Segment>& world, const std::vector<Pose2>& truth,
                               unsigned seed, const ScanOptions& options = RoomLaser()) {
  SimulatedDrive run;
  run.truth = truth;
  std::mt19937 rng(seed);
  const FlirtExtractor extractor;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    LogScan scan;
    static_cast<LaserScan&>(scan) = CastScan(world, truth[i], options, &rng);
    scan.timestamp_s = scan.logger_timestamp_s = 0.1 * static_cast<double>(i);
    run.keypoints.push_back(extractor.Extract(scan, truth[i]));
    run.scans.push_back(std::move(scan));
  }
  return run;
}

// The map of the two rooms: round room A, along the corridor, round room B (true poses).
inline GlobalMap TwoRoomsMap() {
  const SimulatedDrive mapping = Simulate(TwoRooms(),
                                          Drive({{-10, 2},
                                                 {-12, 2},
                                                 {-12, -2},
                                                 {-8, -2},
                                                 {-8, 2},
                                                 {-10, 2},
                                                 {-10, 8},
                                                 {10, 8},
                                                 {10, 2},
                                                 {12, 2},
                                                 {12, -2},
                                                 {8, -2},
                                                 {8, 2},
                                                 {10, 2}}),
                                          1);
  return BuildGlobalMap({mapping.scans, mapping.truth, mapping.keypoints}, MappingConfig{});
}

}  // namespace keyplace::testing
