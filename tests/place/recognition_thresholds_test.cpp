// RecognizeAtThresholds (one query under several mu and gamma_min at once, the pairs and each
// candidate's verification shared) gives, for every threshold, the answer of a recognizer built
// with that threshold: every field of PlaceMatch but the timings, on queries of the bundled FR079
// log, under best-score and first-verified selection and with the rigid-star ranking.

#include <cmath>
#include <cstddef>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "support/bundled_map.hpp"
#include "support/same_match.hpp"

namespace keyplace {
namespace {

// Every 20th of the 500 queries of `keyplace localize` on the bundled log (all-scan keypoints).
std::vector<LocalizationQuery> Queries() { return testing::BundledQueriesEvery(20); }

// Thresholds in no particular order, mu and gamma both above and below the defaults, one
// repeated; the stable-keypoint gamma differs from the all-scan one.
std::vector<RecognitionThresholds> Thresholds() {
  return {{10, 0.4, 0.15}, {5, 0.1, 0.0},   {20, 0.5, 0.6}, {15, 0.3, 0.3},
          {5, 0.0, 0.45},  {10, 0.4, 0.15}, {40, 0.2, 0.05}};
}

PlaceRecognitionConfig WithThresholds(PlaceRecognitionConfig config,
                                      const RecognitionThresholds& thresholds) {
  config.min_pairs = thresholds.min_pairs;
  config.min_gamma = thresholds.min_gamma;
  config.min_gamma_all_scans = thresholds.min_gamma_all_scans;
  return config;
}

struct Setting {
  std::string name;
  PlaceRecognitionConfig config;
};

std::vector<Setting> Settings() {
  using Config = PlaceRecognitionConfig;
  std::vector<Setting> settings;
  settings.push_back({"default", PlacePreset("default")});
  settings.push_back({"paper (first verified, stable query keypoints)", PlacePreset("paper")});
  Config ranked = PlacePreset("default");
  ranked.max_candidates = 8;  // the rigid-star ranking chooses, differently for each mu
  settings.push_back({"default, rigid-star ranking of 8", ranked});
  Config first = PlacePreset("default");
  first.selection = Config::Selection::kFirstVerified;
  first.max_candidates = 40;
  settings.push_back({"first verified, all-scan keypoints, 40 ranked", first});
  Config retrieved = PlacePreset("default");
  retrieved.retrieval = Config::Retrieval::kWords;
  retrieved.retrieval_places = 20;  // fewer than the places of any mu: retrieval chooses
  settings.push_back({"default, 20 places retrieved by words", retrieved});
  return settings;
}

TEST(RecognitionThresholds, EachAnswerIsThatOfARecognizerWithThoseThresholds) {
  const std::vector<LocalizationQuery> queries = Queries();
  ASSERT_GE(queries.size(), 25u);
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<RecognitionThresholds> thresholds = Thresholds();
  for (const Setting& setting : Settings()) {
    const PlaceRecognizer shared(places, setting.config);
    std::vector<PlaceRecognizer> own;
    for (const RecognitionThresholds& t : thresholds) {
      own.emplace_back(places, WithThresholds(setting.config, t));
    }
    // The thresholds must matter here, else equality would prove nothing.
    std::vector<std::set<std::string>> outcomes(queries.size());
    for (std::size_t i = 0; i < queries.size(); ++i) {
      const LocalizationQuery& query = queries[i];
      const auto exclude = [&query](const Place& place) {
        return IsSelfMatch(SelfMatchRule::kSameScans, query.truth_scans, place.scan_indices);
      };
      const std::vector<PlaceMatch> answers =
          shared.RecognizeAtThresholds(query.query, thresholds, exclude);
      ASSERT_EQ(answers.size(), thresholds.size());
      for (std::size_t k = 0; k < thresholds.size(); ++k) {
        const PlaceMatch expected = own[k].Recognize(query.query, exclude);
        testing::ExpectSameMatch(answers[k], expected,
                                 setting.name + ", thresholds " + std::to_string(k) + ", start " +
                                     std::to_string(query.start_scan));
        outcomes[i].insert(std::to_string(expected.candidates) + "/" +
                           std::to_string(expected.candidates_accepted) + "/" +
                           std::to_string(expected.place_id));
      }
    }
    int varied = 0;
    for (const auto& outcome : outcomes) varied += outcome.size() > 2 ? 1 : 0;
    EXPECT_GT(varied, static_cast<int>(queries.size()) / 2) << setting.name;
  }
}

TEST(RecognitionThresholds, RecognizeIsTheConfigsOwnThresholds) {
  const std::vector<LocalizationQuery> queries = Queries();
  const PlaceRecognizer recognizer(PlacesFromMap(testing::BundledFr079().map),
                                   PlacePreset("default"));
  const PlaceRecognitionConfig& c = recognizer.config();
  for (std::size_t i = 0; i < queries.size(); i += 5) {
    const std::vector<PlaceMatch> answers = recognizer.RecognizeAtThresholds(
        queries[i].query, {{c.min_pairs, c.min_gamma, c.min_gamma_all_scans}});
    ASSERT_EQ(answers.size(), 1u);
    testing::ExpectSameMatch(answers[0], recognizer.Recognize(queries[i].query),
                             "query " + std::to_string(i));
  }
  EXPECT_TRUE(recognizer.RecognizeAtThresholds(queries[0].query, {}).empty());
}

TEST(RecognitionThresholds, InvalidThresholdsAreRefusedNamingThem) {
  const PlaceRecognizer recognizer(PlacesFromMap(testing::BundledFr079().map),
                                   PlacePreset("default"));
  const PlaceQuery query = Queries().front().query;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<RecognitionThresholds> bad{
      {1, 0.4, 0.15}, {10, -0.1, 0.15}, {10, 0.4, 1.5}, {10, nan, 0.15}};
  for (const RecognitionThresholds& t : bad) {
    try {
      recognizer.RecognizeAtThresholds(query, {{10, 0.4, 0.15}, t});
      ADD_FAILURE() << "accepted min_pairs " << t.min_pairs << ", gamma " << t.min_gamma << "/"
                    << t.min_gamma_all_scans;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("recognition thresholds 1"), std::string::npos)
          << e.what();
    }
  }
}

// The evaluation records of each threshold are those of EvaluateQueries with it; returns how
// many queries the two thresholds answer differently.
int ExpectThresholdsMatchEvaluateQueries(const PlaceRecognitionConfig& base) {
  const std::vector<LocalizationQuery> queries = Queries();
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<RecognitionThresholds> thresholds{{5, 0.0, 0.0}, {10, 0.4, 0.3}};
  const auto records = EvaluateQueriesAtThresholds(queries, PlaceRecognizer(places, base),
                                                   SelfMatchRule::kSameScans, thresholds);
  EXPECT_EQ(records.size(), thresholds.size());
  int differs = 0;
  for (std::size_t k = 0; k < thresholds.size() && k < records.size(); ++k) {
    const auto expected =
        EvaluateQueries(queries, PlaceRecognizer(places, WithThresholds(base, thresholds[k])),
                        SelfMatchRule::kSameScans);
    EXPECT_EQ(records[k].size(), expected.size());
    for (std::size_t i = 0; i < expected.size() && i < records[k].size(); ++i) {
      const std::string where = "thresholds " + std::to_string(k) + ", query " + std::to_string(i);
      EXPECT_EQ(records[k][i].start_scan, expected[i].start_scan) << where;
      EXPECT_EQ(records[k][i].correct, expected[i].correct) << where;
      EXPECT_EQ(records[k][i].verified_correct, expected[i].verified_correct) << where;
      testing::ExpectSameMatch(records[k][i].match, expected[i].match, where);
      if (k == 1) differs += records[0][i].match.found != records[1][i].match.found;
    }
  }
  return differs;
}

TEST(RecognitionThresholds, EvaluateQueriesAtThresholdsMatchesEvaluateQueries) {
  // Gamma decides the second check (dense check off): the thresholds must change answers.
  PlaceRecognitionConfig gamma = PlacePreset("default");
  gamma.dense_min_hit_fraction = 0.0;
  EXPECT_GT(ExpectThresholdsMatchEvaluateQueries(gamma), 0)
      << "the two thresholds gave the same answers: nothing was tested";
  // The default, where the dense check decides in place of gamma wherever it applies.
  ExpectThresholdsMatchEvaluateQueries(PlacePreset("default"));
}

}  // namespace
}  // namespace keyplace
