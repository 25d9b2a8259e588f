// keyplace merge (issue 16): the second half of the bundled log, mapped in a frame of its own, is
// found in the first half's map, and two different buildings are refused.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/localization/map_merge.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "support/bundled_map.hpp"
#include "support/result_fields_checks.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

constexpr int kSplitScan = 732;  // the middle of the bundled log

// The bundled map's submaps that end before the split (A) or start after it (B).
GlobalMap Half(bool first) {
  GlobalMap half = testing::BundledFr079().map;
  half.submaps.clear();
  for (const Submap& submap : testing::BundledFr079().map.submaps) {
    if (first ? submap.last_scan() < kSplitScan : submap.first_scan() >= kSplitScan) {
      half.submaps.push_back(submap);
    }
  }
  return half;
}

PlaceRecognitionConfig Strict() { return PlacePreset("strict"); }

TEST(MapMerge, TheSecondHalfInAFrameOfItsOwnIsFoundInTheFirst) {
  const GlobalMap a = Half(true);
  // B as a robot starting the second half at its own origin would have mapped it: its frame is
  // the pose of its first scan.
  const GlobalMap b_world = Half(false);
  const Pose2 T_world_b = b_world.submaps.front().origin();
  const GlobalMap b = MovedMap(b_world, T_world_b.inverse());
  std::vector<std::size_t> done;
  const MergeResult result = MergeMaps(a, b, Strict(), {}, [&](std::size_t d, std::size_t total) {
    EXPECT_EQ(total, b.submaps.size());
    done.push_back(d);
  });
  // Progress after each B submap recognised, counting up to all of them.
  ASSERT_EQ(done.size(), b.submaps.size());
  for (std::size_t k = 0; k < done.size(); ++k) EXPECT_EQ(done[k], k + 1);
  // A is in the world frame, so B's frame in A's is T_world_b.
  const Pose2 error = Between(T_world_b, result.T_a_b);
  EXPECT_LT(std::hypot(error.x, error.y), 0.1) << error.x << " " << error.y;
  EXPECT_LT(std::abs(error.theta), 0.5 * M_PI / 180.0) << error.theta;
  EXPECT_GE(result.agreeing, 3U);
  EXPECT_EQ(result.queried, b.submaps.size());
  std::size_t agreeing = 0;
  for (const SubmapRecognition& recognition : result.recognitions) agreeing += recognition.agrees;
  EXPECT_EQ(agreeing, result.agreeing);
  // The merged map: A unchanged, then B back where it was, with ids after a gap and scans after
  // A's.
  ASSERT_EQ(result.merged.submaps.size(), a.submaps.size() + b.submaps.size());
  EXPECT_EQ(result.merged.submaps.front().origin().x, a.submaps.front().origin().x);
  const Submap& first_b = result.merged.submaps[a.submaps.size()];
  // Ids from the second thousand after A's, scans right after A's, keypoints' scans alike.
  EXPECT_EQ(first_b.id % 1000, 0);
  EXPECT_GE(first_b.id - a.submaps.back().id, 1000);
  EXPECT_EQ(first_b.first_scan(), a.submaps.back().last_scan() + 1);
  const int scan_offset = first_b.first_scan() - b.submaps.front().first_scan();
  for (std::size_t k = 0; k < b.submaps.size(); ++k) {
    const Submap& merged = result.merged.submaps[a.submaps.size() + k];
    for (std::size_t i = 0; i < merged.keypoints.size(); ++i) {
      EXPECT_EQ(merged.keypoints[i].scan_index, b.submaps[k].keypoints[i].scan_index + scan_offset);
    }
  }
  const Pose2 moved_error = Between(b_world.submaps.front().origin(), first_b.origin());
  EXPECT_LT(std::hypot(moved_error.x, moved_error.y), 0.1);
  EXPECT_TRUE(result.merged.source_hash.empty());
}

// A map of another building: the Intel lab's first 600 scans.
GlobalMap IntelMap() {
  LogInputOptions options;
  options.end_scan = 600;
  const LogInputs inputs =
      PrepareLogInputs(testing::SharedFile("data/intel-corrected.log.gz"), options);
  return MapLog(inputs, MappingConfig{}).map;
}

TEST(MapMerge, TwoBuildingsAreRefusedWithTheReason) {
  const GlobalMap fr079 = Half(true);
  try {
    MergeMaps(fr079, IntelMap(), Strict());
    FAIL() << "merged two buildings";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("no reliable overlap"), std::string::npos) << message;
    EXPECT_NE(message.find("same building"), std::string::npos) << message;
  }
  GlobalMap other_settings = Half(false);
  other_settings.config.cell_size_m = 0.2;
  try {
    MergeMaps(fr079, other_settings, Strict());
    FAIL() << "merged maps of different settings";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("mapping.cell_size_m"), std::string::npos)
        << error.what();
  }
}

TEST(MergeResultFields, EachFigureReadsItsOwnMember) {
  MergeResult result;
  result.queried = 7;
  result.recognitions.resize(5);
  result.agreeing = 3;
  result.merged.submaps.resize(11);
  ExpectWellFormed(MergeResultFields(), result);
  EXPECT_EQ(ValueOf(MergeResultFields(), result, "recognised"), ResultValue(std::int64_t{5}));
  EXPECT_EQ(ValueOf(MergeResultFields(), result, "submaps_merged"), ResultValue(std::int64_t{11}));

  SubmapRecognition recognition;
  recognition.submap_b = 2;
  recognition.submap_a = 4;
  recognition.confidence = 0.5;
  recognition.agrees = true;
  ExpectWellFormed(SubmapRecognitionFields(), recognition);
  EXPECT_EQ(ValueOf(SubmapRecognitionFields(), recognition, "submap_a"),
            ResultValue(std::int64_t{4}));
}

}  // namespace
}  // namespace keyplace
