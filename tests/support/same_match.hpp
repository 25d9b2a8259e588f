#pragma once
// Field-by-field equality of place-recognition answers (every field but the seconds_* timings and
// descriptors_remembered, which say how an answer was made), for tests that two ways of answering
// agree exactly.

#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/place/place_recognizer.hpp"

namespace keyplace::testing {

// The same descriptor pairs in the same order, distances bit for bit.
inline void ExpectSamePairs(const std::vector<DescriptorPair>& a,
                            const std::vector<DescriptorPair>& b, const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].current, b[k].current) << where << ", pair " << k;
    EXPECT_EQ(a[k].reference, b[k].reference) << where << ", pair " << k;
    EXPECT_EQ(a[k].distance, b[k].distance) << where << ", pair " << k;
  }
}

inline void ExpectSamePose(const Pose2& a, const Pose2& b, const std::string& where) {
  EXPECT_EQ(a.x, b.x) << where;
  EXPECT_EQ(a.y, b.y) << where;
  EXPECT_EQ(a.theta, b.theta) << where;
}

inline void ExpectSameCandidate(const CandidateResult& a, const CandidateResult& b,
                                const std::string& where) {
  EXPECT_EQ(a.place_index, b.place_index) << where;
  EXPECT_EQ(a.pairs, b.pairs) << where;
  EXPECT_EQ(a.mean_pair_distance, b.mean_pair_distance) << where;
  EXPECT_EQ(a.consensus, b.consensus) << where;
  EXPECT_EQ(a.gamma, b.gamma) << where;
  EXPECT_EQ(a.reference_coverage, b.reference_coverage) << where;
  EXPECT_EQ(a.verified, b.verified) << where;
  ExpectSamePose(a.T_ref_cur, b.T_ref_cur, where);
  ExpectSamePose(a.estimated_pose, b.estimated_pose, where);
  EXPECT_EQ(a.estimated_pose_covariance, b.estimated_pose_covariance) << where;
  EXPECT_EQ(a.score, b.score) << where;
}

// Every field but seconds_* and descriptors_remembered.
inline void ExpectSameMatch(const PlaceMatch& a, const PlaceMatch& b, const std::string& where) {
  EXPECT_EQ(a.verified, b.verified) << where;
  EXPECT_EQ(a.found, b.found) << where;
  EXPECT_EQ(a.ambiguous, b.ambiguous) << where;
  EXPECT_EQ(a.place_index, b.place_index) << where;
  EXPECT_EQ(a.place_id, b.place_id) << where;
  ExpectSamePose(a.T_ref_cur, b.T_ref_cur, where);
  ExpectSamePose(a.estimated_pose, b.estimated_pose, where);
  EXPECT_EQ(a.estimated_pose_covariance, b.estimated_pose_covariance) << where;
  EXPECT_EQ(a.pairs, b.pairs) << where;
  EXPECT_EQ(a.consensus, b.consensus) << where;
  EXPECT_EQ(a.gamma, b.gamma) << where;
  EXPECT_EQ(a.reference_coverage, b.reference_coverage) << where;
  EXPECT_EQ(a.score, b.score) << where;
  EXPECT_EQ(a.second_score, b.second_score) << where;
  EXPECT_EQ(a.confidence, b.confidence) << where;
  EXPECT_EQ(a.candidates, b.candidates) << where;
  EXPECT_EQ(a.candidates_verified, b.candidates_verified) << where;
  EXPECT_EQ(a.candidates_accepted, b.candidates_accepted) << where;
  EXPECT_EQ(a.places_excluded, b.places_excluded) << where;
  EXPECT_EQ(a.weak_confidence, b.weak_confidence) << where;
  ASSERT_EQ(a.weak.has_value(), b.weak.has_value()) << where;
  if (a.weak) ExpectSameCandidate(*a.weak, *b.weak, where + ", weak answer");
  ASSERT_EQ(a.verified_candidates.size(), b.verified_candidates.size()) << where;
  for (std::size_t k = 0; k < a.verified_candidates.size(); ++k) {
    ExpectSameCandidate(a.verified_candidates[k], b.verified_candidates[k],
                        where + ", verified candidate " + std::to_string(k));
  }
}

}  // namespace keyplace::testing
