// The exact descriptor index against its oracle, exhaustive matching: the square-root bound
// ||sqrt(x) - sqrt(y)||^2 <= 2 chi2_sym(x, y) on random and real descriptors, the same pairs on
// random descriptor sets, and the same answer on every query of the bundled log.

#include "place/descriptor_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "support/bundled_map.hpp"
#include "support/same_match.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using Index = PlaceRecognitionConfig::DescriptorIndex;

// ||sqrt(x) - sqrt(y)||^2 in long double, zero bins as zero.
double RootDistance2(const BetaGridDescriptor& x, const BetaGridDescriptor& y) {
  long double sum = 0.0L;
  for (int i = 0; i < kBetaGridBins; ++i) {
    const long double d =
        std::sqrt(static_cast<long double>(x[i])) - std::sqrt(static_cast<long double>(y[i]));
    sum += d * d;
  }
  return static_cast<double>(sum);
}

// A random histogram over `support` random bins (0: all zero), normalised to 1 unless `raw`.
BetaGridDescriptor RandomDescriptor(std::mt19937& rng, int support, bool raw = false) {
  BetaGridDescriptor d{};
  std::vector<int> bins(kBetaGridBins);
  for (int i = 0; i < kBetaGridBins; ++i) bins[i] = i;
  std::shuffle(bins.begin(), bins.end(), rng);
  std::exponential_distribution<float> mass(1.0f);
  float sum = 0.0f;
  for (int k = 0; k < support; ++k) {
    d[bins[k]] = mass(rng);
    sum += d[bins[k]];
  }
  if (!raw && sum > 0.0f) {
    for (float& v : d) v /= sum;
  }
  return d;
}

// `base` with each bin moved by up to +-`noise` (relative), some bins emptied or filled,
// renormalised: pairs of these straddle the 0.4 threshold.
BetaGridDescriptor Perturbed(const BetaGridDescriptor& base, float noise, std::mt19937& rng) {
  std::uniform_real_distribution<float> factor(1.0f - noise, 1.0f + noise);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  BetaGridDescriptor d = base;
  float sum = 0.0f;
  for (float& v : d) {
    const float u = unit(rng);
    if (u < 0.05f) {
      v = 0.0f;
    } else if (u < 0.10f) {
      v += 0.05f * unit(rng);
    } else {
      v *= factor(rng);
    }
    sum += v;
  }
  if (sum > 0.0f) {
    for (float& v : d) v /= sum;
  }
  return d;
}

// The bound with the margin the index uses, and the ratio H / chi2.
struct BoundCheck {
  double max_ratio = 0.0;
  int checked = 0;
  int violations = 0;
  void Add(const BetaGridDescriptor& x, const BetaGridDescriptor& y) {
    const double chi2 = SymmetricChi2(x, y);
    const double root2 = RootDistance2(x, y);
    ++checked;
    if (!(root2 <= 2.0 * chi2 * (1.0 + 1e-12) + 1e-12)) ++violations;
    if (chi2 > 1e-6) max_ratio = std::max(max_ratio, root2 / chi2);
  }
};

TEST(DescriptorIndexBound, RootDistanceIsAtMostTwiceTheChi2OnRandomDescriptors) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> support(0, kBetaGridBins);
  BoundCheck check;
  for (int k = 0; k < 200000; ++k) {
    const bool raw = k % 10 == 0;  // also histograms that do not sum to 1
    const BetaGridDescriptor x = RandomDescriptor(rng, k % 7 == 0 ? 1 : support(rng), raw);
    const BetaGridDescriptor y =
        k % 3 == 0 ? Perturbed(x, 0.5f, rng) : RandomDescriptor(rng, support(rng), raw);
    check.Add(x, y);
  }
  EXPECT_EQ(check.checked, 200000);
  EXPECT_EQ(check.violations, 0);
  EXPECT_LE(check.max_ratio, 2.0 + 1e-9);
  // c = 2 is tight: disjoint supports reach it.
  BetaGridDescriptor a{};
  BetaGridDescriptor b{};
  a[0] = 0.7f;
  a[5] = 0.3f;
  b[1] = 1.0f;
  EXPECT_NEAR(RootDistance2(a, b) / SymmetricChi2(a, b), 2.0, 1e-12);
  EXPECT_GT(check.max_ratio, 1.99);
}

// The bundled log and its map (default mapping), built once.
struct Bundled {
  LogInputs inputs;
  GlobalMap map;
  std::vector<BetaGridDescriptor> descriptors;  // of every keypoint of every scan
};

const Bundled& BundledLog() {
  static const Bundled bundled = [] {
    Bundled b;
    const testing::BundledMap& log = testing::BundledFr079();
    b.inputs = log.inputs;
    b.map = log.map;
    for (const auto& scan : b.inputs.keypoints) {
      for (const Keypoint& keypoint : scan) b.descriptors.push_back(keypoint.descriptor);
    }
    return b;
  }();
  return bundled;
}

TEST(DescriptorIndexBound, RootDistanceIsAtMostTwiceTheChi2OnTheBundledLog) {
  const std::vector<BetaGridDescriptor>& all = BundledLog().descriptors;
  ASSERT_GT(all.size(), 10000u);
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::size_t> pick(0, all.size() - 1);
  BoundCheck check;
  for (int k = 0; k < 500000; ++k) check.Add(all[pick(rng)], all[pick(rng)]);
  for (std::size_t k = 0; k + 1 < all.size(); ++k) check.Add(all[k], all[k + 1]);  // neighbours
  EXPECT_EQ(check.violations, 0) << "of " << check.checked;
  EXPECT_LE(check.max_ratio, 2.0 + 1e-9);
  EXPECT_GT(check.max_ratio, 1.99);  // real descriptors with disjoint supports
}

// The distance as FLIRTLib writes it (a zero bin replaced by PSEUDOZERO in a branch), summed in
// the same order: SymmetricChi2 (branch-free) must give the same doubles. (Here rather than in
// tests/features: the index's results rest on it.)
double FlirtLibChi2(const BetaGridDescriptor& a, const BetaGridDescriptor& b) {
  const double pseudo_zero = std::numeric_limits<double>::min();
  double sum = 0.0;
  for (int i = 0; i < kBetaGridBins; ++i) {
    const double q = a[i] == 0.0f ? pseudo_zero : static_cast<double>(a[i]);
    const double p = b[i] == 0.0f ? pseudo_zero : static_cast<double>(b[i]);
    sum += (q - p) * (q - p) / (q + p);
  }
  return 0.5 * sum;
}

TEST(DescriptorIndexBound, Chi2IsBitIdenticalToFlirtLibsBranchingPseudoZero) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  const float tiny = std::numeric_limits<float>::denorm_min();
  for (int trial = 0; trial < 20000; ++trial) {
    BetaGridDescriptor a;
    BetaGridDescriptor b;
    for (int i = 0; i < kBetaGridBins; ++i) {
      const float u = uniform(rng);
      a[i] = u < 0.5f ? 0.0f : (u < 0.52f ? tiny : (u < 0.53f ? -0.0f : uniform(rng)));
      b[i] = uniform(rng) < 0.5f ? 0.0f : uniform(rng) * 1e-3f;
    }
    ASSERT_EQ(SymmetricChi2(a, b), FlirtLibChi2(a, b));
    ASSERT_EQ(SymmetricChi2(b, a), FlirtLibChi2(b, a));
  }
  const std::vector<BetaGridDescriptor>& real = BundledLog().descriptors;
  for (std::size_t k = 0; k + 1 < real.size(); ++k) {
    ASSERT_EQ(SymmetricChi2(real[k], real[k + 1]), FlirtLibChi2(real[k], real[k + 1]));
  }
}

TEST(DescriptorIndexBound, Chi2IfBelowIsTheChi2OrInfinity) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> support(0, kBetaGridBins);
  const std::vector<BetaGridDescriptor>& real = BundledLog().descriptors;
  for (std::size_t k = 0; k < 100000; ++k) {
    const std::size_t r = k % (real.size() - 1);
    const BetaGridDescriptor x = k % 2 ? RandomDescriptor(rng, support(rng)) : real[r];
    const BetaGridDescriptor y = k % 4 == 1 ? Perturbed(x, 0.6f, rng)
                                 : k % 2    ? RandomDescriptor(rng, support(rng))
                                            : real[r + 1];
    for (double threshold : {0.05, 0.4, 1.0}) {
      const double below = SymmetricChi2IfBelow(x, y, threshold);
      if (SymmetricChi2Below(x, y, threshold)) {
        ASSERT_EQ(below, SymmetricChi2(x, y));
      } else {
        ASSERT_EQ(below, std::numeric_limits<double>::infinity());
      }
    }
  }
}

// Places of random descriptors: bases, perturbed copies (pairs near the threshold), sparse ones,
// all-zero ones, unnormalised ones, and some empty places.
std::vector<Place> RandomPlaces(std::mt19937& rng, const std::vector<BetaGridDescriptor>& bases) {
  std::uniform_int_distribution<int> size(0, 40);
  std::uniform_int_distribution<int> kind(0, 9);
  std::uniform_int_distribution<std::size_t> base(0, bases.size() - 1);
  std::uniform_int_distribution<int> support(1, kBetaGridBins);
  std::vector<Place> places(60);
  for (std::size_t p = 0; p < places.size(); ++p) {
    places[p].id = static_cast<int>(p);
    const int n = p % 13 == 5 ? 0 : size(rng);
    for (int k = 0; k < n; ++k) {
      const int what = kind(rng);
      BetaGridDescriptor d{};
      if (what < 6) {
        d = Perturbed(bases[base(rng)], 0.8f, rng);
      } else if (what < 8) {
        d = RandomDescriptor(rng, what == 6 ? 2 : support(rng));
      } else if (what == 8) {
        d = RandomDescriptor(rng, support(rng), /*raw=*/true);
      }  // else all zero
      places[p].positions.emplace_back(k, p);
      places[p].descriptors.push_back(d);
    }
  }
  return places;
}

// The exhaustive pairs of MatchDescriptorPairs, before uniqueness: every (c, r, chi2) with
// SymmetricChi2Below, by c then r.
std::vector<DescriptorPair> ExhaustiveBelow(const std::vector<BetaGridDescriptor>& query,
                                            const std::vector<BetaGridDescriptor>& reference,
                                            double threshold) {
  std::vector<DescriptorPair> below;
  for (std::size_t c = 0; c < query.size(); ++c) {
    for (std::size_t r = 0; r < reference.size(); ++r) {
      if (SymmetricChi2Below(query[c], reference[r], threshold)) {
        below.push_back(
            {static_cast<int>(c), static_cast<int>(r), SymmetricChi2(query[c], reference[r])});
      }
    }
  }
  return below;
}

TEST(DescriptorIndex, FindsExactlyTheExhaustivePairsOnRandomDescriptors) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> support(1, kBetaGridBins);
  std::vector<BetaGridDescriptor> bases;
  for (int k = 0; k < 12; ++k) bases.push_back(RandomDescriptor(rng, support(rng)));
  std::size_t pairs_seen = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const std::vector<Place> places = RandomPlaces(rng, bases);
    // About 100 query descriptors: the dense product takes all places in one block.
    std::vector<BetaGridDescriptor> query;
    for (const Place& place : RandomPlaces(rng, bases)) {
      if (query.size() < 100) {
        query.insert(query.end(), place.descriptors.begin(), place.descriptors.end());
      }
    }
    query.push_back(BetaGridDescriptor{});  // an all-zero query descriptor
    query.push_back(places[2].descriptors.empty() ? bases[0] : places[2].descriptors[0]);
    std::vector<char> searched(places.size(), 1);
    for (std::size_t p = 0; p < places.size(); p += 7) searched[p] = 0;
    for (Index kind : {Index::kDense, Index::kKdTree}) {
      const SqrtDescriptorIndex built(places, kind);
      // Grown: the first 10 places at construction (one big tree), then one place at a time.
      SqrtDescriptorIndex grown(std::vector<Place>(places.begin(), places.begin() + 10), kind);
      std::size_t most_trees = 0;
      for (std::size_t p = 10; p < places.size(); ++p) {
        ASSERT_EQ(grown.AddPlace(places[p].descriptors), p);
        // The merging keeps the trees few.
        ASSERT_LE(grown.trees(), std::log2(static_cast<double>(grown.keypoints())) + 1.0);
        most_trees = std::max(most_trees, grown.trees());
      }
      ASSERT_EQ(grown.places(), places.size());
      ASSERT_EQ(grown.keypoints(), built.keypoints());
      if (kind == Index::kKdTree) {
        // Added places get trees of their own (no rebuild of the whole index).
        EXPECT_EQ(built.trees(), 1u);
        EXPECT_GT(most_trees, 2u);
      }
      for (double threshold : {0.1, 0.4, 0.8}) {
        for (const SqrtDescriptorIndex* index : {&built, &std::as_const(grown)}) {
          std::vector<std::vector<DescriptorPair>> below;
          index->FindPairs(query, threshold, searched, below);
          ASSERT_EQ(below.size(), places.size());
          for (std::size_t p = 0; p < places.size(); ++p) {
            const std::vector<DescriptorPair> expected =
                searched[p] ? ExhaustiveBelow(query, places[p].descriptors, threshold)
                            : std::vector<DescriptorPair>{};
            testing::ExpectSamePairs(below[p], expected, "place " + std::to_string(p));
            pairs_seen += expected.size();
          }
        }
      }
    }
  }
  EXPECT_GT(pairs_seen, 20000u);  // the sets do have pairs near every threshold
}

TEST(DescriptorIndex, DenseBlocksOfPlacesFindTheExhaustivePairs) {
  // The dense product takes blocks of whole places whose H for all query rows fit its budget
  // (2^19 values): 6000 query rows give blocks of a few places, 20000 blocks smaller than the
  // largest places (40 keypoints), which then form a block alone.
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> support(1, kBetaGridBins);
  std::vector<BetaGridDescriptor> bases;
  for (int k = 0; k < 12; ++k) bases.push_back(RandomDescriptor(rng, support(rng)));
  const std::vector<Place> places = RandomPlaces(rng, bases);
  // Most places searched (runs of four between gaps), and a few apart (retrieval: runs of one).
  std::vector<char> most_searched(places.size(), 1);
  for (std::size_t p = 3; p < places.size(); p += 5) most_searched[p] = 0;
  std::vector<char> few_searched(places.size(), 0);
  for (std::size_t p = 2; p < places.size(); p += 9) few_searched[p] = 1;
  const SqrtDescriptorIndex index(places, Index::kDense);
  for (const bool few : {false, true}) {
    const std::vector<char>& searched = few ? few_searched : most_searched;
    for (const std::size_t rows : {std::size_t{6000}, std::size_t{20000}}) {
      std::vector<BetaGridDescriptor> query;
      while (query.size() < rows) {
        for (const Place& place : RandomPlaces(rng, bases)) {
          query.insert(query.end(), place.descriptors.begin(), place.descriptors.end());
        }
      }
      query.resize(rows);
      std::vector<std::vector<DescriptorPair>> below;
      index.FindPairs(query, 0.4, searched, below);
      std::size_t pairs = 0;
      for (std::size_t p = 0; p < places.size(); ++p) {
        const std::vector<DescriptorPair> expected =
            searched[p] ? ExhaustiveBelow(query, places[p].descriptors, 0.4)
                        : std::vector<DescriptorPair>{};
        testing::ExpectSamePairs(below[p], expected,
                                 std::to_string(rows) + " rows, place " + std::to_string(p));
        pairs += expected.size();
      }
      EXPECT_GT(pairs, few ? rows / 20 : rows);  // the searched places had pairs to find
    }
  }
}

TEST(DescriptorIndex, NoneHasNoIndexAndEmptyMapsWork) {
  EXPECT_THROW(SqrtDescriptorIndex({}, Index::kNone), std::invalid_argument);
  const SqrtDescriptorIndex index(std::vector<Place>(3), Index::kKdTree);
  std::vector<std::vector<DescriptorPair>> below;
  index.FindPairs({BetaGridDescriptor{}}, 0.4, std::vector<char>(3, 1), below);
  EXPECT_EQ(below.size(), 3u);
  EXPECT_THROW(index.FindPairs({}, 0.4, std::vector<char>(2, 1), below), std::invalid_argument);
}

TEST(DescriptorIndex, RecognizerGivesTheSameMatchesOnRandomPlaces) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> support(1, kBetaGridBins);
  std::vector<BetaGridDescriptor> bases;
  for (int k = 0; k < 8; ++k) bases.push_back(RandomDescriptor(rng, support(rng)));
  const std::vector<Place> places = RandomPlaces(rng, bases);
  for (const PlaceRecognitionConfig& preset : {PlacePreset("default"), PlacePreset("paper")}) {
    PlaceRecognitionConfig none = preset;
    none.descriptor_index = Index::kNone;
    PlaceRecognitionConfig config = preset;
    config.min_gamma = config.min_gamma_all_scans = 0.0;
    none.min_gamma = none.min_gamma_all_scans = 0.0;
    const PlaceRecognizer oracle(places, none);
    for (Index kind : {Index::kDense, Index::kKdTree}) {
      config.descriptor_index = kind;
      const PlaceRecognizer indexed(places, config);
      for (std::size_t q = 0; q < places.size(); q += 3) {
        PlaceQuery query;
        query.positions = places[q].positions;
        query.descriptors = places[q].descriptors;
        const auto exclude = [q](const Place& place) { return place.id == static_cast<int>(q); };
        testing::ExpectSameMatch(indexed.Recognize(query, exclude),
                                 oracle.Recognize(query, exclude), "query " + std::to_string(q));
      }
    }
  }
}

// Algorithm 4 on the bundled log (its map, every second of 500 equally spaced starts, all-scan
// queries): every answer of the dense index equals the exhaustive one; the kd-tree is compared on
// every 5th of those (the exhaustive answers take most of this test's time).
TEST(DescriptorIndex, SameAnswerAsExhaustiveOnEverySecondQueryOfTheBundledLog) {
  const Bundled& b = BundledLog();
  const std::vector<LocalizationQuery> queries = testing::BundledQueriesEvery(2);
  ASSERT_GT(queries.size(), 240u);
  const PlaceRecognitionConfig base;  // default preset
  PlaceRecognitionConfig none = base;
  none.descriptor_index = Index::kNone;
  const std::vector<LocalizationRecord> expected = EvaluateQueries(
      queries, PlaceRecognizer(PlacesFromMap(b.map), none), SelfMatchRule::kSameScans);
  std::vector<LocalizationQuery> every_fifth;
  for (std::size_t i = 0; i < queries.size(); i += 5) every_fifth.push_back(queries[i]);
  int found = 0;
  for (Index kind : {Index::kDense, Index::kKdTree}) {
    PlaceRecognitionConfig config = base;
    config.descriptor_index = kind;
    const bool all = kind == Index::kDense;
    const std::vector<LocalizationRecord> records =
        EvaluateQueries(all ? queries : every_fifth, PlaceRecognizer(PlacesFromMap(b.map), config),
                        SelfMatchRule::kSameScans);
    ASSERT_EQ(records.size(), all ? expected.size() : every_fifth.size());
    for (std::size_t i = 0; i < records.size(); ++i) {
      const std::size_t e = all ? i : 5 * i;
      testing::ExpectSameMatch(records[i].match, expected[e].match,
                               "start " + std::to_string(queries[e].start_scan));
      if (all) found += records[i].match.found ? 1 : 0;
    }
  }
  EXPECT_GT(found, static_cast<int>(queries.size()) * 9 / 10);  // recall ~0.98
}

// Incremental place database: a recognizer grown place by place (from empty), then shrunk and
// grown again, gives on the bundled log the answers of a recognizer built at once from the same
// places, for every descriptor index; removed places never answer.
std::vector<PlaceMatch> Answers(const std::vector<LocalizationQuery>& queries,
                                const PlaceRecognizer& recognizer) {
  std::vector<PlaceMatch> answers;
  for (const LocalizationRecord& record :
       EvaluateQueries(queries, recognizer, SelfMatchRule::kSameScans)) {
    answers.push_back(record.match);
  }
  return answers;
}

std::vector<PlaceMatch> ExpectSameAnswers(const std::vector<LocalizationQuery>& queries,
                                          const PlaceRecognizer& incremental,
                                          const std::vector<Place>& places,
                                          const std::string& what) {
  const PlaceRecognizer at_once(places, incremental.config());
  EXPECT_EQ(incremental.places().size(), places.size()) << what;
  for (std::size_t p = 0; p < places.size() && p < incremental.places().size(); ++p) {
    EXPECT_EQ(incremental.places()[p].id, places[p].id) << what;
  }
  const std::vector<PlaceMatch> expected = Answers(queries, at_once);
  std::vector<PlaceMatch> answers = Answers(queries, incremental);
  EXPECT_EQ(answers.size(), expected.size());
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const std::string where = what + ", start " + std::to_string(queries[i].start_scan);
    testing::ExpectSameMatch(answers[i], expected[i], where);
    EXPECT_EQ(answers[i].place_index, expected[i].place_index) << where;
    EXPECT_EQ(answers[i].reference_coverage, expected[i].reference_coverage) << where;
  }
  return answers;
}

TEST(PlaceDatabase, AddAndRemoveGiveTheAnswersOfARecognizerBuiltAtOnceOnTheBundledLog) {
  const Bundled& b = BundledLog();
  const std::vector<Place> all = PlacesFromMap(b.map);
  ASSERT_GT(all.size(), 30u);
  for (Index kind : {Index::kDense, Index::kKdTree, Index::kNone}) {
    const std::string name = kind == Index::kDense    ? "dense"
                             : kind == Index::kKdTree ? "kdtree"
                                                      : "none";
    // Every 20th query (every 100th for the exhaustive search, which dominates this test's time).
    const std::vector<LocalizationQuery> queries =
        testing::BundledQueriesEvery(kind == Index::kNone ? 100 : 20);
    PlaceRecognitionConfig config;  // default preset
    config.descriptor_index = kind;

    PlaceRecognizer incremental({}, config);
    for (const Place& place : all) incremental.AddPlace(place);
    const std::vector<PlaceMatch> before =
        ExpectSameAnswers(queries, incremental, all, name + " added one by one");

    // Remove every 3rd place (a third of the keypoints: kept in the index, never searched).
    std::vector<Place> kept;
    std::vector<Place> removed;
    for (std::size_t p = 0; p < all.size(); ++p) (p % 3 == 1 ? removed : kept).push_back(all[p]);
    for (const Place& place : removed) ASSERT_TRUE(incremental.RemovePlace(place.id));
    EXPECT_FALSE(incremental.RemovePlace(removed.front().id));  // gone already
    const std::vector<PlaceMatch> after =
        ExpectSameAnswers(queries, incremental, kept, name + " without every 3rd place");
    // Removed places never answer, though some answered before.
    int answered_by_removed = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      for (const Place& place : removed) {
        if (before[i].verified && before[i].place_id == place.id) ++answered_by_removed;
        EXPECT_NE(after[i].place_id, place.id);
        for (const CandidateResult& candidate : after[i].verified_candidates) {
          EXPECT_NE(incremental.places()[candidate.place_index].id, place.id);
        }
      }
    }
    EXPECT_GT(answered_by_removed, 0) << name;
    ASSERT_EQ(after.size(), queries.size());

    // Remove half of the rest (the removed keypoints now outnumber the live ones: the index is
    // rebuilt), then add the first removed places back, last in the list.
    std::vector<Place> rest;
    for (std::size_t p = 0; p < kept.size(); ++p) {
      if (p % 2 == 0) {
        rest.push_back(kept[p]);
      } else {
        ASSERT_TRUE(incremental.RemovePlace(kept[p].id));
      }
    }
    for (const Place& place : removed) {
      incremental.AddPlace(place);
      rest.push_back(place);
    }
    ExpectSameAnswers(queries, incremental, rest, name + " after removals and additions");
  }
}

TEST(PlaceDatabase, CopiesDoNotShareChangesAndBadInputThrows) {
  const Bundled& b = BundledLog();
  const std::vector<Place> all = PlacesFromMap(b.map);
  PlaceRecognitionConfig config;
  const PlaceRecognizer original(std::vector<Place>(all.begin(), all.end() - 5), config);
  PlaceRecognizer copy = original;
  for (auto it = all.end() - 5; it != all.end(); ++it) copy.AddPlace(*it);
  ASSERT_TRUE(copy.RemovePlace(all.front().id));
  EXPECT_EQ(original.places().size(), all.size() - 5);
  const std::vector<LocalizationQuery> queries = testing::BundledQueriesEvery(10);
  ExpectSameAnswers(queries, original, std::vector<Place>(all.begin(), all.end() - 5), "original");
  ExpectSameAnswers(queries, copy, std::vector<Place>(all.begin() + 1, all.end()), "copy");

  Place bad = all.front();
  bad.positions.pop_back();
  EXPECT_THROW(copy.AddPlace(bad), std::invalid_argument);
  EXPECT_THROW(copy.SetPlacePose(copy.places().size(), Pose2{}), std::out_of_range);
  copy.SetPlacePose(0, Pose2{1.0, 2.0, 0.5});
  EXPECT_EQ(copy.places()[0].T_world_place.x, 1.0);
}

}  // namespace
}  // namespace keyplace
