// PrepareLogInputs on the bundled corrected log, cut to a range of its scans, and MapLog's
// file-absolute scan indices.

#include "keyplace/mapping/scan_sources.hpp"

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/mapping/global_mapper.hpp"

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

// A map of scans 100:200 names scans of the file, so that queries from another part of the same
// log meet the self-match rule with the same numbers (time-split protocol).
TEST(MapLog, ScanIndicesAreThoseOfTheFile) {
  const std::string path = testing::SourceDir() + "/data/fr079-corrected.log.gz";
  LogInputOptions options;
  options.first_scan = 100;
  options.end_scan = 200;
  const LogInputs inputs = PrepareLogInputs(path, options);
  ASSERT_EQ(inputs.first_scan, 100u);
  const LogMap result = MapLog(inputs, MappingConfig{});
  ASSERT_GE(result.map.submaps.size(), 2u);
  // The mapper itself numbers the cut log's scans; the map is the same with the offset added.
  const GlobalMap relative =
      BuildGlobalMap({inputs.log.scans, inputs.poses, inputs.keypoints}, MappingConfig{});
  ASSERT_EQ(relative.submaps.size(), result.map.submaps.size());
  for (std::size_t s = 0; s < result.map.submaps.size(); ++s) {
    const Submap& submap = result.map.submaps[s];
    ASSERT_EQ(submap.scan_indices.size(), relative.submaps[s].scan_indices.size());
    for (std::size_t k = 0; k < submap.scan_indices.size(); ++k) {
      const int index = submap.scan_indices[k];
      EXPECT_GE(index, 100) << "submap " << s;
      EXPECT_LT(index, 200) << "submap " << s;
      EXPECT_EQ(index, relative.submaps[s].scan_indices[k] + 100);
      // Each pose still belongs to its scan: the corrected pose of that scan of the file.
      EXPECT_EQ(submap.poses[k].x, inputs.log.scans[index - 100].corrected_pose->x);
    }
    for (const StableKeypoint& keypoint : submap.keypoints) {
      EXPECT_TRUE(std::find(submap.scan_indices.begin(), submap.scan_indices.end(),
                            keypoint.scan_index) != submap.scan_indices.end())
          << "keypoint of scan " << keypoint.scan_index << " in submap " << s;
    }
  }
  EXPECT_EQ(result.map.submaps.front().first_scan(), 100);

  // No cut: the indices the mapper gives, unchanged.
  options.first_scan = 0;
  options.end_scan = 60;
  const LogInputs head = PrepareLogInputs(path, options);
  const LogMap head_map = MapLog(head, MappingConfig{});
  const GlobalMap head_relative =
      BuildGlobalMap({head.log.scans, head.poses, head.keypoints}, MappingConfig{});
  ASSERT_EQ(head_map.map.submaps.size(), head_relative.submaps.size());
  for (std::size_t s = 0; s < head_map.map.submaps.size(); ++s) {
    EXPECT_EQ(head_map.map.submaps[s].scan_indices, head_relative.submaps[s].scan_indices);
  }
}

}  // namespace
}  // namespace keyplace
