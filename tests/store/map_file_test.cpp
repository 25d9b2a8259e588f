#include "keyplace/store/map_file.hpp"

#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

GlobalMap RandomMap(int submaps, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-20.0, 20.0);
  GlobalMap map;
  map.source_log = "fr079-corrected.log.gz";
  map.source_hash = "crc32:0badf00d:1234";
  map.pose_source = "corrected";
  map.source_scans = 1464;
  map.source_keypoints = 35000;
  map.config.min_stability = 0.35;
  map.config.overlap_cells = MappingConfig::OverlapCells::kObserved;
  for (int s = 0; s < submaps; ++s) {
    Submap submap;
    submap.id = s;
    submap.overlap = 0.7 + 0.001 * s;
    submap.distribution = 0.4 + 1e-17 * s;
    submap.forced = s % 3 == 0;
    for (int k = 0; k < 5 + s % 4; ++k) {
      submap.scan_indices.push_back(10 * s + k);
      submap.poses.emplace_back(uniform(rng), uniform(rng), uniform(rng) / 7.0);
    }
    for (int k = 0; k < 12 + s; ++k) {
      StableKeypoint keypoint;
      keypoint.position_m = {uniform(rng), uniform(rng)};
      keypoint.orientation_rad = uniform(rng) / 7.0;
      keypoint.scale_m = 0.4 * (1 + k % 5);
      keypoint.scale_level = k % 5;
      keypoint.scan_index = 10 * s + k % 5;
      keypoint.stability = static_cast<float>(uniform(rng));
      keypoint.occurrences = k;
      for (auto& bin : keypoint.descriptor) bin = static_cast<float>(uniform(rng));
      submap.keypoints.push_back(keypoint);
    }
    submap.occupancy.cell_size_m = 0.1;
    for (int k = 0; k < 200; ++k) submap.occupancy.cells.emplace_back(k - 100, 3 * k + s);
    map.submaps.push_back(submap);
  }
  return map;
}

void ExpectSameMap(const GlobalMap& a, const GlobalMap& b) {
  EXPECT_EQ(a.source_log, b.source_log);
  EXPECT_EQ(a.source_hash, b.source_hash);
  EXPECT_EQ(a.pose_source, b.pose_source);
  EXPECT_EQ(a.source_scans, b.source_scans);
  EXPECT_EQ(a.source_keypoints, b.source_keypoints);
  EXPECT_EQ(ToKeyValues(a.config), ToKeyValues(b.config));
  ASSERT_EQ(a.submaps.size(), b.submaps.size());
  for (std::size_t s = 0; s < a.submaps.size(); ++s) {
    const Submap& x = a.submaps[s];
    const Submap& y = b.submaps[s];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.overlap, y.overlap);
    EXPECT_EQ(x.distribution, y.distribution);
    EXPECT_EQ(x.forced, y.forced);
    EXPECT_EQ(x.scan_indices, y.scan_indices);
    ASSERT_EQ(x.poses.size(), y.poses.size());
    for (std::size_t k = 0; k < x.poses.size(); ++k) {
      EXPECT_EQ(x.poses[k].x, y.poses[k].x);
      EXPECT_EQ(x.poses[k].y, y.poses[k].y);
      EXPECT_EQ(x.poses[k].theta, y.poses[k].theta);
    }
    ASSERT_EQ(x.keypoints.size(), y.keypoints.size());
    for (std::size_t k = 0; k < x.keypoints.size(); ++k) {
      const auto& p = x.keypoints[k];
      const auto& q = y.keypoints[k];
      EXPECT_EQ(p.position_m, q.position_m);
      EXPECT_EQ(p.orientation_rad, q.orientation_rad);
      EXPECT_EQ(p.scale_m, q.scale_m);
      EXPECT_EQ(p.scale_level, q.scale_level);
      EXPECT_EQ(p.scan_index, q.scan_index);
      EXPECT_EQ(p.stability, q.stability);
      EXPECT_EQ(p.occurrences, q.occurrences);
      EXPECT_EQ(p.descriptor, q.descriptor);
    }
    EXPECT_EQ(x.occupancy.cell_size_m, y.occupancy.cell_size_m);
    EXPECT_EQ(x.occupancy.cells, y.occupancy.cells);
  }
}

template <typename Function>
std::string ErrorOf(Function&& function) {
  try {
    function();
  } catch (const std::exception& error) {
    return error.what();
  }
  return "";
}

TEST(MapFile, SaveLoadRoundTripIsIdentical) {
  const std::string path = testing::MakeTempDir("mapfile") + "/map.kpm";
  const GlobalMap map = RandomMap(7, 42);
  SaveMap(map, path);
  ExpectSameMap(map, LoadMap(path));
  // Saving again over an existing file replaces it.
  const GlobalMap other = RandomMap(3, 7);
  SaveMap(other, path);
  ExpectSameMap(other, LoadMap(path));
}

TEST(MapFile, EmptyMapRoundTrips) {
  const std::string path = testing::MakeTempDir("mapfile") + "/empty.kpm";
  GlobalMap map;
  map.source_log = "x";
  SaveMap(map, path);
  ExpectSameMap(map, LoadMap(path));
}

TEST(MapFile, GarbageFileIsRejectedWithItsPath) {
  const std::string path = testing::MakeTempDir("mapfile") + "/garbage.kpm";
  std::ofstream(path) << "this is not a database, just text\n";
  const std::string message = ErrorOf([&] { LoadMap(path); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("not a keyplace map"), std::string::npos) << message;
}

TEST(MapFile, TruncatedFileIsRejected) {
  const std::string dir = testing::MakeTempDir("mapfile");
  const std::string path = dir + "/map.kpm";
  SaveMap(RandomMap(40, 3), path);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size / 2);
  const std::string message = ErrorOf([&] { LoadMap(path); });
  EXPECT_FALSE(message.empty()) << "a truncated map loaded without error";
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

TEST(MapFile, OtherSchemaVersionIsRejected) {
  const std::string path = testing::MakeTempDir("mapfile") + "/map.kpm";
  SaveMap(RandomMap(2, 1), path);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE meta SET value = '99' WHERE key = 'schema_version'", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const std::string message = ErrorOf([&] { LoadMap(path); });
  EXPECT_NE(message.find("schema version 99"), std::string::npos) << message;
}

TEST(MapFile, MissingFileAndUnwritablePathAreClearErrors) {
  EXPECT_NE(ErrorOf([] { LoadMap("/nonexistent/map.kpm"); }).find("/nonexistent/map.kpm"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              SaveMap(RandomMap(1, 1), "/nonexistent/dir/map.kpm");
            }).find("/nonexistent/dir/map.kpm"),
            std::string::npos);
}

TEST(MapFile, FailedSaveKeepsTheExistingFile) {
  const std::string path = testing::MakeTempDir("mapfile") + "/map.kpm";
  const GlobalMap good = RandomMap(2, 5);
  SaveMap(good, path);
  GlobalMap bad = RandomMap(2, 6);
  bad.submaps[1].poses.pop_back();  // inconsistent: fewer poses than scans
  EXPECT_THROW(SaveMap(bad, path), std::runtime_error);
  ExpectSameMap(good, LoadMap(path));
  int files = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(path).parent_path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1) << "temporary file left behind";
}

}  // namespace
}  // namespace keyplace
