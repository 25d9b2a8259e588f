// Two identical rooms joined by a corridor: a robot kidnapped into one of them must not believe
// it knows which until it drives somewhere that tells them apart, and then it must know.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "localization/simulated_drive.hpp"

namespace keyplace {
namespace {

using testing::Drive;
using testing::Segment;
using testing::Simulate;
using testing::SimulatedDrive;
using testing::TwoRooms;

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
  const GlobalMap map = testing::TwoRoomsMap();
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
  LocalizerConfig config;
  config.map_search_window_m = 0.0;  // the keypoints' answers alone
  const QueryOutcome outcome = KidnappedIntoRoomB(config);
  // The rooms did look alike (an answer matched both)...
  EXPECT_GT(outcome.confused_answers, 0);
  // ... so no fix until the corridor told them apart, and then only right ones.
  EXPECT_EQ(outcome.fixes_in_room, 0);
  EXPECT_GT(outcome.fixes, 0);
  EXPECT_EQ(outcome.wrong_fixes, 0);
}

TEST(TwoRooms, TheSearchOfTheWholeMapDoesNotFixInOneOfTheRoomsEither) {
  const QueryOutcome outcome = KidnappedIntoRoomB(LocalizerConfig{});  // the search is on
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
