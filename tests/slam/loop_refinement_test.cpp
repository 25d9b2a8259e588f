// Loop refinement (ICP between submap clouds) and loop partner choice on synthetic submaps cast
// in a known world, so that the true transform between any two submaps is known.

#include "keyplace/slam/loop_refinement.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "registration/synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::CastScan;
using testing::Polygon;
using testing::ScanOptions;
using testing::Segment;

// A long hall (40 x 6 m) with irregular boxes along both walls (seeded), so that every stretch
// of it looks different and registration is constrained in every direction.
std::vector<Segment> Hall() {
  std::vector<Segment> world = Polygon({{-20, -3}, {20, -3}, {20, 3}, {-20, 3}});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> size(0.2, 0.7);
  std::uniform_real_distribution<double> gap(0.8, 2.0);
  std::uniform_real_distribution<double> turn(-0.7, 0.7);
  for (const double wall : {-2.6, 2.6}) {
    double u = -19.0;
    while (u < 19.0) {
      const double w = size(rng), h = size(rng), a = turn(rng);
      std::vector<Eigen::Vector2d> box;
      for (const auto& c : {Eigen::Vector2d(-w / 2, -h / 2), Eigen::Vector2d(w / 2, -h / 2),
                            Eigen::Vector2d(w / 2, h / 2), Eigen::Vector2d(-w / 2, h / 2)}) {
        box.emplace_back(u + std::cos(a) * c.x() - std::sin(a) * c.y(),
                         wall + std::sin(a) * c.x() + std::cos(a) * c.y());
      }
      const std::vector<Segment> segments = Polygon(box);
      world.insert(world.end(), segments.begin(), segments.end());
      u += gap(rng);
    }
  }
  return world;
}

// A submap of `scans` scans 0.2 m apart along the hall axis starting at `origin` (world frame),
// with a 180 deg laser of 8 m range looking along +x (so it sees a limited stretch of the hall).
// Its cloud is in the frame of its first pose.
SubmapCloud CastSubmap(const std::vector<Segment>& world, const Pose2& origin, int scans,
                       std::mt19937* rng, const LoopRefinementConfig& config) {
  ScanOptions options = testing::FrontLaser(361, 0.01);
  options.max_range_m = 8.0;
  std::vector<std::vector<Eigen::Vector2d>> points;
  std::vector<Pose2> T_submap_laser;
  for (int k = 0; k < scans; ++k) {
    const Pose2 T_submap_k(0.2 * k, 0.0, 0.02 * k);
    const LaserScan scan = CastScan(world, origin * T_submap_k, options, rng);
    points.push_back(scan.ValidEndpoints());
    T_submap_laser.push_back(T_submap_k);
  }
  return BuildSubmapCloud(points, T_submap_laser, config);
}

double TranslationError(const Pose2& a, const Pose2& b) { return TranslationNorm(Between(a, b)); }
double RotationError(const Pose2& a, const Pose2& b) { return std::abs(Between(a, b).theta); }

TEST(LoopRefinement, BuildSubmapCloudThinsOnTheVoxelGridAndFitsNormals) {
  LoopRefinementConfig config;
  config.voxel_m = 0.1;
  // Two copies of the same straight wall, 1 cm apart: one mean point per 0.1 m voxel.
  std::vector<Eigen::Vector2d> wall;
  wall.reserve(50);
  for (int i = 0; i < 50; ++i) wall.emplace_back(0.02 * i + 0.001, 1.05);
  const SubmapCloud cloud =
      BuildSubmapCloud({wall, wall}, {Pose2(), Pose2(0.0, 0.01, 0.0)}, config);
  EXPECT_EQ(cloud.points.size(), 10u);
  for (const Eigen::Vector2d& p : cloud.points) EXPECT_NEAR(p.y(), 1.055, 1e-9);
  ASSERT_EQ(cloud.normals.normals.size(), cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    ASSERT_TRUE(cloud.normals.valid[i]);
    EXPECT_NEAR(std::abs(cloud.normals.normals[i].y()), 1.0, 1e-6);
  }
  EXPECT_THROW(BuildSubmapCloud({wall}, {}, config), std::invalid_argument);
}

TEST(LoopRefinement, PointOverlapIsOneForTheSameCloudAndZeroWhenDisjoint) {
  const std::vector<Segment> world = Hall();
  std::mt19937 rng(1);
  const LoopRefinementConfig config;
  const SubmapCloud a = CastSubmap(world, Pose2(-10.0, 0.0, 0.0), 8, &rng, config);
  EXPECT_GT(PointOverlap(a, a, Pose2(), config.icp), 0.9);
  EXPECT_EQ(PointOverlap(a, a, Pose2(100.0, 0.0, 0.0), config.icp), 0.0);
  EXPECT_EQ(PointOverlap(a, SubmapCloud{}, Pose2(), config.icp), 0.0);
}

TEST(LoopRefinement, RecoversAKnownSmallOffsetBetweenTwoSubmaps) {
  const std::vector<Segment> world = Hall();
  std::mt19937 rng(2);
  const LoopRefinementConfig config;
  // The same stretch seen twice from slightly different places (a revisit).
  const Pose2 ref_origin(-6.0, -0.3, 0.05);
  const Pose2 cur_origin(-5.6, 0.4, -0.08);
  const SubmapCloud reference = CastSubmap(world, ref_origin, 10, &rng, config);
  const SubmapCloud current = CastSubmap(world, cur_origin, 10, &rng, config);
  const Pose2 truth = Between(ref_origin, cur_origin);
  // A RANSAC-like estimate: 8 cm and 6 cm off, 2 deg.
  const Pose2 initial = truth * Pose2(0.08, -0.06, 2.0 * M_PI / 180.0);
  const LoopRefinement r = RefineLoop(reference, current, initial, config);
  ASSERT_TRUE(r.refined) << ToString(r.status);
  EXPECT_LT(TranslationError(r.T_ref_cur, truth), 0.01);
  EXPECT_LT(RotationError(r.T_ref_cur, truth), 0.2 * M_PI / 180.0);
  EXPECT_GT(r.inlier_ratio, r.inlier_ratio_initial);
  EXPECT_GT(r.inlier_ratio, 0.8);
  EXPECT_NEAR(r.correction_m, TranslationError(initial, truth), 0.01);
  EXPECT_GT(r.overlap, PointOverlap(reference, current, initial, config.icp));

  // Refinement off: the initial estimate, scored.
  LoopRefinementConfig off = config;
  off.refine = false;
  const LoopRefinement kept = RefineLoop(reference, current, initial, off);
  EXPECT_FALSE(kept.refined);
  EXPECT_EQ(kept.T_ref_cur.x, initial.x);
  EXPECT_EQ(kept.T_ref_cur.theta, initial.theta);
  EXPECT_DOUBLE_EQ(kept.inlier_ratio, kept.inlier_ratio_initial);
  EXPECT_DOUBLE_EQ(kept.overlap, PointOverlap(reference, current, initial, config.icp));
}

TEST(LoopRefinement, KeepsTheInitialEstimateWhenTheCorrectionWouldBeTooLarge) {
  const std::vector<Segment> world = Hall();
  std::mt19937 rng(3);
  LoopRefinementConfig config;
  const Pose2 ref_origin(4.0, 0.2, 0.0);
  const Pose2 cur_origin(4.3, -0.2, 0.1);
  const SubmapCloud reference = CastSubmap(world, ref_origin, 10, &rng, config);
  const SubmapCloud current = CastSubmap(world, cur_origin, 10, &rng, config);
  const Pose2 truth = Between(ref_origin, cur_origin);
  const Pose2 initial = truth * Pose2(0.15, 0.1, 0.0);
  config.max_correction_m = 0.05;  // ICP would move it by 0.18 m
  const LoopRefinement r = RefineLoop(reference, current, initial, config);
  EXPECT_FALSE(r.refined);
  EXPECT_EQ(r.T_ref_cur.x, initial.x);
  EXPECT_EQ(r.T_ref_cur.y, initial.y);
  EXPECT_EQ(r.correction_m, 0.0);
  // Without the bound it is refined.
  config.max_correction_m = 0.5;
  EXPECT_TRUE(RefineLoop(reference, current, initial, config).refined);
}

TEST(LoopRefinement, KeepsTheInitialEstimateWhenTheCloudsDoNotOverlap) {
  const std::vector<Segment> world = Hall();
  std::mt19937 rng(4);
  const LoopRefinementConfig config;
  const SubmapCloud reference = CastSubmap(world, Pose2(-15.0, 0.0, 0.0), 6, &rng, config);
  const SubmapCloud current = CastSubmap(world, Pose2(8.0, 0.0, 0.0), 6, &rng, config);
  const Pose2 wrong(0.3, 0.1, 0.05);  // a wrong loop: the clouds are 23 m apart in truth
  const LoopRefinement r = RefineLoop(reference, current, wrong, config);
  if (r.refined) {
    // ICP may only have converged to something close to the start and must not wander off.
    EXPECT_LE(r.correction_m, config.max_correction_m);
  } else {
    EXPECT_EQ(r.T_ref_cur.x, wrong.x);
  }
  EXPECT_LT(r.overlap, 0.5);
}

TEST(LoopRefinement, ChoosesTheNeighbourThatOverlapsTheCurrentSubmapMost) {
  const std::vector<Segment> world = Hall();
  std::mt19937 rng(6);
  const LoopRefinementConfig config;
  // The map's consecutive submaps 10, 11, 12 along the hall (4 m apart); the current submap
  // revisits the stretch of submap 11, but place recognition matched submap 10, which shares
  // only part of it.
  const Pose2 origin10(-8.0, 0.0, 0.0), origin11(-4.0, 0.1, 0.02), origin12(0.0, -0.1, 0.0);
  const SubmapCloud s10 = CastSubmap(world, origin10, 10, &rng, config);
  const SubmapCloud s11 = CastSubmap(world, origin11, 10, &rng, config);
  const SubmapCloud s12 = CastSubmap(world, origin12, 10, &rng, config);
  const Pose2 cur_origin(-3.9, 0.3, -0.04);
  const SubmapCloud current = CastSubmap(world, cur_origin, 10, &rng, config);
  const Pose2 ransac = Between(origin10, cur_origin) * Pose2(0.05, 0.04, 0.01);
  // The graph's estimate of the neighbours relative to submap 10, 3 cm / 0.5 deg off.
  const std::vector<LoopPartnerCandidate> candidates{
      {12, &s12, Between(origin12, origin10) * Pose2(0.03, 0.0, 0.009)},
      {11, &s11, Between(origin11, origin10) * Pose2(0.0, 0.03, -0.009)}};
  const LoopPartnerChoice choice = ChooseLoopPartner(current, 10, s10, ransac, candidates, config);
  EXPECT_EQ(choice.partner, 11);
  EXPECT_TRUE(choice.refinement.refined);
  const Pose2 truth = Between(origin11, cur_origin);
  EXPECT_LT(TranslationError(choice.refinement.T_ref_cur, truth), 0.01);
  EXPECT_LT(RotationError(choice.refinement.T_ref_cur, truth), 0.2 * M_PI / 180.0);
  EXPECT_GT(choice.refinement.overlap, RefineLoop(s10, current, ransac, config).overlap + 0.1);

  // Without candidates, or when they do not overlap the current submap, the matched one stays.
  EXPECT_EQ(ChooseLoopPartner(current, 10, s10, ransac, {}, config).partner, 10);
  const SubmapCloud far = CastSubmap(world, Pose2(15.0, 0.0, 0.0), 10, &rng, config);
  const LoopPartnerChoice kept = ChooseLoopPartner(
      current, 10, s10, ransac, {{9, &far, Between(Pose2(15.0, 0.0, 0.0), origin10)}}, config);
  EXPECT_EQ(kept.partner, 10);
  EXPECT_THROW(ChooseLoopPartner(current, 10, s10, ransac, {{9, nullptr, Pose2()}}, config),
               std::invalid_argument);
}

TEST(LoopRefinement, RejectsInvalidConfig) {
  LoopRefinementConfig config;
  config.voxel_m = 0.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = LoopRefinementConfig();
  config.partner_neighbours = -1;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = LoopRefinementConfig();
  config.icp.min_inlier_ratio = 2.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
