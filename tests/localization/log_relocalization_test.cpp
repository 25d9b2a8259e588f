// RelocalizeLog: a log without truth relocalized as a robot would be (keyplace relocalize without
// --truth): the second half of the bundled log, its poses moved into an odometry frame, against
// a map of the first half.

#include "keyplace/localization/log_relocalization.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/config/config.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "support/bundled_map.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using testing::BundledFr079;

constexpr std::size_t kMapScans = 732;
const Pose2 kT_odom_world(3.0, -7.0, 0.8);  // the odometry frame is not the map's

GlobalMap FirstHalfMap() {
  const LogInputs& inputs = BundledFr079().inputs;
  const std::vector<LogScan> scans(inputs.log.scans.begin(), inputs.log.scans.begin() + kMapScans);
  const std::vector<Pose2> poses(inputs.poses.begin(), inputs.poses.begin() + kMapScans);
  const std::vector<std::vector<Keypoint>> keypoints(inputs.keypoints.begin(),
                                                     inputs.keypoints.begin() + kMapScans);
  return BuildGlobalMap({scans, poses, keypoints}, MappingConfig{});
}

// The second half as a robot would record it: odometry poses in its own frame, no truth.
LogInputs SecondHalfWithoutTruth() {
  const LogInputs& all = BundledFr079().inputs;
  LogInputs inputs;
  inputs.source_log = "second-half";
  inputs.first_scan = kMapScans;
  inputs.log.scans.assign(all.log.scans.begin() + kMapScans, all.log.scans.end());
  inputs.keypoints.assign(all.keypoints.begin() + kMapScans, all.keypoints.end());
  for (std::size_t k = kMapScans; k < all.poses.size(); ++k) {
    inputs.poses.push_back(kT_odom_world * all.poses[k]);
  }
  return inputs;
}

TEST(RelocalizeLog, FixesTheSecondHalfWithoutTruthAndKeepsEveryScansStatus) {
  const GlobalMap map = FirstHalfMap();
  const LogInputs inputs = SecondHalfWithoutTruth();
  const LocalizerConfig config = ToLocalizerConfig(PresetConfig("strict"));
  std::size_t progress_calls = 0;
  const LogRelocalization run =
      RelocalizeLog(map, inputs, config, [&](std::size_t done, std::size_t total) {
        EXPECT_EQ(done, ++progress_calls);
        EXPECT_EQ(total, inputs.log.scans.size());
      });
  ASSERT_EQ(run.scans.size(), inputs.log.scans.size());
  EXPECT_EQ(progress_calls, inputs.log.scans.size());
  ASSERT_TRUE(run.first_fix.has_value()) << run.answers << " answers";
  ASSERT_TRUE(run.first_fix_pose.has_value());
  EXPECT_EQ(run.first_fix_pose->frame_id, "map");

  const std::vector<Pose2>& truth = BundledFr079().inputs.poses;  // map frame
  std::size_t new_fixes = 0, losses = 0, answers = 0, fixed = 0;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const RelocalizedScan& scan = run.scans[i];
    EXPECT_EQ(scan.scan, kMapScans + i);
    EXPECT_EQ(scan.stamp_s, inputs.log.scans[i].timestamp_s);
    if (i > 0) {
      EXPECT_GE(scan.odometry_m, run.scans[i - 1].odometry_m);
    }
    if (run.losses == 0) {
      EXPECT_EQ(scan.status == FixStatus::kFixed, i >= *run.first_fix) << i;
    }
    new_fixes += scan.new_fix;
    losses += scan.lost;
    answers += scan.answered;
    if (scan.status != FixStatus::kFixed) continue;
    ++fixed;
    // Every reported pose is the robot's true pose in the map (0.5 m, 10 deg).
    const Pose2 error = Between(truth[scan.scan], scan.T_world_robot);
    EXPECT_LT(TranslationNorm(error), 0.5) << "scan " << scan.scan;
    EXPECT_LT(std::abs(error.theta), 10.0 * M_PI / 180.0) << "scan " << scan.scan;
    EXPECT_GT(scan.confidence, 0.0);
  }
  EXPECT_EQ(new_fixes, run.fixes);
  EXPECT_EQ(losses, run.losses);
  EXPECT_EQ(answers, run.answers);
  EXPECT_GT(fixed, run.scans.size() / 2) << "fixed at " << fixed << " scans";
  EXPECT_EQ(run.first_fix_pose->T_map_robot.x, run.scans[*run.first_fix].T_world_robot.x);
  EXPECT_GT(run.update_seconds_max, 0.0);
  EXPECT_LE(run.update_seconds_mean, run.update_seconds_max);
}

// With retrieval `words` and one place retrieved, the words alone rarely bring the place that
// would confirm an answer; the Relocalizer hands its answers to the localizer as beliefs
// (LocalizerConfig::search_near_m), whose queries then also pair the places near them.
TEST(RelocalizeLog, AnswersHeldMakeTheQueriesAlsoPairThePlacesTheyPointTo) {
  const GlobalMap map = FirstHalfMap();
  const LogInputs inputs = SecondHalfWithoutTruth();
  const auto fixed_scans = [&](double search_near_m) {
    LocalizerConfig config = ToLocalizerConfig(PresetConfig("strict"));
    config.place.retrieval = PlaceRecognitionConfig::Retrieval::kWords;
    config.place.retrieval_places = 1;
    config.search_near_m = search_near_m;
    const LogRelocalization run = RelocalizeLog(map, inputs, config, nullptr);
    std::size_t fixed = 0;
    for (const RelocalizedScan& scan : run.scans) fixed += scan.status == FixStatus::kFixed;
    return fixed;
  };
  const std::size_t words_alone = fixed_scans(0.0);
  // Measured: 512 scans fixed with the words alone, 538 with the places near the answers.
  EXPECT_GT(fixed_scans(3.0), words_alone + 10) << "words alone " << words_alone;
}

// With retrieval `auto` (the default) the Relocalizer's queries pair every place while it searches
// and, once it holds a fix, only the places the words retrieve and those near its beliefs (the
// fix and the answers that challenge it, place.retrieval_places each); the fix holds as well.
TEST(RelocalizeLog, HoldingAFixTheQueriesPairTheRetrievedPlacesOnly) {
  const GlobalMap map = FirstHalfMap();
  const LogInputs inputs = SecondHalfWithoutTruth();
  LocalizerConfig config = ToLocalizerConfig(PresetConfig("strict"));
  ASSERT_EQ(config.place.retrieval, PlaceRecognitionConfig::Retrieval::kAuto);
  config.place.retrieval_places = 5;
  Relocalizer relocalizer(map, config);
  int most_searching = 0, most_tracking = 0, tracking_answers = 0, fixed = 0;
  for (std::size_t k = 0; k < inputs.log.scans.size(); ++k) {
    const bool tracking = relocalizer.status() == FixStatus::kFixed;
    const RelocalizationUpdate update = relocalizer.AddScan(
        inputs.log.scans[k], inputs.poses[k], inputs.keypoints[k], static_cast<int>(k));
    fixed += update.status == FixStatus::kFixed;
    if (!update.answer) continue;
    int& most = tracking ? most_tracking : most_searching;
    most = std::max(most, update.answer->match.candidates);
    tracking_answers += tracking;
  }
  EXPECT_GT(tracking_answers, 20);
  // Measured: at most 10 candidates while tracking, 122 while searching.
  EXPECT_LE(most_tracking, 15);  // the words' 5 and 5 near each belief: a margin over 10
  EXPECT_GT(most_searching, 15);
  EXPECT_GT(fixed, static_cast<int>(inputs.log.scans.size()) / 2);
}

TEST(RelocalizeLog, InputsWithoutAPosePerScanAreRefusedNamingTheLog) {
  LogInputs inputs = SecondHalfWithoutTruth();
  inputs.poses.pop_back();
  try {
    RelocalizeLog(FirstHalfMap(), inputs, LocalizerConfig{});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    testing::ExpectContains(error.what(), "second-half: relocalizing needs a pose and keypoints");
  }
}

}  // namespace
}  // namespace keyplace
