// One place-recognition query works in parallel (TBB: the index's blocks, the unique pairs per
// place, the rigid-star ranking, the verification of the candidates) and gives the same answer at
// any number of threads: every field of PlaceMatch but the timings, on queries of the bundled
// FR079 log against its map, under several settings (kFirstVerified among them).

#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "support/bundled_map.hpp"
#include "support/same_match.hpp"

namespace keyplace {
namespace {

// The answers of `recognizer` to `queries`, one query after the other, on `threads` threads.
std::vector<PlaceMatch> AnswersOnThreads(const PlaceRecognizer& recognizer,
                                         const std::vector<LocalizationQuery>& queries,
                                         int threads) {
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));
  tbb::task_arena arena(threads);
  std::vector<PlaceMatch> answers;
  arena.execute([&] {
    for (const LocalizationQuery& query : queries) {
      const auto exclude = [&query](const Place& place) {
        return IsSelfMatch(SelfMatchRule::kSameScans, query.truth_scans, place.scan_indices);
      };
      answers.push_back(recognizer.Recognize(query.query, exclude));
    }
  });
  return answers;
}

// Every 10th of the 500 queries of `keyplace localize` on the bundled log (all-scan keypoints).
std::vector<LocalizationQuery> Queries() { return testing::BundledQueriesEvery(10); }

struct Setting {
  std::string name;
  PlaceRecognitionConfig config;
};

std::vector<Setting> Settings() {
  using Config = PlaceRecognitionConfig;
  std::vector<Setting> settings;
  settings.push_back({"default", PlacePreset("default")});
  settings.push_back({"paper (first verified)", PlacePreset("paper")});
  // Fewer candidates verified than found: the rigid-star ranking chooses them.
  Config ranked = PlacePreset("default");
  ranked.max_candidates = 8;
  settings.push_back({"default, rigid-star ranking of 8", ranked});
  // The first verified of many candidates, through the kd-tree, with map neighbours; a low
  // gamma threshold so that both early and late first verified candidates occur.
  Config first = PlacePreset("default");
  first.selection = Config::Selection::kFirstVerified;
  first.descriptor_index = Config::DescriptorIndex::kKdTree;
  first.max_candidates = 40;
  settings.push_back({"first verified, kd-tree, 40 ranked", first});
  Config greedy_first = first;
  greedy_first.descriptor_index = Config::DescriptorIndex::kDense;
  greedy_first.candidate_ranking = Config::CandidateRanking::kMeanDistance;
  greedy_first.min_gamma_all_scans = 0.5;
  settings.push_back({"first verified, dense, gamma 0.5", greedy_first});
  return settings;
}

TEST(ParallelRecognition, SameAnswerAtOneTwoAndFourThreadsOnTheBundledLog) {
  const std::vector<LocalizationQuery> queries = Queries();
  ASSERT_GT(queries.size(), 45u);
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  for (const Setting& setting : Settings()) {
    const PlaceRecognizer recognizer(places, setting.config);
    const std::vector<PlaceMatch> expected = AnswersOnThreads(recognizer, queries, 1);
    // The settings reach what they are here for.
    int found = 0;
    int ranked = 0;
    int verified_late = 0;
    for (const PlaceMatch& match : expected) {
      found += match.found ? 1 : 0;
      ranked += match.candidates > setting.config.max_candidates ? 1 : 0;
      verified_late += match.verified && match.candidates_verified > 1 ? 1 : 0;
    }
    EXPECT_GT(found, static_cast<int>(queries.size()) / 5) << setting.name;
    if (setting.config.max_candidates < 100) {
      EXPECT_GT(ranked, 0) << setting.name;
    }
    if (setting.config.selection == PlaceRecognitionConfig::Selection::kFirstVerified) {
      EXPECT_GT(verified_late, 0) << setting.name;
      for (const PlaceMatch& match : expected) {
        EXPECT_LE(match.verified_candidates.size(), 1u) << setting.name;
      }
    }
    for (const int threads : {2, 4}) {
      const std::vector<PlaceMatch> answers = AnswersOnThreads(recognizer, queries, threads);
      ASSERT_EQ(answers.size(), expected.size());
      for (std::size_t i = 0; i < answers.size(); ++i) {
        testing::ExpectSameMatch(answers[i], expected[i],
                                 setting.name + ", " + std::to_string(threads) +
                                     " threads, start " + std::to_string(queries[i].start_scan));
      }
    }
  }
}

}  // namespace
}  // namespace keyplace
