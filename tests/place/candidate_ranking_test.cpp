// Which candidates are verified when there are more than n_c: the rigid-pair count and the choice
// of the n_c most rigid ones.

#include "place/candidate_ranking.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "keyplace/common/pose2.hpp"

namespace keyplace {
namespace {

std::vector<DescriptorPair> Identity(int count) {
  std::vector<DescriptorPair> pairs;
  pairs.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) pairs.push_back({k, k, 0.1});
  return pairs;
}

TEST(LargestRigidStar, CountsThePairsOneRigidTransformExplains) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  const Pose2 T_ref_cur(2.0, -1.0, 0.8);
  std::vector<Eigen::Vector2d> current;
  std::vector<Eigen::Vector2d> reference;
  for (int k = 0; k < 12; ++k) {  // 12 pairs seen through T_ref_cur
    current.emplace_back(coordinate(rng), coordinate(rng));
    reference.push_back(T_ref_cur * current.back());
  }
  const double rigidity_m2 = 0.0064;
  EXPECT_EQ(LargestRigidStar(Identity(12), current, reference, rigidity_m2), 12);
  // Three pairs whose reference keypoint is 40-60 m away agree with no correct pair.
  for (int k = 0; k < 3; ++k) {
    current.emplace_back(coordinate(rng), coordinate(rng));
    reference.emplace_back(40.0 + 10.0 * k, 0.0);
  }
  EXPECT_EQ(LargestRigidStar(Identity(15), current, reference, rigidity_m2), 12);
  // A reflected copy keeps every distance: rigidity is a necessary condition, not a proof.
  std::vector<Eigen::Vector2d> mirrored;
  mirrored.reserve(current.size());
  for (const Eigen::Vector2d& p : current) mirrored.emplace_back(p.x(), -p.y());
  EXPECT_EQ(LargestRigidStar(Identity(12), current, mirrored, rigidity_m2), 12);
}

TEST(LargestRigidStar, RandomPairsAgreeRarelyAndNoPairsCountNothing) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  std::vector<Eigen::Vector2d> current;
  std::vector<Eigen::Vector2d> reference;
  for (int k = 0; k < 30; ++k) {
    current.emplace_back(coordinate(rng), coordinate(rng));
    reference.emplace_back(coordinate(rng), coordinate(rng));
  }
  const int star = LargestRigidStar(Identity(30), current, reference, 0.0064);
  EXPECT_GE(star, 1);
  EXPECT_LE(star, 8);  // chance agreement of 30 unrelated pairs, far below 30
  EXPECT_EQ(LargestRigidStar({}, current, reference, 0.0064), 0);
  // A pair whose two keypoints coincide on one side gives no sample, as in RANSAC.
  const std::vector<Eigen::Vector2d> same(2, Eigen::Vector2d(1.0, 1.0));
  EXPECT_EQ(LargestRigidStar(Identity(2), same, same, 0.0064), 1);
}

TEST(KeepMostRigid, KeepsTheLargestInTheirOrderTiesToTheEarlier) {
  const std::vector<int> star = {3, 9, 5, 9, 1, 5, 7};
  EXPECT_EQ(KeepMostRigid(star, 3), (std::vector<std::size_t>{1, 3, 6}));
  EXPECT_EQ(KeepMostRigid(star, 4), (std::vector<std::size_t>{1, 2, 3, 6}));  // 5 at 2 before 5
  EXPECT_EQ(KeepMostRigid(star, 7), (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(KeepMostRigid(star, 70).size(), 7U);
  EXPECT_TRUE(KeepMostRigid(star, 0).empty());
}

}  // namespace
}  // namespace keyplace
