// LocalizeLogAgainstMap (keyplace localize as one call) against its steps called one by one, the
// way the command called them before, on the bundled FR079 log and map.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/map_localization.hpp"
#include "support/bundled_map.hpp"

namespace keyplace {
namespace {

constexpr int kQueries = 40;

// The bundled map with the provenance `keyplace map` records: made from the bundled log.
GlobalMap MapOfTheLog(const testing::BundledMap& b) {
  GlobalMap map = b.map;
  map.source_log = "fr079-corrected.log.gz";
  map.source_hash = b.truth.truth_log_hash;
  return map;
}

TEST(MapLocalization, EqualsItsStepsOneByOne) {
  const testing::BundledMap& b = testing::BundledFr079();
  const PlaceRecognitionConfig place;
  const EvaluationConfig evaluation;
  std::vector<std::string> stages;
  MapLocalizationOptions options;
  options.n_pos = kQueries;
  options.rank_by = RankBy::kGamma;
  const GlobalMap map = MapOfTheLog(b);
  ASSERT_FALSE(map.source_hash.empty());
  const MapLocalization result =
      LocalizeLogAgainstMap(b.inputs, b.truth, map, place, evaluation, options,
                            [&](const std::string& stage, std::size_t, std::size_t) {
                              if (stages.empty() || stages.back() != stage) stages.push_back(stage);
                            });
  EXPECT_EQ(stages, (std::vector<std::string>{"query submaps", "localize"}));

  const std::vector<int> starts = QueryStarts(b.truth, kQueries);
  const std::vector<LocalizationQuery> queries =
      BuildSubmapQueries(b.inputs, b.truth, b.map.config, starts, place.query_keypoints);
  const PlaceRecognizer recognizer(PlacesFromMap(b.map), place);
  std::vector<LocalizationRecord> records =
      EvaluateQueries(queries, recognizer, SelfMatchRule::kSameScans);
  MarkRevisitable(queries, b.map.submaps, SelfMatchRule::kSameScans, evaluation, records);
  const LocalizationSummary summary = Summarize(records, RankBy::kGamma);

  EXPECT_EQ(result.starts, starts);
  EXPECT_TRUE(result.truth_is_map_log);
  EXPECT_EQ(result.self_match, SelfMatchRule::kSameScans);
  EXPECT_EQ(result.places, b.map.submaps.size());
  ASSERT_EQ(result.records.size(), records.size());
  ASSERT_GT(records.size(), static_cast<std::size_t>(kQueries) * 9 / 10);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const LocalizationRecord& got = result.records[i];
    EXPECT_EQ(got.start_scan, records[i].start_scan);
    EXPECT_EQ(got.match.place_id, records[i].match.place_id);
    EXPECT_EQ(got.match.estimated_pose.x, records[i].match.estimated_pose.x);
    EXPECT_EQ(got.match.places_excluded, records[i].match.places_excluded);
    EXPECT_EQ(got.correct, records[i].correct);
    EXPECT_EQ(got.revisitable, records[i].revisitable);
  }
  EXPECT_EQ(result.summary.n_acc, summary.n_acc);
  EXPECT_EQ(result.summary.n_cor, summary.n_cor);
  EXPECT_EQ(result.summary.n_revisitable, summary.n_revisitable);
  EXPECT_EQ(result.summary.p_gl, summary.p_gl);
  EXPECT_EQ(result.summary.rank_by, RankBy::kGamma);
  EXPECT_GT(result.summary.precision, 0.9);
}

TEST(MapLocalization, AnotherRecordingExcludesNoSelfMatch) {
  const testing::BundledMap& b = testing::BundledFr079();
  GroundTruth other = b.truth;
  other.truth_log_hash = "crc32:00000000:1";  // another file than the map's log
  const GlobalMap map = MapOfTheLog(b);
  MapLocalizationOptions options;
  options.n_pos = 5;
  options.self_match = SelfMatchRule::kSharedScan;
  const MapLocalization result = LocalizeLogAgainstMap(b.inputs, other, b.map, {}, {}, options);
  EXPECT_FALSE(result.truth_is_map_log);
  EXPECT_EQ(result.self_match, SelfMatchRule::kNone);
  ASSERT_FALSE(result.records.empty());
  for (const LocalizationRecord& record : result.records) {
    EXPECT_EQ(record.match.places_excluded, 0);
  }
}

TEST(MapLocalization, RejectsBadSettingsBeforeAnyWork) {
  const testing::BundledMap& b = testing::BundledFr079();
  MapLocalizationOptions options;
  options.n_pos = 0;
  EXPECT_THROW(LocalizeLogAgainstMap(b.inputs, b.truth, b.map, {}, {}, options),
               std::invalid_argument);
  PlaceRecognitionConfig place;
  place.min_pairs = -1;
  EXPECT_THROW(LocalizeLogAgainstMap(b.inputs, b.truth, b.map, place, {}, {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
