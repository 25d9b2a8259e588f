// PrepareLogInputs on the bundled corrected log, cut to its first scans.

#include "keyplace/mapping/scan_sources.hpp"

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

TEST(PrepareLogInputs, PosesAndKeypointsOnRequest) {
  const std::string path = testing::SourceDir() + "/data/fr079-corrected.log.gz";
  LogInputOptions options;
  options.first_scan = 5;
  options.end_scan = 25;
  const LogInputs all = PrepareLogInputs(path, options);
  ASSERT_EQ(all.log.scans.size(), 20u);
  EXPECT_EQ(all.first_scan, 5u);
  EXPECT_EQ(all.pose_source, PoseSource::kCorrected);
  ASSERT_EQ(all.poses.size(), 20u);
  EXPECT_EQ(all.poses[0].x, all.log.scans[0].corrected_pose->x);
  EXPECT_EQ(all.keypoints.size(), 20u);

  // SLAM estimates its own poses: none are computed, the keypoints are the same.
  options.compute_poses = false;
  const LogInputs no_poses = PrepareLogInputs(path, options);
  EXPECT_TRUE(no_poses.poses.empty());
  EXPECT_EQ(no_poses.seconds_poses, 0.0);
  ASSERT_EQ(no_poses.keypoints.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(no_poses.keypoints[i].size(), all.keypoints[i].size()) << i;
  }
  options.keypoints = false;
  EXPECT_TRUE(PrepareLogInputs(path, options).keypoints.empty());
}

}  // namespace
}  // namespace keyplace
