// The kidnapped-robot benchmark's figures that say whether a start had a fair chance: the path a
// start has left after it first meets ground the map has seen (StartRecord::room_after_revisit_m)
// and the fixed fraction over the starts with room (RelocalizationSummary::fixed_with_room).

#include <cstddef>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "support/bundled_map.hpp"

namespace keyplace {
namespace {

StartRecord StartWith(bool revisit, double room_m, bool fixed) {
  StartRecord record;
  record.revisit = revisit;
  record.room_after_revisit_m = room_m;
  record.fixed = fixed;
  return record;
}

TEST(RelocalizationSummary, TheFixedFractionWithRoomCountsStartsWithRoomAfterTheirRevisitOnly) {
  RelocalizationOptions options;
  options.revisit_room_m = 10.0;
  const std::vector<StartRecord> records = {
      StartWith(true, 2.0, false),    // met the map 2 m before it stopped: no room
      StartWith(true, 10.0, true),    // room, fixed
      StartWith(true, 30.0, false),   // room, not fixed
      StartWith(false, 40.0, false),  // no revisit: never counts
      StartWith(true, 1.0, true),     // fixed without room: counts in the plain fraction only
  };
  const RelocalizationSummary s = SummarizeRelocalization(records, options);
  EXPECT_EQ(s.starts_with_revisit, 4U);
  EXPECT_EQ(s.fixed_with_revisit, 2U);
  EXPECT_DOUBLE_EQ(s.fixed_fraction, 0.5);
  EXPECT_EQ(s.starts_with_room, 2U);
  EXPECT_EQ(s.fixed_with_room, 1U);
  EXPECT_DOUBLE_EQ(s.fixed_fraction_with_room, 0.5);

  options.revisit_room_m = 0.0;  // every start with a revisit has room
  const RelocalizationSummary all = SummarizeRelocalization(records, options);
  EXPECT_EQ(all.starts_with_room, all.starts_with_revisit);
  EXPECT_DOUBLE_EQ(all.fixed_fraction_with_room, all.fixed_fraction);
}

// The searches of the whole map run within the updates: their time is counted per search and
// taken out of the updates' mean for what a node (searching in the background) spends per scan.
TEST(RelocalizationSummary, TheSearchesOfTheWholeMapAreTimedApartFromTheUpdates) {
  StartRecord searching = StartWith(true, 10.0, false);
  searching.start_scan = 0;
  searching.end_scan = 100;
  searching.update_seconds_mean = 0.012;  // 1.2 s over 100 updates
  searching.map_searches = 4;
  searching.map_search_seconds = 1.0;
  StartRecord fixed_at_once = StartWith(true, 10.0, true);
  fixed_at_once.start_scan = 200;
  fixed_at_once.end_scan = 300;
  fixed_at_once.update_seconds_mean = 0.002;  // 0.2 s, no search
  const RelocalizationSummary s =
      SummarizeRelocalization({searching, fixed_at_once}, RelocalizationOptions{});
  EXPECT_EQ(s.map_searches, 4U);
  EXPECT_NEAR(s.map_search_seconds_mean, 0.25, 1e-12);
  EXPECT_NEAR(s.update_seconds_mean, 0.007, 1e-12);
  EXPECT_NEAR(s.update_seconds_mean_without_search, 0.002, 1e-12);
}

TEST(RelocalizationOptions, TakeTheRoomFromTheEvaluationSettingsAndRefuseANegativeOne) {
  EvaluationConfig evaluation;
  evaluation.revisit_room_m = 4.0;
  EXPECT_DOUBLE_EQ(RelocalizationOptionsFor(evaluation, 5, true, true).revisit_room_m, 4.0);
  evaluation.revisit_room_m = -1.0;
  EXPECT_THROW(Validate(evaluation), std::invalid_argument);
}

double PathMetres(const std::vector<Pose2>& poses, std::size_t from, std::size_t to) {
  double metres = 0.0;
  for (std::size_t k = from + 1; k <= to; ++k) {
    metres += TranslationNorm(Between(poses[k - 1], poses[k]));
  }
  return metres;
}

// A start that is never fixed runs until the give-up distance or the log's end: the room after
// its revisit is the path from the revisit to the last scan it was fed (the revisit search and
// the benchmark's feed stop by one rule). A place recognizer that needs more inliers than a place
// holds keypoints answers nothing, so no start is fixed. The log's end is not reached here: a run
// to it costs 15 s.
TEST(Relocalization, RoomAfterRevisitIsThePathAnUnfixedStartHadLeft) {
  const testing::BundledMap& b = testing::BundledFr079();
  RelocalizationOptions options;
  options.starts = 12;
  options.give_up_m = 6.0;  // every start gives up before the log's end
  LocalizerConfig config;
  config.place.min_consensus = 100000;
  std::size_t with_revisit = 0;
  std::size_t revisit_after_the_start = 0;  // the room is not the whole path fed
  for (const StartRecord& r : RunRelocalization(b.map, b.inputs, b.truth, config, options)) {
    ASSERT_FALSE(r.fixed);
    ASSERT_LT(r.end_scan, static_cast<int>(b.inputs.poses.size()));
    if (!r.revisit) continue;
    ++with_revisit;
    revisit_after_the_start += r.distance_to_revisit_m > 0.0 ? 1 : 0;
    const double fed_m = PathMetres(b.inputs.poses, static_cast<std::size_t>(r.start_scan),
                                    static_cast<std::size_t>(r.end_scan - 1));
    EXPECT_NEAR(r.distance_to_revisit_m + r.room_after_revisit_m, fed_m, 1e-9) << r.start_scan;
    EXPECT_GE(r.room_after_revisit_m, 0.0);
    EXPECT_LE(fed_m, options.give_up_m);
  }
  EXPECT_GE(with_revisit, 6U);  // the bundled log revisits most of its ground
  EXPECT_GE(revisit_after_the_start, 1U);
}

}  // namespace
}  // namespace keyplace
