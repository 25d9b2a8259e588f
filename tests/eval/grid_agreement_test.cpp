// The grid check of `keyplace slam --grid --truth`: a grid agrees with itself wherever it is put,
// through the right transform, and a grid shifted by more than the tolerance does not.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/grid_agreement.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

// The grid of the bundled log's first 300 scans at their corrected poses, moved by T_new_world.
OccupancyGrid BundledGrid(const Pose2& T_new_world) {
  static const CarmenLog log = ReadCarmenLog(testing::SourceDir() + "/data/fr079-corrected.log.gz");
  std::vector<const LaserScan*> scans;
  std::vector<Pose2> poses;
  for (std::size_t i = 0; i < 300; ++i) {
    scans.push_back(&log.scans[i]);
    poses.push_back(T_new_world * *log.scans[i].corrected_pose);
  }
  return BuildOccupancyGrid(scans, poses, OccupancyGridConfig{});
}

TEST(GridAgreement, AGridMovedAndMovedBackAgreesAShiftedOneDoesNot) {
  const OccupancyGridConfig config;
  const OccupancyGrid reference = BundledGrid(Pose2());
  const GridAgreement self = CompareOccupancyGrids(reference, reference, Pose2(), config, 0.1);
  EXPECT_GT(self.occupied, 1000U);
  EXPECT_EQ(self.occupied, self.occupied_reference);
  EXPECT_DOUBLE_EQ(self.occupied_matched, 1.0);
  EXPECT_DOUBLE_EQ(self.reference_matched, 1.0);
  EXPECT_DOUBLE_EQ(self.occupied_on_free, 0.0);
  // The same scans in another frame (a SLAM run starts wherever it starts): through the right
  // transform they agree up to the cells' re-quantisation.
  const Pose2 T_slam_world(-7.3, 12.1, 2.2);
  const OccupancyGrid moved = BundledGrid(T_slam_world);
  const GridAgreement right =
      CompareOccupancyGrids(moved, reference, T_slam_world.inverse(), config, 0.1);
  EXPECT_GT(right.occupied_matched, 0.97);
  EXPECT_GT(right.reference_matched, 0.97);
  EXPECT_LT(right.occupied_on_free, 0.01);
  // Through a transform 0.5 m off, most walls miss and many land on free cells.
  const GridAgreement wrong = CompareOccupancyGrids(
      moved, reference, Pose2(0.5, 0.0, 0.0) * T_slam_world.inverse(), config, 0.1);
  EXPECT_LT(wrong.occupied_matched, 0.6);
  EXPECT_GT(wrong.occupied_on_free, 0.1);
}

}  // namespace
}  // namespace keyplace
