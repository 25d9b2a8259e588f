// Two identical rooms joined by a corridor: a robot kidnapped into one of them must not believe
// it knows which until it drives somewhere that tells them apart, and then it must know.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "registration/synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::Segment;

void Append(std::vector<Segment>& world, const std::vector<Segment>& more) {
  world.insert(world.end(), more.begin(), more.end());
}

// A small box of random size and turn centred at `centre`.
std::vector<Segment> Box(const Eigen::Vector2d& centre, std::mt19937& rng) {
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
  return testing::Polygon(corners);
}

// An 8 x 8 m room centred at (ox, 0) with boxes along its walls (the same seed: the same room),
// a 1.5 m door in its north wall and a 3 m stub up to the corridor.
std::vector<Segment> Room(double ox) {
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
std::vector<Segment> TwoRooms() {
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
std::vector<Pose2> Drive(const std::vector<Eigen::Vector2d>& waypoints) {
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

SimulatedDrive Simulate(const std::vector<Segment>& world, const std::vector<Pose2>& truth,
                        unsigned seed) {
  SimulatedDrive run;
  run.truth = truth;
  testing::ScanOptions options;
  options.max_range_m = 10.0;
  options.range_noise_m = 0.005;
  std::mt19937 rng(seed);
  const FlirtExtractor extractor;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    LogScan scan;
    static_cast<LaserScan&>(scan) = testing::CastScan(world, truth[i], options, &rng);
    scan.timestamp_s = scan.logger_timestamp_s = 0.1 * static_cast<double>(i);
    run.keypoints.push_back(extractor.Extract(scan, truth[i]));
    run.scans.push_back(std::move(scan));
  }
  return run;
}

// Verified candidates put the robot in both rooms (x < 0 and x > 0).
bool MatchedBothRooms(const PlaceMatch& match) {
  bool west = false;
  bool east = false;
  for (const CandidateResult& candidate : match.verified_candidates) {
    (candidate.estimated_pose.x < 0.0 ? west : east) = true;
  }
  return west && east;
}

bool Near(const Pose2& a, const Pose2& b) {
  const Pose2 difference = Between(a, b);
  return TranslationNorm(difference) < 0.5 && std::abs(difference.theta) < 10.0 * M_PI / 180.0;
}

struct QueryOutcome {
  int confused_answers = 0;  // answers in room B or its stub that matched both rooms
  int fixes_in_room = 0;     // fixed updates while in room B or its stub
  int wrong_fixes = 0;       // fixed updates more than 0.5 m / 10 deg off
  int fixes = 0;
};

// The map: round room A, along the corridor, round room B. The query: kidnapped into room B,
// round it, up the stub, west along the corridor.
QueryOutcome KidnappedIntoRoomB(const LocalizerConfig& config) {
  const std::vector<Segment> world = TwoRooms();
  const SimulatedDrive mapping = Simulate(world,
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
  const GlobalMap map =
      BuildGlobalMap({mapping.scans, mapping.truth, mapping.keypoints}, MappingConfig{});
  const SimulatedDrive query =
      Simulate(world, Drive({{12, -2}, {8, -2}, {8, 2}, {10, 2}, {10, 8}, {-3, 8}}), 2);
  // Odometry starts where the robot woke up: the map <- odometry transform is unknown.
  const Pose2 T_world_odom = query.truth.front();
  Relocalizer relocalizer(map, config);
  QueryOutcome outcome;
  for (std::size_t i = 0; i < query.scans.size(); ++i) {
    const Pose2 T_odom_robot = T_world_odom.inverse() * query.truth[i];
    const RelocalizationUpdate update = relocalizer.AddScan(query.scans[i], T_odom_robot);
    const bool in_room_or_stub = query.truth[i].y < 7.0;
    if (in_room_or_stub && update.answer && MatchedBothRooms(update.answer->match)) {
      ++outcome.confused_answers;
    }
    if (update.status != FixStatus::kFixed) continue;
    ++outcome.fixes;
    if (in_room_or_stub) ++outcome.fixes_in_room;
    if (!Near(update.T_world_robot, query.truth[i])) ++outcome.wrong_fixes;
  }
  return outcome;
}

TEST(TwoRooms, NoFixUntilMotionTellsTheRoomsApartThenTheRightOne) {
  const QueryOutcome outcome = KidnappedIntoRoomB(LocalizerConfig{});
  // The rooms did look alike (an answer matched both)...
  EXPECT_GT(outcome.confused_answers, 0);
  // ... so no fix until the corridor told them apart, and then only right ones.
  EXPECT_EQ(outcome.fixes_in_room, 0);
  EXPECT_GT(outcome.fixes, 0);
  EXPECT_EQ(outcome.wrong_fixes, 0);
}

TEST(TwoRooms, WithoutTheTemporalCheckTheWrongRoomIsAFix) {
  LocalizerConfig config;
  config.fix.confirmations = 1;  // every accepted answer is a fix
  const QueryOutcome outcome = KidnappedIntoRoomB(config);
  EXPECT_GT(outcome.wrong_fixes, 0);
}

}  // namespace
}  // namespace keyplace
