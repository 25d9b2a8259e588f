// Place recognition on synthetic maps where the right place and transform are known; gamma by
// hand; descriptor pairing; self-match exclusion.

#include "keyplace/place/place_recognizer.hpp"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "keyplace/eval/localization.hpp"
#include "place/unique_pairs.hpp"

namespace keyplace {
namespace {

// A descriptor with its mass in 3 bins chosen by `code`: two different codes share no bin (when
// their bins differ), so their symmetric chi2 is 1; equal codes give 0.
BetaGridDescriptor Descriptor(int code) {
  BetaGridDescriptor d{};
  d[(code * 3) % kBetaGridBins] += 0.5f;
  d[(code * 3 + 1) % kBetaGridBins] += 0.3f;
  d[(code * 3 + 2) % kBetaGridBins] += 0.2f;
  return d;
}

// Places of `n` keypoints each, with descriptor codes 0..15 drawn at random: descriptors repeat
// across places (aliasing), so the geometry must decide.
std::vector<Place> MakePlaces(int count, int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  std::uniform_int_distribution<int> code(0, 15);
  std::vector<Place> places;
  for (int p = 0; p < count; ++p) {
    Place place;
    place.id = p;
    place.T_world_place = Pose2(20.0 * p, 5.0 * (p % 3), 0.3 * p);
    for (int k = 0; k < n; ++k) {
      place.positions.emplace_back(coordinate(rng), coordinate(rng));
      place.descriptors.push_back(Descriptor(code(rng)));
    }
    place.scan_indices = {10 * p, 10 * p + 1, 10 * p + 2};
    places.push_back(place);
  }
  return places;
}

// The query sees place `target` from frame T_place_query (its first pose), drops the last
// `dropped` keypoints and adds `extra` random ones.
PlaceQuery MakeQuery(const Place& target, const Pose2& T_place_query, int dropped, int extra,
                     std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  std::uniform_int_distribution<int> code(0, 15);
  PlaceQuery query;
  const Pose2 T_query_place = T_place_query.inverse();
  for (std::size_t k = 0; k + dropped < target.positions.size(); ++k) {
    query.positions.push_back(T_query_place * target.positions[k]);
    query.descriptors.push_back(target.descriptors[k]);
  }
  for (int k = 0; k < extra; ++k) {
    query.positions.emplace_back(coordinate(rng), coordinate(rng));
    query.descriptors.push_back(Descriptor(code(rng)));
  }
  query.T_first_evaluated = Pose2(1.5, 0.2, 0.1);
  return query;
}

TEST(PlaceRecognizer, FindsTheRightPlaceAndTransform) {
  const std::vector<Place> places = MakePlaces(30, 25, 11);
  for (const auto& preset : {std::string("default"), std::string("paper")}) {
    const PlaceRecognizer recognizer(places, PlacePreset(preset));
    for (int target = 0; target < 30; target += 7) {
      const Pose2 T_place_query(1.0, -0.5, 0.7);
      const PlaceQuery query = MakeQuery(places[target], T_place_query, 5, 8, 100 + target);
      const PlaceMatch match = recognizer.Recognize(query);
      ASSERT_TRUE(match.found) << preset << " target " << target;
      EXPECT_EQ(match.place_id, target) << preset;
      EXPECT_NEAR(match.T_ref_cur.x, T_place_query.x, 1e-6);
      EXPECT_NEAR(match.T_ref_cur.y, T_place_query.y, 1e-6);
      EXPECT_NEAR(match.T_ref_cur.theta, T_place_query.theta, 1e-6);
      // Eq. (9): P_r[0] * T_ref_cur * p_c.
      const Pose2 expected = places[target].T_world_place * T_place_query * query.T_first_evaluated;
      EXPECT_TRUE(IsCorrectPose(match.estimated_pose, expected, 1e-6, 1e-6));
      EXPECT_GE(match.consensus, 20);
      EXPECT_GT(match.confidence, 0.0);
    }
  }
}

TEST(PlaceRecognizer, ExhaustiveMatchesBruteForceCandidateCount) {
  // The candidate count equals a brute-force count of places with >= mu unique pairs.
  const std::vector<Place> places = MakePlaces(20, 15, 5);
  PlaceRecognitionConfig config;
  config.min_pairs = 6;
  const PlaceRecognizer recognizer(places, config);
  const PlaceQuery query = MakeQuery(places[3], Pose2(0.5, 0.5, 0.1), 0, 0, 9);
  int expected = 0;
  for (const Place& place : places) {
    // Unique pairs with exact-duplicate descriptors: per code, min(count in query, in place).
    int pairs = 0;
    for (int code = 0; code < 16; ++code) {
      int in_query = 0;
      int in_place = 0;
      for (const auto& d : query.descriptors) in_query += d == Descriptor(code);
      for (const auto& d : place.descriptors) in_place += d == Descriptor(code);
      pairs += std::min(in_query, in_place);
    }
    if (pairs >= config.min_pairs) ++expected;
  }
  const PlaceMatch match = recognizer.Recognize(query);
  EXPECT_EQ(match.candidates, expected);
  EXPECT_EQ(match.place_id, 3);
}

TEST(PlaceRecognizer, RigidPairRankingVerifiesTheRightPlaceWhenCandidatesExceedTheCap) {
  // Place 0 has the target's descriptors at unrelated positions: it pairs with the query as well
  // as the target and comes first by mean pair distance (all distances are 0, ties keep the map
  // order), but no rigid transform explains its pairs.
  std::vector<Place> places = MakePlaces(2, 25, 21);
  places[0].descriptors = places[1].descriptors;
  const PlaceQuery query = MakeQuery(places[1], Pose2(1.0, -0.5, 0.7), 5, 8, 77);
  PlaceRecognitionConfig config;
  config.max_candidates = 1;
  config.candidate_ranking = PlaceRecognitionConfig::CandidateRanking::kMeanDistance;
  const PlaceMatch by_distance = PlaceRecognizer(places, config).Recognize(query);
  EXPECT_EQ(by_distance.candidates, 2);
  EXPECT_EQ(by_distance.candidates_verified, 1);
  EXPECT_FALSE(by_distance.verified);
  config.candidate_ranking = PlaceRecognitionConfig::CandidateRanking::kRigidPairs;
  const PlaceMatch by_rigidity = PlaceRecognizer(places, config).Recognize(query);
  EXPECT_EQ(by_rigidity.candidates_verified, 1);
  ASSERT_TRUE(by_rigidity.found);
  EXPECT_EQ(by_rigidity.place_id, 1);
  // Under the cap the ranking changes nothing.
  config.max_candidates = 2;
  const PlaceMatch all = PlaceRecognizer(places, config).Recognize(query);
  config.candidate_ranking = PlaceRecognitionConfig::CandidateRanking::kMeanDistance;
  const PlaceMatch all_by_distance = PlaceRecognizer(places, config).Recognize(query);
  EXPECT_EQ(all.place_id, 1);
  EXPECT_EQ(all.place_id, all_by_distance.place_id);
  EXPECT_EQ(all.consensus, all_by_distance.consensus);
  EXPECT_EQ(all.score, all_by_distance.score);
}

TEST(PlaceRecognizer, AllScanKeypointsRecoverAQueryWithTooFewStableOnes) {
  // The query's stable keypoints are too few for mu pairs; the keypoints of all its scans (each
  // place keypoint seen twice, a few mm apart) are enough, and merging removes the duplicates.
  const std::vector<Place> places = MakePlaces(12, 25, 31);
  const Pose2 T_place_query(0.8, 0.3, -0.4);
  PlaceQuery query = MakeQuery(places[5], T_place_query, 20, 0, 7);  // 5 stable keypoints
  const Pose2 T_query_place = T_place_query.inverse();
  for (int copy = 0; copy < 2; ++copy) {
    for (std::size_t k = 0; k < places[5].positions.size(); ++k) {
      query.all_positions.push_back(T_query_place * places[5].positions[k] +
                                    Eigen::Vector2d(0.003 * copy, 0.0));
      query.all_descriptors.push_back(places[5].descriptors[k]);
    }
  }
  PlaceRecognitionConfig stable;
  stable.query_keypoints = PlaceRecognitionConfig::QueryKeypoints::kStable;
  EXPECT_FALSE(PlaceRecognizer(places, stable).Recognize(query).verified);

  PlaceRecognitionConfig all = stable;
  all.query_keypoints = PlaceRecognitionConfig::QueryKeypoints::kAllScans;
  all.consensus_counting = PlaceRecognitionConfig::ConsensusCounting::kDistinctReference;
  all.min_gamma = 1.0;            // not used: the query comes with all-scan keypoints
  all.min_gamma_all_scans = 0.0;  // gamma compares the 5 stable query keypoints with the place
  const PlaceMatch match = PlaceRecognizer(places, all).Recognize(query);
  ASSERT_TRUE(match.found);
  EXPECT_EQ(match.place_id, 5);
  EXPECT_NEAR(match.T_ref_cur.theta, T_place_query.theta, 1e-6);
  EXPECT_EQ(match.consensus, 25);  // distinct place keypoints, not 50 query keypoints

  // Without all-scan keypoints the query falls back to its stable ones and to min_gamma.
  const PlaceQuery stable_query = MakeQuery(places[5], T_place_query, 5, 8, 7);
  EXPECT_FALSE(PlaceRecognizer(places, all).Recognize(stable_query).verified);
  all.min_gamma = 0.0;
  EXPECT_TRUE(PlaceRecognizer(places, all).Recognize(stable_query).found);
}

TEST(QueryKeypoints, MergeKeepsTheFirstOfEachCluster) {
  const std::vector<Eigen::Vector2d> points = {{0.0, 0.0},   {0.03, 0.0}, {1.0, 0.0},
                                               {0.0, 0.049}, {0.0, 0.06}, {1.0, 0.04}};
  EXPECT_EQ(MergeNearbyKeypoints(points, 0.05), (std::vector<int>{0, 2, 4}));
  EXPECT_EQ(MergeNearbyKeypoints(points, 0.0), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(MergeNearbyKeypoints({}, 0.05).empty());
}

TEST(PlaceConfig, PaperPresetKeepsThePapersQueryConsensusAndGamma) {
  const PlaceRecognitionConfig paper = PlacePreset("paper");
  EXPECT_EQ(paper.query_keypoints, PlaceRecognitionConfig::QueryKeypoints::kStable);
  EXPECT_EQ(paper.consensus_counting, PlaceRecognitionConfig::ConsensusCounting::kQueryKeypoints);
  EXPECT_DOUBLE_EQ(paper.min_gamma, 0.4);
  const PlaceRecognitionConfig standard = PlacePreset("default");
  EXPECT_EQ(standard.query_keypoints, PlaceRecognitionConfig::QueryKeypoints::kAllScans);
  EXPECT_DOUBLE_EQ(standard.min_gamma, 0.4);  // stable queries (SLAM) keep the paper's check
  EXPECT_DOUBLE_EQ(standard.min_gamma_all_scans, 0.15);
  PlaceRecognitionConfig copy = standard;
  ApplyKeyValues({{"query_keypoints", "stable"}, {"consensus_counting", "query_keypoints"}}, copy);
  EXPECT_EQ(copy.query_keypoints, PlaceRecognitionConfig::QueryKeypoints::kStable);
  EXPECT_THROW(ApplyKeyValues({{"query_merge_m", "-1"}}, copy), std::invalid_argument);
}

TEST(Consensus, DistinctReferenceCountsEachReferenceKeypointOnce) {
  const std::vector<std::pair<int, int>> inliers = {{0, 3}, {1, 3}, {2, 5}, {3, 7}, {4, 5}};
  EXPECT_EQ(CountConsensus(inliers, PlaceRecognitionConfig::ConsensusCounting::kQueryKeypoints), 5);
  EXPECT_EQ(CountConsensus(inliers, PlaceRecognitionConfig::ConsensusCounting::kDistinctReference),
            3);
  EXPECT_EQ(CountConsensus({}, PlaceRecognitionConfig::ConsensusCounting::kDistinctReference), 0);
}

TEST(PlaceRecognizer, NoMatchWhenNothingFits) {
  const std::vector<Place> places = MakePlaces(10, 20, 1);
  const PlaceRecognizer recognizer(places, PlaceRecognitionConfig{});
  PlaceQuery query;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  for (int k = 0; k < 20; ++k) {
    query.positions.emplace_back(coordinate(rng), coordinate(rng));
    query.descriptors.push_back(Descriptor(k % 16));
  }
  const PlaceMatch match = recognizer.Recognize(query);
  EXPECT_FALSE(match.found);
  EXPECT_FALSE(match.verified);
}

TEST(PlaceRecognizer, SelfMatchRulesSkipPlaces) {
  std::vector<Place> places = MakePlaces(8, 25, 21);
  // Place 8: the same keypoints as place 2 seen from elsewhere (another pass), other scans.
  Place copy = places[2];
  copy.id = 8;
  copy.T_world_place = places[2].T_world_place * Pose2(2.0, 1.0, 0.5);
  const Pose2 T_copy_place2 = Pose2(2.0, 1.0, 0.5).inverse();
  for (auto& p : copy.positions) p = T_copy_place2 * p;
  copy.scan_indices = {500, 501, 502};
  places.push_back(copy);
  const PlaceRecognizer recognizer(places, PaperPlaceConfig());
  const PlaceQuery query = MakeQuery(places[2], Pose2(), 0, 0, 4);
  const std::vector<int> query_scans = {20, 21, 22};

  // Without exclusion the identical place 2 (mean pair distance 0, first) wins.
  EXPECT_EQ(recognizer.Recognize(query).place_id, 2);
  // The paper's rule skips place 2 (same scans): the other pass is found, at the right pose.
  const PlaceMatch paper = recognizer.Recognize(query, [&](const Place& place) {
    return IsSelfMatch(SelfMatchRule::kSameScans, query_scans, place.scan_indices);
  });
  EXPECT_EQ(paper.places_excluded, 1);
  ASSERT_TRUE(paper.found);
  EXPECT_EQ(paper.place_id, 8);
  const Pose2 expected = places[2].T_world_place * query.T_first_evaluated;
  EXPECT_TRUE(IsCorrectPose(paper.estimated_pose, expected, 1e-6, 1e-6));

  // A query sharing one scan with place 2 is skipped only by the shared-scan rule.
  const std::vector<int> shifted = {22, 23, 24};
  const PlaceMatch same = recognizer.Recognize(query, [&](const Place& place) {
    return IsSelfMatch(SelfMatchRule::kSameScans, shifted, place.scan_indices);
  });
  EXPECT_EQ(same.place_id, 2);
  const PlaceMatch shared = recognizer.Recognize(query, [&](const Place& place) {
    return IsSelfMatch(SelfMatchRule::kSharedScan, shifted, place.scan_indices);
  });
  EXPECT_EQ(shared.place_id, 8);
}

TEST(SelfMatch, Rules) {
  EXPECT_TRUE(IsSelfMatch(SelfMatchRule::kSameScans, {5, 6, 7}, {7, 6, 5}));
  EXPECT_FALSE(IsSelfMatch(SelfMatchRule::kSameScans, {5, 6, 7}, {5, 6, 7, 8}));
  EXPECT_TRUE(IsSelfMatch(SelfMatchRule::kSharedScan, {5, 6, 7}, {7, 8}));
  EXPECT_FALSE(IsSelfMatch(SelfMatchRule::kSharedScan, {5, 6, 7}, {8, 9}));
  EXPECT_FALSE(IsSelfMatch(SelfMatchRule::kNone, {5}, {5}));
}

TEST(Gamma, ByHandOnASmallCase) {
  // Reference box [0, 3] x [-0.5, 3]; current box [-1, 1.5] x [-1, 0.5]; overlap
  // [0, 1.5] x [-0.5, 0.5]. Inside: reference (0,0), (1,0) -> n_r = 2; current (0.02,0),
  // (1,0.03), (0.5,0.5) -> n_c = 3. Doubly matched (lambda 0.05, same descriptor): only
  // (0.02,0)-(0,0); (1,0.03) is near (1,0) but its descriptor differs.
  // gamma = 2 * 1 / (2 + 3) = 0.4.
  const std::vector<Eigen::Vector2d> reference = {{0, 0}, {1, 0}, {0, 1}, {3, 3}, {2, -0.5}};
  const std::vector<BetaGridDescriptor> reference_d = {Descriptor(1), Descriptor(2), Descriptor(3),
                                                       Descriptor(4), Descriptor(5)};
  const std::vector<Eigen::Vector2d> current_ref = {
      {0.02, 0}, {1, 0.03}, {0.5, 0.5}, {-1, -1}, {1.5, -1}};
  const std::vector<BetaGridDescriptor> current_d = {Descriptor(1), Descriptor(7), Descriptor(3),
                                                     Descriptor(4), Descriptor(5)};
  // Express the current keypoints in a frame T_ref_cur away.
  const Pose2 T_ref_cur(0.7, -2.0, 1.3);
  std::vector<Eigen::Vector2d> current;
  for (const auto& p : current_ref) current.push_back(T_ref_cur.inverse() * p);
  for (auto counting : {PlaceRecognitionConfig::GammaCounting::kUniquePairs,
                        PlaceRecognitionConfig::GammaCounting::kPerKeypoint}) {
    const GammaResult gamma =
        ComputeGamma(reference, reference_d, current, current_d, T_ref_cur, 0.05, 0.4, counting);
    EXPECT_EQ(gamma.reference_in_overlap, 2);
    EXPECT_EQ(gamma.current_in_overlap, 3);
    EXPECT_DOUBLE_EQ(gamma.double_matched, 1.0);
    EXPECT_NEAR(gamma.gamma, 0.4, 1e-12);
  }
  // lambda 0.01 loses the double match.
  EXPECT_EQ(ComputeGamma(reference, reference_d, current, current_d, T_ref_cur, 0.01, 0.4,
                         PlaceRecognitionConfig::GammaCounting::kUniquePairs)
                .gamma,
            0.0);
}

TEST(ReferenceCoverage, ByHandOnTheGammaCase) {
  // Same boxes as above: the reference keypoints inside the overlap are (0,0) and (1,0); the
  // nearest current keypoints lie 0.02 m and 0.03 m away (descriptors do not matter here).
  const std::vector<Eigen::Vector2d> reference = {{0, 0}, {1, 0}, {0, 1}, {3, 3}, {2, -0.5}};
  const std::vector<Eigen::Vector2d> current_ref = {
      {0.02, 0}, {1, 0.03}, {0.5, 0.5}, {-1, -1}, {1.5, -1}};
  const Pose2 T_ref_cur(0.7, -2.0, 1.3);
  std::vector<Eigen::Vector2d> current;
  for (const auto& p : current_ref) current.push_back(T_ref_cur.inverse() * p);
  EXPECT_NEAR(ReferenceCoverage(reference, current, T_ref_cur, 0.1), 1.0, 1e-12);
  EXPECT_NEAR(ReferenceCoverage(reference, current, T_ref_cur, 0.025), 0.5, 1e-12);
  EXPECT_EQ(ReferenceCoverage(reference, current, T_ref_cur, 0.01), 0.0);
  // Disjoint boxes: nothing to cover.
  EXPECT_EQ(ReferenceCoverage(reference, current, Pose2(100.0, 0.0, 0.0) * T_ref_cur, 0.1), 0.0);
}

TEST(PlaceRecognizer, ReferenceCoverageCheckRejectsPartialMatches) {
  // The query re-observes 13 of the place's 25 keypoints (plus 8 random ones): consensus and
  // gamma pass, but about half of the reference keypoints in the overlap stay uncovered.
  // The check applies to queries verified with their all-scan keypoints.
  const std::vector<Place> places = MakePlaces(10, 25, 5);
  const auto with_all_scan_keypoints = [](PlaceQuery query) {
    query.all_positions = query.positions;
    query.all_descriptors = query.descriptors;
    return query;
  };
  const PlaceQuery stable_only = MakeQuery(places[3], Pose2(0.4, 0.3, -0.2), 12, 8, 77);
  const PlaceQuery query = with_all_scan_keypoints(stable_only);
  PlaceRecognitionConfig config = PlacePreset("default");
  EXPECT_EQ(config.min_reference_coverage, 0.0);
  EXPECT_EQ(PlacePreset("strict").min_reference_coverage, 0.5);
  config.min_reference_coverage = 0.0;
  const PlaceMatch open = PlaceRecognizer(places, config).Recognize(query);
  ASSERT_TRUE(open.found);
  EXPECT_EQ(open.place_id, 3);
  EXPECT_GT(open.reference_coverage, 0.4);
  EXPECT_LT(open.reference_coverage, 0.8);
  config.min_reference_coverage = 0.9;
  EXPECT_FALSE(PlaceRecognizer(places, config).Recognize(query).verified);
  // A stable-keypoint query is not checked.
  EXPECT_TRUE(PlaceRecognizer(places, config).Recognize(stable_only).found);
  // A full re-observation covers every reference keypoint in the overlap.
  const PlaceMatch full =
      PlaceRecognizer(places, config)
          .Recognize(with_all_scan_keypoints(MakeQuery(places[3], Pose2(), 0, 8, 78)));
  ASSERT_TRUE(full.found);
  EXPECT_DOUBLE_EQ(full.reference_coverage, 1.0);
}

TEST(DescriptorPairs, EachKeypointUsedOnce) {
  BetaGridDescriptor a = Descriptor(1);
  BetaGridDescriptor a2 = a;
  a2[3] += 0.05f;  // a2 slightly farther from a than a is from itself
  const std::vector<BetaGridDescriptor> current = {a2, a};
  const std::vector<BetaGridDescriptor> reference = {a};
  // Query order: the first current keypoint (a2) takes the only reference keypoint.
  const auto in_order = MatchDescriptorPairs(current, reference, 0.4,
                                             PlaceRecognitionConfig::PairMatching::kQueryOrder);
  ASSERT_EQ(in_order.size(), 1u);
  EXPECT_EQ(in_order[0].current, 0);
  // Global greedy: the closest pair (a, a) wins.
  const auto greedy = MatchDescriptorPairs(current, reference, 0.4,
                                           PlaceRecognitionConfig::PairMatching::kGlobalGreedy);
  ASSERT_EQ(greedy.size(), 1u);
  EXPECT_EQ(greedy[0].current, 1);
  EXPECT_DOUBLE_EQ(greedy[0].distance, 0.0);
}

// Global greedy takes the pairs by distance and equally distant ones in (current, reference)
// order, as Algorithm 3's loop meets them: with hundreds of ties any other order (an unstable
// sort by distance alone) pairs the keypoints differently.
TEST(DescriptorPairs, GlobalGreedyBreaksTiesInQueryThenReferenceOrder) {
  const BetaGridDescriptor a = Descriptor(1);
  BetaGridDescriptor a2 = a;
  a2[3] += 0.05f;
  std::vector<BetaGridDescriptor> current;
  for (int c = 0; c < 30; ++c) current.push_back(c % 2 == 0 ? a : a2);
  const std::vector<BetaGridDescriptor> reference(20, a);
  const auto greedy = MatchDescriptorPairs(current, reference, 0.4,
                                           PlaceRecognitionConfig::PairMatching::kGlobalGreedy);
  std::vector<std::pair<int, int>> expected;
  for (int c = 0; c < 30; c += 2) expected.emplace_back(c, c / 2);  // distance 0 first
  for (int c = 1; c < 10; c += 2) expected.emplace_back(c, 15 + c / 2);
  ASSERT_EQ(greedy.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(greedy[k].current, expected[k].first) << k;
    EXPECT_EQ(greedy[k].reference, expected[k].second) << k;
  }
  EXPECT_EQ(greedy[0].distance, 0.0);
  EXPECT_GT(greedy.back().distance, 0.0);
}

// UniquePairs takes the pairs in chunks; on random pair lists with many ties (distances from a
// few values), of every size around the chunk, it takes what one stable sort and one pass take.
TEST(DescriptorPairs, GlobalGreedyEqualsOneSortedPass) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 300; ++trial) {
    const int n_current = 1 + static_cast<int>(rng() % 90);
    const int n_reference = 1 + static_cast<int>(rng() % 90);
    const double keep = std::uniform_real_distribution<double>(0.05, 0.6)(rng);
    std::vector<DescriptorPair> below;  // ordered by current, then reference, as given
    for (int c = 0; c < n_current; ++c) {
      for (int r = 0; r < n_reference; ++r) {
        if (std::uniform_real_distribution<double>(0.0, 1.0)(rng) >= keep) continue;
        below.push_back({c, r, 0.05 * static_cast<double>(rng() % 7)});
      }
    }
    std::vector<DescriptorPair> sorted = below;
    std::stable_sort(
        sorted.begin(), sorted.end(),
        [](const DescriptorPair& a, const DescriptorPair& b) { return a.distance < b.distance; });
    std::vector<char> current_used(static_cast<std::size_t>(n_current), 0);
    std::vector<char> reference_used(static_cast<std::size_t>(n_reference), 0);
    std::vector<DescriptorPair> expected;
    for (const DescriptorPair& pair : sorted) {
      if (current_used[pair.current] || reference_used[pair.reference]) continue;
      current_used[pair.current] = 1;
      reference_used[pair.reference] = 1;
      expected.push_back(pair);
    }
    const std::vector<DescriptorPair> greedy = UniquePairs(
        below, static_cast<std::size_t>(n_current), static_cast<std::size_t>(n_reference),
        PlaceRecognitionConfig::PairMatching::kGlobalGreedy);
    ASSERT_EQ(greedy.size(), expected.size()) << "trial " << trial;
    for (std::size_t k = 0; k < expected.size(); ++k) {
      ASSERT_EQ(greedy[k].current, expected[k].current) << "trial " << trial << ", pair " << k;
      ASSERT_EQ(greedy[k].reference, expected[k].reference) << "trial " << trial << ", pair " << k;
      ASSERT_EQ(greedy[k].distance, expected[k].distance);
    }
  }
}

TEST(PlaceConfig, KeyValuesRoundTripAndErrorsNameTheField) {
  PlaceRecognitionConfig config = PaperPlaceConfig();
  std::map<std::string, std::string> values;
  for (const auto& [key, value] : ToKeyValues(config)) values[key] = value;
  PlaceRecognitionConfig copy;
  ApplyKeyValues(values, copy);
  EXPECT_EQ(ToKeyValues(copy), ToKeyValues(config));
  try {
    ApplyKeyValues({{"min_gamma", "2"}}, copy);
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("min_gamma"), std::string::npos);
  }
  EXPECT_THROW(ApplyKeyValues({{"no_such_key", "1"}}, copy), std::invalid_argument);
  EXPECT_THROW(PlacePreset("fast"), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
