// EmbedAmongDistractors (the scale benchmark's maps): the map untouched, copies of real submaps
// far away, ids and scan indices that no evaluation rule can relate to the map.

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/distractor_map.hpp"

namespace keyplace {
namespace {

// `count` submaps along x from `x0_m`, ids from `first_id`, two scans and two keypoints each.
GlobalMap Corridor(int count, double x0_m, int first_id, int first_scan) {
  GlobalMap map;
  for (int k = 0; k < count; ++k) {
    Submap submap;
    submap.id = first_id + k;
    const double x_m = x0_m + 4.0 * k;
    // push_back: GCC 12 warns (-Wnonnull, falsely) on assigning an initializer list here.
    submap.scan_indices.push_back(first_scan + 2 * k);
    submap.scan_indices.push_back(first_scan + 2 * k + 1);
    submap.poses = {Pose2(x_m, 1.0, 0.3 * k), Pose2(x_m + 1.0, 1.5, 0.3 * k + 0.1)};
    for (int j = 0; j < 2; ++j) {
      StableKeypoint keypoint;
      keypoint.position_m = Eigen::Vector2d(0.5 * j, 2.0 - j);
      keypoint.scan_index = submap.scan_indices[j];
      keypoint.descriptor.fill(static_cast<float>(k + j));
      submap.keypoints.push_back(keypoint);
    }
    submap.occupancy.cell_size_m = 0.1;
    submap.occupancy.cells = {Eigen::Vector2i(3, -4)};
    map.submaps.push_back(submap);
  }
  return map;
}

std::vector<Eigen::Vector2d> WorldPoints(const Submap& submap) {
  std::vector<Eigen::Vector2d> points;
  for (const Pose2& pose : submap.poses) points.push_back(pose.translation());
  for (const StableKeypoint& k : submap.keypoints) points.push_back(submap.origin() * k.position_m);
  return points;
}

double Distance(const Submap& a, const Submap& b) {
  double closest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : WorldPoints(a)) {
    for (const Eigen::Vector2d& q : WorldPoints(b)) closest = std::min(closest, (p - q).norm());
  }
  return closest;
}

bool SamePose(const Pose2& a, const Pose2& b) {
  return std::abs(a.x - b.x) < 1e-9 && std::abs(a.y - b.y) < 1e-9 &&
         std::abs(WrapAngle(a.theta - b.theta)) < 1e-12;
}

TEST(EmbedAmongDistractors, KeepsTheMapAndFillsUpWithMovedCopies) {
  const GlobalMap map = Corridor(3, 0.0, 0, 100);
  const std::vector<GlobalMap> sources = {Corridor(4, 50.0, 7, 0), Corridor(2, -20.0, 0, 5)};
  DistractorOptions options;
  options.total_submaps = 3 + 4 + 2 + 4 + 1;  // the last copy cut after one submap
  options.margin_m = 25.0;
  const GlobalMap embedded = EmbedAmongDistractors(map, sources, options);
  ASSERT_EQ(embedded.submaps.size(), options.total_submaps);
  for (std::size_t i = 0; i < map.submaps.size(); ++i) {
    EXPECT_EQ(embedded.submaps[i].id, map.submaps[i].id);
    EXPECT_EQ(embedded.submaps[i].scan_indices, map.submaps[i].scan_indices);
    EXPECT_TRUE(SamePose(embedded.submaps[i].origin(), map.submaps[i].origin()));
  }
  // Copies in turn: source 0, source 1, source 0, then the first submap of source 1.
  const std::vector<std::pair<int, int>> origin = {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 0}, {1, 1},
                                                   {0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 0}};
  std::set<int> ids;
  std::set<int> scans;
  for (const Submap& submap : embedded.submaps) ids.insert(submap.id);
  EXPECT_EQ(ids.size(), embedded.submaps.size());
  for (std::size_t k = 0; k < origin.size(); ++k) {
    const Submap& copy = embedded.submaps[3 + k];
    const Submap& real = sources[origin[k].first].submaps[origin[k].second];
    ASSERT_EQ(copy.keypoints.size(), real.keypoints.size());
    for (std::size_t j = 0; j < real.keypoints.size(); ++j) {
      EXPECT_EQ(copy.keypoints[j].descriptor, real.keypoints[j].descriptor);
      EXPECT_EQ(copy.keypoints[j].position_m, real.keypoints[j].position_m);
    }
    EXPECT_EQ(copy.occupancy.cells, real.occupancy.cells);
    EXPECT_TRUE(
        SamePose(Between(copy.poses[0], copy.poses[1]), Between(real.poses[0], real.poses[1])));
    for (const int scan : copy.scan_indices) {
      EXPECT_GT(scan, 101 + 2 * 2);  // past the map's last scan
      EXPECT_TRUE(scans.insert(scan).second) << "scan " << scan << " used twice";
    }
    // Each keypoint keeps naming the scan it was detected in.
    for (std::size_t j = 0; j < real.keypoints.size(); ++j) {
      EXPECT_EQ(copy.keypoints[j].scan_index, copy.scan_indices[j]) << "copy " << k;
    }
    for (const Submap& own : map.submaps) EXPECT_GE(Distance(copy, own), 25.0) << "copy " << k;
  }
  // No two submaps of different copies come closer than the margin.
  for (std::size_t a = 0; a < origin.size(); ++a) {
    for (std::size_t b = a + 1; b < origin.size(); ++b) {
      const Submap& first = embedded.submaps[3 + a];
      const Submap& second = embedded.submaps[3 + b];
      const bool same_copy = origin[b].first == origin[a].first &&
                             origin[b].second - origin[a].second == static_cast<int>(b - a);
      if (!same_copy) {
        EXPECT_GE(Distance(first, second), 25.0) << a << " " << b;
      }
    }
  }
  // Within a copy the map neighbours stay neighbours (same relative pose, consecutive ids) ...
  for (std::size_t k = 1; k < origin.size(); ++k) {
    const Submap& before = embedded.submaps[2 + k];
    const Submap& copy = embedded.submaps[3 + k];
    const bool same_copy = origin[k].second == origin[k - 1].second + 1;
    EXPECT_EQ(copy.id == before.id + 1, same_copy) << "copy submap " << k;
    if (same_copy) {
      const Submap& real_before = sources[origin[k - 1].first].submaps[origin[k - 1].second];
      const Submap& real = sources[origin[k].first].submaps[origin[k].second];
      EXPECT_TRUE(SamePose(Between(before.origin(), copy.origin()),
                           Between(real_before.origin(), real.origin())));
    } else {
      // ... and two copies lie margin_m apart.
      EXPECT_GE(Distance(before, copy), 25.0) << "copy submap " << k;
    }
  }
}

TEST(EmbedAmongDistractors, ScansStartPastTheLogsTheyAreComparedWith) {
  // A time split: the map holds scans 0..5 of a file whose queries are its scans 6..999.
  const GlobalMap map = Corridor(3, 0.0, 0, 0);
  DistractorOptions options;
  options.total_submaps = 6;
  options.first_scan = 1000;
  const GlobalMap embedded = EmbedAmongDistractors(map, {Corridor(3, 0.0, 0, 0)}, options);
  ASSERT_EQ(embedded.submaps.size(), 6U);
  EXPECT_EQ(embedded.submaps[3].scan_indices.front(), 1000);
  for (std::size_t i = 3; i < embedded.submaps.size(); ++i) {
    for (const int scan : embedded.submaps[i].scan_indices) EXPECT_GE(scan, 1000);
    for (const StableKeypoint& k : embedded.submaps[i].keypoints) EXPECT_GE(k.scan_index, 1000);
  }
}

TEST(EmbedAmongDistractors, SeedDrawsTheHeadingsAndRepeats) {
  const GlobalMap map = Corridor(2, 0.0, 0, 0);
  const std::vector<GlobalMap> sources = {Corridor(2, 0.0, 0, 0)};
  DistractorOptions options;
  options.total_submaps = 8;
  const GlobalMap a = EmbedAmongDistractors(map, sources, options);
  const GlobalMap b = EmbedAmongDistractors(map, sources, options);
  options.seed = 2;
  const GlobalMap c = EmbedAmongDistractors(map, sources, options);
  bool any_different = false;
  for (std::size_t i = 2; i < a.submaps.size(); ++i) {
    EXPECT_TRUE(SamePose(a.submaps[i].origin(), b.submaps[i].origin()));
    any_different = any_different || !SamePose(a.submaps[i].origin(), c.submaps[i].origin());
  }
  EXPECT_TRUE(any_different);
}

TEST(EmbedAmongDistractors, NothingToAddAndBadOptions) {
  const GlobalMap map = Corridor(3, 0.0, 0, 0);
  DistractorOptions options;
  options.total_submaps = 2;
  EXPECT_EQ(EmbedAmongDistractors(map, {}, options).submaps.size(), 3U);
  options.total_submaps = 5;
  EXPECT_THROW(EmbedAmongDistractors(map, {GlobalMap{}}, options), std::invalid_argument);
  options.margin_m = -1.0;
  EXPECT_THROW(EmbedAmongDistractors(map, {Corridor(1, 0.0, 0, 0)}, options),
               std::invalid_argument);
  options.margin_m = std::nan("");
  EXPECT_THROW(EmbedAmongDistractors(map, {Corridor(1, 0.0, 0, 0)}, options),
               std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
