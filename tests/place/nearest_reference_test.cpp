// The inlier search of RANSAC's scoring gives what a scan of every reference keypoint in index
// order gives, including ties, points on the threshold and non-finite coordinates.

#include "place/nearest_reference.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

// The scan ScoreTransform did before the sorted search: the first of the nearest, kept only when
// nearer than the radius.
std::pair<int, double> ScanEveryKeypoint(const std::vector<Eigen::Vector2d>& reference,
                                         const Eigen::Vector2d& point, double radius_m) {
  double best = std::numeric_limits<double>::infinity();
  int best_index = -1;
  for (std::size_t j = 0; j < reference.size(); ++j) {
    const double d2 = (point - reference[j]).squaredNorm();
    if (d2 < best) {
      best = d2;
      best_index = static_cast<int>(j);
    }
  }
  if (best < radius_m * radius_m) return {best_index, best};
  return {-1, radius_m * radius_m};
}

TEST(NearestReference, EqualsAScanOfEveryKeypoint) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
  std::uniform_real_distribution<double> jitter(-0.12, 0.12);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Eigen::Vector2d> reference;
    reference.reserve(62);
    for (int k = 0; k < 60; ++k) reference.emplace_back(coordinate(rng), coordinate(rng));
    reference.push_back(reference[7]);  // an exact duplicate: the earlier index must win
    reference.emplace_back(reference[3].x(), reference[3].y() + 0.05);  // same x
    const NearestReference search(reference, 0.1);
    int inliers = 0;
    for (int q = 0; q < 200; ++q) {
      const Eigen::Vector2d& near = reference[static_cast<std::size_t>(q) % reference.size()];
      const Eigen::Vector2d point =
          q % 2 == 0 ? Eigen::Vector2d(coordinate(rng), coordinate(rng))
                     : Eigen::Vector2d(near.x() + jitter(rng), near.y() + jitter(rng));
      const auto expected = ScanEveryKeypoint(reference, point, 0.1);
      const auto found = search.Nearest(point);
      ASSERT_EQ(found.first, expected.first) << "trial " << trial << " query " << q;
      ASSERT_EQ(found.second, expected.second);
      inliers += found.first >= 0;
    }
    EXPECT_GT(inliers, 40);  // the jittered half mostly lands within 0.1 m
  }
}

// A long thin place, queries around and far beyond its ends and sides, and huge coordinates:
// the scan's answers.
TEST(NearestReference, EqualsAScanOfEveryKeypointOnALongStripAndBeyondIt) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> along(0.0, 400.0);
  std::uniform_real_distribution<double> across(-0.3, 0.3);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  std::vector<Eigen::Vector2d> reference;
  for (int k = 0; k < 300; ++k) reference.emplace_back(along(rng), across(rng));
  reference.emplace_back(-0.05, 0.31);  // on the corners of the strip
  reference.emplace_back(400.02, -0.31);
  const NearestReference search(reference, 0.1);
  int inliers = 0;
  for (int q = 0; q < 3000; ++q) {
    const Eigen::Vector2d& near = reference[static_cast<std::size_t>(q) % reference.size()];
    Eigen::Vector2d point(near.x() + jitter(rng), near.y() + jitter(rng));
    if (q % 3 == 1) point = {along(rng) * 1.2 - 40.0, across(rng) * 3.0};  // around the strip
    const auto expected = ScanEveryKeypoint(reference, point, 0.1);
    const auto found = search.Nearest(point);
    ASSERT_EQ(found.first, expected.first) << "query " << q;
    ASSERT_EQ(found.second, expected.second);
    inliers += found.first >= 0;
  }
  EXPECT_GT(inliers, 500);
  for (const Eigen::Vector2d& point :
       {Eigen::Vector2d(-0.12, 0.31), Eigen::Vector2d(400.1, -0.35), Eigen::Vector2d(1e300, 0.0),
        Eigen::Vector2d(-1e300, -1e300)}) {
    EXPECT_EQ(search.Nearest(point), ScanEveryKeypoint(reference, point, 0.1));
  }
}

// A dense place: dozens of keypoints in the strip of every query, many of them within the radius.
TEST(NearestReference, EqualsAScanOfEveryKeypointInADensePlace) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::vector<Eigen::Vector2d> reference;
  for (int k = 0; k < 2000; ++k) reference.emplace_back(coordinate(rng), coordinate(rng));
  const NearestReference search(reference, 0.1);
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector2d point(coordinate(rng) * 1.1, coordinate(rng) * 1.1);
    ASSERT_EQ(search.Nearest(point), ScanEveryKeypoint(reference, point, 0.1)) << "query " << q;
  }
}

TEST(NearestReference, TiesThresholdAndNonFiniteKeypoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector2d> reference = {{nan, 0.0},
                                                  {1.0, 0.0},
                                                  {0.0, 1.0},
                                                  {0.0, -1.0},
                                                  {std::numeric_limits<double>::infinity(), 0.0}};
  const NearestReference search(reference, 1.5);
  // (0, 0) is 1 m from keypoints 1, 2 and 3: the first of them.
  EXPECT_EQ(search.Nearest({0.0, 0.0}), std::make_pair(1, 1.0));
  // Exactly on the radius is not within it.
  const NearestReference tight(reference, 1.0);
  EXPECT_EQ(tight.Nearest({0.0, 0.0}), std::make_pair(-1, 1.0));
  EXPECT_EQ(search.Nearest({nan, 0.0}).first, -1);
  EXPECT_EQ(search.Nearest({5.0, 5.0}).first, -1);
}

}  // namespace
}  // namespace keyplace
