// PairMemo against its oracle, the descriptor index's FindPairs: the same pairs for queries that
// grow, shrink and change the places searched, pairing only the descriptors it does not hold; a
// memo that outlived its index starts afresh; and a recognizer answers a growing query the same
// with and without it.

#include "place/pair_memo.hpp"

#include <cstddef>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/place/pair_memo.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "place/descriptor_index.hpp"
#include "support/bundled_map.hpp"
#include "support/same_match.hpp"

namespace keyplace {
namespace {

using Index = PlaceRecognitionConfig::DescriptorIndex;
constexpr double kChi2 = 0.4;

std::vector<BetaGridDescriptor> BundledDescriptors() {
  std::vector<BetaGridDescriptor> all;
  for (const auto& scan : testing::BundledFr079().inputs.keypoints) {
    for (const Keypoint& keypoint : scan) all.push_back(keypoint.descriptor);
  }
  return all;
}

void ExpectSamePairs(const std::vector<std::vector<DescriptorPair>>& memo,
                     const std::vector<std::vector<DescriptorPair>>& index,
                     const std::string& where) {
  ASSERT_EQ(memo.size(), index.size()) << where;
  for (std::size_t p = 0; p < memo.size(); ++p) {
    testing::ExpectSamePairs(memo[p], index[p], where + ", place " + std::to_string(p));
  }
}

std::size_t Distinct(const std::vector<BetaGridDescriptor>& descriptors) {
  return std::set<BetaGridDescriptor>(descriptors.begin(), descriptors.end()).size();
}

// A query of the log's descriptors [first, end), every drop-th left out (the merge of nearby
// keypoints keeps another one as the query grows), and its first descriptor twice.
std::vector<BetaGridDescriptor> Window(const std::vector<BetaGridDescriptor>& all,
                                       std::size_t first, std::size_t end, std::size_t drop) {
  std::vector<BetaGridDescriptor> query;
  for (std::size_t k = first; k < end; ++k) {
    if (drop > 0 && k % drop == drop - 1) continue;
    query.push_back(all[k]);
  }
  query.push_back(all[first]);
  return query;
}

TEST(PairMemo, GivesTheIndexsPairsAndPairsOnlyWhatItDoesNotHold) {
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<BetaGridDescriptor> all = BundledDescriptors();
  ASSERT_GT(all.size(), 2000u);
  for (Index kind : {Index::kDense, Index::kKdTree}) {
    const SqrtDescriptorIndex index(places, kind);
    PairMemo memo;
    std::vector<BetaGridDescriptor> previous;
    // Grows, grows with other keypoints left out, shrinks, then moves on to new scans.
    const struct {
      std::size_t first, end, drop;
    } windows[] = {
        {1000, 1100, 0}, {1000, 1250, 7}, {1000, 1400, 5}, {1200, 1400, 5}, {1700, 1800, 0}};
    for (std::size_t w = 0; w < std::size(windows); ++w) {
      const std::vector<BetaGridDescriptor> query =
          Window(all, windows[w].first, windows[w].end, windows[w].drop);
      // Some places left out (an exclusion), others each time.
      std::vector<char> searched(index.places(), 1);
      for (std::size_t p = w; p < searched.size(); p += 3) searched[p] = 0;
      std::vector<std::vector<DescriptorPair>> expected;
      index.FindPairs(query, kChi2, searched, expected);
      std::vector<std::vector<DescriptorPair>> got;
      PairMemoAccess::FindPairs(memo, index, query, kChi2, searched, got);
      const std::string where = "window " + std::to_string(w);
      ExpectSamePairs(got, expected, where);
      EXPECT_EQ(memo.descriptors(), Distinct(query)) << where;
      std::set<BetaGridDescriptor> held_before(previous.begin(), previous.end());
      std::size_t shared = 0;
      for (const BetaGridDescriptor& d : std::set<BetaGridDescriptor>(query.begin(), query.end())) {
        shared += held_before.count(d);
      }
      EXPECT_EQ(memo.reused(), shared) << where;
      if (w == 1 || w == 2 || w == 3) {
        EXPECT_GT(memo.reused(), 80u) << where;
      }
      previous = query;
    }
  }
}

// Descriptors are told apart by their bytes: a NaN bin (never equal to itself as a float) and a
// -0.0 bin (equal to 0.0) get rows of their own, with the index's pairs.
TEST(PairMemo, TellsDescriptorsApartByTheirBytes) {
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<BetaGridDescriptor> all = BundledDescriptors();
  const SqrtDescriptorIndex index(places, Index::kDense);
  const std::vector<char> every(index.places(), 1);
  std::vector<BetaGridDescriptor> query = Window(all, 800, 840, 0);
  const std::size_t distinct_before = Distinct(query);
  BetaGridDescriptor with_nan = query[3];
  with_nan[5] = std::numeric_limits<float>::quiet_NaN();
  BetaGridDescriptor signed_zero = query[4];
  std::size_t zero_bin = 0;
  while (zero_bin < signed_zero.size() && signed_zero[zero_bin] != 0.0f) ++zero_bin;
  ASSERT_LT(zero_bin, signed_zero.size());
  signed_zero[zero_bin] = -0.0f;
  query.push_back(with_nan);
  query.push_back(signed_zero);
  query.push_back(with_nan);
  PairMemo memo;
  std::vector<std::vector<DescriptorPair>> got;
  std::vector<std::vector<DescriptorPair>> expected;
  index.FindPairs(query, kChi2, every, expected);
  for (int answer = 0; answer < 2; ++answer) {
    PairMemoAccess::FindPairs(memo, index, query, kChi2, every, got);
    ExpectSamePairs(got, expected, "answer " + std::to_string(answer));
  }
  EXPECT_EQ(memo.descriptors(), distinct_before + 2);
  EXPECT_EQ(memo.reused(), distinct_before + 2);
}

// A memo too small for a query's rows keeps those of its first descriptors, and gives the same
// pairs.
TEST(PairMemo, HoldsNoMorePairsThanItsBudget) {
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<BetaGridDescriptor> all = BundledDescriptors();
  const SqrtDescriptorIndex index(places, Index::kDense);
  const std::vector<char> every(index.places(), 1);
  const std::vector<BetaGridDescriptor> query = Window(all, 300, 500, 0);
  PairMemo unbounded;
  std::vector<std::vector<DescriptorPair>> got;
  PairMemoAccess::FindPairs(unbounded, index, query, kChi2, every, got);
  ASSERT_GT(unbounded.pairs(), 4000u);
  EXPECT_EQ(unbounded.descriptors(), Distinct(query));

  const std::size_t budget = unbounded.pairs() / 3;
  PairMemo bounded(budget);
  PairMemoAccess::FindPairs(bounded, index, query, kChi2, every, got);
  EXPECT_LE(bounded.pairs(), budget);
  EXPECT_GT(bounded.pairs(), budget / 2);
  EXPECT_LT(bounded.descriptors(), Distinct(query));
  const std::vector<BetaGridDescriptor> grown = Window(all, 300, 560, 0);
  PairMemoAccess::FindPairs(bounded, index, grown, kChi2, every, got);
  std::vector<std::vector<DescriptorPair>> expected;
  index.FindPairs(grown, kChi2, every, expected);
  ExpectSamePairs(got, expected, "grown, bounded");
  EXPECT_GT(bounded.reused(), 0u);
  EXPECT_LT(bounded.reused(), Distinct(query));
  EXPECT_LE(bounded.pairs(), budget);
}

TEST(PairMemo, StartsAfreshForAnotherIndexAThresholdOrAnAddedPlace) {
  std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const std::vector<BetaGridDescriptor> all = BundledDescriptors();
  const std::vector<BetaGridDescriptor> query = Window(all, 500, 650, 0);
  SqrtDescriptorIndex index(places, Index::kDense);
  PairMemo memo;
  std::vector<std::vector<DescriptorPair>> got;
  std::vector<std::vector<DescriptorPair>> expected;
  const std::vector<char> every(index.places(), 1);
  PairMemoAccess::FindPairs(memo, index, query, kChi2, every, got);

  // The query's own descriptors as a new place: its pairs must appear, so the rows are redone.
  index.AddPlace(std::vector<BetaGridDescriptor>(query.begin(), query.begin() + 40));
  const std::vector<char> every_now(index.places(), 1);
  PairMemoAccess::FindPairs(memo, index, query, kChi2, every_now, got);
  EXPECT_EQ(memo.reused(), 0u);
  index.FindPairs(query, kChi2, every_now, expected);
  ExpectSamePairs(got, expected, "after a place was added");
  EXPECT_GE(got.back().size(), 40u);

  PairMemoAccess::FindPairs(memo, index, query, 0.2, every_now, got);
  EXPECT_EQ(memo.reused(), 0u);
  index.FindPairs(query, 0.2, every_now, expected);
  ExpectSamePairs(got, expected, "another threshold");

  const SqrtDescriptorIndex same_places(places, Index::kDense);
  const std::vector<char> every_other(same_places.places(), 1);
  PairMemoAccess::FindPairs(memo, same_places, query, 0.2, every_other, got);
  EXPECT_EQ(memo.reused(), 0u);
  PairMemoAccess::FindPairs(memo, same_places, query, 0.2, every_other, got);
  EXPECT_EQ(memo.reused(), Distinct(query));
  EXPECT_THROW(PairMemoAccess::FindPairs(memo, same_places, query, 0.2, every_now, got),
               std::invalid_argument);
}

// A query that grows from half its scans' keypoints to all of them, answered with one memo and
// without: the same answers, field for field, the later ones from mostly remembered pairs. A
// query by the words does not use the memo.
TEST(PairMemo, ARecognizerAnswersAGrowingQueryTheSameWithIt) {
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  const PlaceRecognizer recognizer(places, PlaceRecognitionConfig{},
                                   PlaceRecognizer::LearnWords::kAlways);
  const std::vector<LocalizationQuery> queries = testing::BundledQueriesEvery(100);
  ASSERT_GE(queries.size(), 3u);
  for (std::size_t q = 0; q < 3; ++q) {
    const PlaceQuery& full = queries[q].query;
    ASSERT_GT(full.all_descriptors.size(), 60u);
    PairMemo memo;
    int answers_from_memory = 0;
    for (double share : {0.5, 0.75, 1.0}) {
      PlaceQuery grown = full;
      const auto kept = static_cast<std::size_t>(share * full.all_descriptors.size());
      grown.all_positions.resize(kept);
      grown.all_descriptors.resize(kept);
      // Every fifth place excluded, other ones for each query.
      const PlaceExclusion exclude = [q](const Place& place) {
        return place.id % 5 == static_cast<int>(q);
      };
      const PlaceMatch without = recognizer.Recognize(grown, exclude);
      EXPECT_EQ(without.descriptors_remembered, -1);
      grown.pair_memo = &memo;
      const PlaceMatch with = recognizer.Recognize(grown, exclude);
      const std::string where = "query " + std::to_string(q) + ", share " + std::to_string(share);
      testing::ExpectSameMatch(with, without, where);
      EXPECT_EQ(with.descriptors_remembered, static_cast<int>(memo.reused())) << where;
      if (share > 0.5 && with.descriptors_remembered > 25) ++answers_from_memory;
    }
    EXPECT_EQ(answers_from_memory, 2) << "query " << q;
    PlaceQuery by_words = full;
    by_words.by_words = true;
    by_words.pair_memo = &memo;
    const std::size_t held = memo.descriptors();
    EXPECT_EQ(recognizer.Recognize(by_words).descriptors_remembered, -1);
    EXPECT_EQ(memo.descriptors(), held);
  }
}

// A place removed from the recognizer (its slot no longer searched, its keypoints still in the
// index) is not paired from the memo's rows either.
TEST(PairMemo, APlaceRemovedIsNoLongerPairedFromTheRows) {
  const std::vector<Place> places = PlacesFromMap(testing::BundledFr079().map);
  PlaceRecognizer recognizer(places, PlaceRecognitionConfig{});
  const std::vector<LocalizationQuery> queries = testing::BundledQueriesEvery(100);
  ASSERT_FALSE(queries.empty());
  PlaceQuery query = queries.front().query;
  PairMemo memo;
  query.pair_memo = &memo;
  const PlaceMatch first = recognizer.Recognize(query);
  ASSERT_TRUE(first.verified);
  ASSERT_TRUE(recognizer.RemovePlace(first.place_id));
  const PlaceMatch with = recognizer.Recognize(query);
  EXPECT_GT(with.descriptors_remembered, 0);
  query.pair_memo = nullptr;
  const PlaceMatch without = recognizer.Recognize(query);
  testing::ExpectSameMatch(with, without, "after RemovePlace");
  EXPECT_NE(with.place_id, first.place_id);
}

}  // namespace
}  // namespace keyplace
