// A fix carried by odometry that turned without the robot (a fast turn the odometry missed, a
// wheel glitch) must be given up as soon as the scans stop fitting the map, not reported with
// the confidence of the answers that made it.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/localization/track_check.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "localization/simulated_drive.hpp"

namespace keyplace {
namespace {

using testing::DegToRad;
using testing::Drive;
using testing::Simulate;
using testing::SimulatedDrive;
using testing::TwoRooms;

// Room A, the corridor and room B: the map. The query runs the corridor from its east end to
// its west end and down into room A.
struct World {
  GlobalMap map;
  SimulatedDrive query;
};

const World& SharedWorld() {
  static const World world = [] {
    World w;
    w.map = testing::TwoRoomsMap();
    w.query = Simulate(TwoRooms(), Drive({{13, 8}, {-10, 8}, {-10, 2}, {-12, 2}, {-12, -2}}), 2);
    return w;
  }();
  return world;
}

bool OnTruth(const Pose2& a, const Pose2& b) {
  const Pose2 difference = Between(a, b);
  return TranslationNorm(difference) < 0.5 && std::abs(difference.theta) < DegToRad(10.0);
}

// The scans of the query from `first` to `last` (exclusive) in a TrackCheck, odometry = truth.
TrackCheck RecentScans(const SimulatedDrive& drive, std::size_t first, std::size_t last) {
  TrackCheck check;
  for (std::size_t i = first; i < last; ++i) {
    check.AddScan(drive.scans[i], drive.truth[i], static_cast<int>(i));
  }
  return check;
}

TEST(TrackCheck, ATurnedFixIsSuspectedThenFoundOffByTheNextScans) {
  const World& world = SharedWorld();
  const PlaceRecognizer recognizer(PlacesFromMap(world.map), PlaceRecognitionConfig{});
  const PlaceRecognitionConfig place;
  // Odometry frame = world frame: the true fix is the identity.
  for (const std::size_t at : {20U, 80U, 140U}) {
    SCOPED_TRACE(at);
    TrackCheck right = RecentScans(world.query, at - 10, at);
    EXPECT_EQ(right.Check(recognizer, place, Pose2(), {}).fit, TrackFit::kFits);
    // The fix turned by 30 degrees about the robot: what a missed fast turn leaves.
    const Pose2 robot = world.query.truth[at - 1];
    const Pose2 turned = robot * Pose2(0, 0, DegToRad(30.0)) * robot.inverse();
    TrackCheck wrong = RecentScans(world.query, at - 10, at);
    const TrackCheckResult suspected = wrong.Check(recognizer, place, turned, {});
    EXPECT_NE(suspected.fit, TrackFit::kMisfit);  // one look may be a look-alike
    EXPECT_GE(suspected.best_hit_fraction, 0.8);
    EXPECT_LT(suspected.latest_hit_fraction, suspected.best_hit_fraction - 0.3);
    EXPECT_TRUE(OnTruth(suspected.T_world_odom_best * robot, robot));
    // Ten scans later the same error still holds, and the suspect fits the new scans.
    for (std::size_t i = at; i < at + 10; ++i) {
      wrong.AddScan(world.query.scans[i], world.query.truth[i], static_cast<int>(i));
    }
    const TrackCheckResult found = wrong.Check(recognizer, place, turned, {});
    EXPECT_EQ(found.fit, TrackFit::kMisfit);
    EXPECT_TRUE(
        OnTruth(found.T_world_odom_best * world.query.truth[at + 9], world.query.truth[at + 9]));
  }
}

TEST(TrackCheck, NothingToSayAwayFromTheMapOrWhereEveryPlaceIsExcluded) {
  const World& world = SharedWorld();
  const PlaceRecognizer recognizer(PlacesFromMap(world.map), PlaceRecognitionConfig{});
  TrackCheck check = RecentScans(world.query, 40, 50);
  EXPECT_EQ(check.Check(recognizer, {}, Pose2(100.0, 0.0, 0.0), {}).fit, TrackFit::kUnknown);
  const QueryExclusion everything = [](const Place&, const std::vector<int>&) { return true; };
  EXPECT_EQ(check.Check(recognizer, {}, Pose2(), everything).fit, TrackFit::kUnknown);
  TrackCheck empty;
  EXPECT_EQ(empty.Check(recognizer, {}, Pose2(), {}).fit, TrackFit::kUnknown);
}

struct GlitchOutcome {
  int fixed_before = 0;               // fixed updates before the glitch
  int wrong_fixed_after = 0;          // fixed updates off the truth after it, among the boxes
  int misfit_losses = 0;              // fixes given up by the track check
  int fitting_checks = 0;             // checks that found the scans on the walls
  double lost_after_glitch_m = -1.0;  // odometry from the glitch to the first loss (-1: none)
};

// The query with its odometry turned by 35 degrees at scan `glitch` (the odometry saw a turn the
// robot did not make).
GlitchOutcome RunWithGlitch(const LocalizerConfig& config, std::size_t glitch) {
  const World& world = SharedWorld();
  const Pose2 error(0, 0, DegToRad(35.0));
  Relocalizer relocalizer(world.map, config);
  GlitchOutcome outcome;
  double travelled_m = 0.0;
  for (std::size_t i = 0; i < world.query.scans.size(); ++i) {
    Pose2 T_odom_robot = world.query.truth[i];
    if (i >= glitch) {
      const Pose2& at = world.query.truth[glitch];
      T_odom_robot = at * error * Between(at, world.query.truth[i]);
    }
    if (i > glitch) {
      travelled_m += TranslationNorm(Between(world.query.truth[i - 1], world.query.truth[i]));
    }
    const RelocalizationUpdate update = relocalizer.AddScan(world.query.scans[i], T_odom_robot);
    if (update.track_fit == TrackFit::kFits) ++outcome.fitting_checks;
    if (update.track_misfit) {
      ++outcome.misfit_losses;
      if (outcome.lost_after_glitch_m < 0.0 && i >= glitch)
        outcome.lost_after_glitch_m = travelled_m;
    }
    if (update.status != FixStatus::kFixed) continue;
    if (i < glitch) ++outcome.fixed_before;
    const bool among_boxes = world.query.truth[i].x > -7.0;  // the corridor's telling part
    if (i >= glitch && among_boxes && !OnTruth(update.T_world_robot, world.query.truth[i])) {
      ++outcome.wrong_fixed_after;
    }
  }
  return outcome;
}

// The glitch comes in the corridor's east half, among the boxes that tell the rooms apart (its
// ends look alike: a fix lost there may come back in the wrong room).
constexpr std::size_t kGlitchScan = 50;

TEST(TrackCheck, AFixTurnedByAnOdometryGlitchIsGivenUpWithinTwoMetres) {
  ASSERT_GT(SharedWorld().query.scans.size(), kGlitchScan + 60);
  const GlitchOutcome outcome = RunWithGlitch(LocalizerConfig{}, kGlitchScan);
  ASSERT_GT(outcome.fixed_before, 0);  // the fix came before the glitch
  EXPECT_EQ(outcome.misfit_losses, 1);
  EXPECT_GE(outcome.lost_after_glitch_m, 0.0);
  EXPECT_LE(outcome.lost_after_glitch_m, 2.2);
  // Until the check gives it up (the first check after the glitch suspects it, the next confirms
  // it), the turned fix is reported: up to two metres of scans (0.15 m apart).
  EXPECT_LE(outcome.wrong_fixed_after, 15);
}

TEST(TrackCheck, WithoutTheCheckTheTurnedFixIsReportedOnAndOn) {
  LocalizerConfig config;
  config.fix.track_check_every_m = 0.0;
  const GlitchOutcome outcome = RunWithGlitch(config, kGlitchScan);
  ASSERT_GT(outcome.fixed_before, 0);
  EXPECT_EQ(outcome.misfit_losses, 0);
  EXPECT_GE(outcome.wrong_fixed_after, 20);
}

TEST(TrackCheck, NoCorrectFixIsGivenUpWithoutAGlitch) {
  const GlitchOutcome outcome = RunWithGlitch(LocalizerConfig{}, SharedWorld().query.scans.size());
  ASSERT_GT(outcome.fixed_before, 0);
  EXPECT_GT(outcome.fitting_checks, 20);  // checked every metre of the 30 m drive
  EXPECT_EQ(outcome.misfit_losses, 0);
}

}  // namespace
}  // namespace keyplace
