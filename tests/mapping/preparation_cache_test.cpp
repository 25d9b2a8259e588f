// The preparation cache of PrepareLogInputs: a second run reads the ICP poses and keypoints the
// first one computed, bit for bit; a changed setting or scan range is another entry; a damaged
// entry is named and computed again; a cache directory that cannot be used is an error.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/mapping/scan_sources.hpp"
#include "mapping/preparation_cache.hpp"

#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

namespace fs = std::filesystem;

LogInputOptions CachedIcpOptions(const std::string& cache_dir) {
  LogInputOptions options;
  options.poses = PoseSource::kIcp;
  options.first_scan = 10;
  options.end_scan = 40;
  options.cache_dir = cache_dir;
  return options;
}

template <typename Error, typename Call>
void ExpectThrowContains(const Call& call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one saying '" << fragment << "'";
  } catch (const Error& error) {
    testing::ExpectContains(error.what(), fragment);
  }
}

std::string BundledLog() { return testing::SourceDir() + "/data/fr079-corrected.log.gz"; }

void ExpectSamePreparation(const LogInputs& a, const LogInputs& b) {
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    EXPECT_EQ(a.poses[i].x, b.poses[i].x) << i;
    EXPECT_EQ(a.poses[i].y, b.poses[i].y) << i;
    EXPECT_EQ(a.poses[i].theta, b.poses[i].theta) << i;
  }
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
    ASSERT_EQ(a.keypoints[i].size(), b.keypoints[i].size()) << i;
    for (std::size_t k = 0; k < a.keypoints[i].size(); ++k) {
      const Keypoint& p = a.keypoints[i][k];
      const Keypoint& q = b.keypoints[i][k];
      EXPECT_EQ(p.position_m, q.position_m);
      EXPECT_EQ(p.orientation_rad, q.orientation_rad);
      EXPECT_EQ(p.scale_m, q.scale_m);
      EXPECT_EQ(p.scale_level, q.scale_level);
      EXPECT_EQ(p.beam_index, q.beam_index);
      EXPECT_EQ(p.descriptor, q.descriptor);
    }
  }
}

std::vector<fs::path> Entries(const std::string& dir, const std::string& kind) {
  std::vector<fs::path> entries;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().rfind(kind + "-", 0) == 0) entries.push_back(entry);
  }
  return entries;
}

TEST(PreparationCache, ASecondRunReadsWhatTheFirstComputedBitForBit) {
  const std::string dir = testing::MakeTempDir("prep_cache") + "/cache";
  LogInputOptions uncached = CachedIcpOptions("");
  const LogInputs reference = PrepareLogInputs(BundledLog(), uncached);

  const LogInputs first = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  EXPECT_FALSE(first.poses_from_cache);
  EXPECT_FALSE(first.keypoints_from_cache);
  EXPECT_EQ(Entries(dir, "poses-icp").size(), 1u);
  EXPECT_EQ(Entries(dir, "keypoints").size(), 1u);
  const LogInputs second = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  EXPECT_TRUE(second.poses_from_cache);
  EXPECT_TRUE(second.keypoints_from_cache);
  EXPECT_TRUE(second.cache_warnings.empty());
  ExpectSamePreparation(reference, first);
  ExpectSamePreparation(reference, second);
  ASSERT_GT(second.keypoints[0].size(), 0u);
}

TEST(PreparationCache, AChangedSettingOrScanRangeIsAnotherEntry) {
  const std::string dir = testing::MakeTempDir("prep_cache_key");
  PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));

  LogInputOptions finer = CachedIcpOptions(dir);
  finer.features.min_peak = 0.2;  // more keypoints, same poses
  const LogInputs changed = PrepareLogInputs(BundledLog(), finer);
  EXPECT_TRUE(changed.poses_from_cache);
  EXPECT_FALSE(changed.keypoints_from_cache);
  finer.cache_dir.clear();
  ExpectSamePreparation(PrepareLogInputs(BundledLog(), finer), changed);

  LogInputOptions looser_icp = CachedIcpOptions(dir);
  looser_icp.odometry.icp.max_correspondence_distance_m = 1.0;
  const LogInputs other_icp = PrepareLogInputs(BundledLog(), looser_icp);
  EXPECT_FALSE(other_icp.poses_from_cache);
  EXPECT_TRUE(other_icp.keypoints_from_cache);

  LogInputOptions later = CachedIcpOptions(dir);  // the same number of scans, one later
  later.first_scan = 11;
  later.end_scan = 41;
  const LogInputs shifted = PrepareLogInputs(BundledLog(), later);
  EXPECT_FALSE(shifted.poses_from_cache);
  EXPECT_FALSE(shifted.keypoints_from_cache);

  LogInputOptions shorter = CachedIcpOptions(dir);
  shorter.end_scan = 39;
  const LogInputs cut = PrepareLogInputs(BundledLog(), shorter);
  EXPECT_FALSE(cut.poses_from_cache);
  EXPECT_FALSE(cut.keypoints_from_cache);
  EXPECT_EQ(Entries(dir, "keypoints").size(), 4u);
  EXPECT_EQ(Entries(dir, "poses-icp").size(), 4u);
}

TEST(PreparationCache, ADamagedEntryIsNamedAndComputedAgain) {
  const std::string dir = testing::MakeTempDir("prep_cache_damage");
  const LogInputs reference = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  const fs::path keypoints = Entries(dir, "keypoints").at(0);
  const fs::path poses = Entries(dir, "poses-icp").at(0);
  {  // one descriptor byte changed in place
    std::fstream file(keypoints, std::ios::in | std::ios::out | std::ios::binary);
    const auto middle = static_cast<std::streamoff>(fs::file_size(keypoints) / 2);
    file.seekg(middle);
    const int byte = file.get();
    file.seekp(middle);
    file.put(static_cast<char>(byte ^ 0x5a));
  }
  fs::resize_file(poses, fs::file_size(poses) - 5);  // cut short

  const LogInputs repaired = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  EXPECT_FALSE(repaired.poses_from_cache);
  EXPECT_FALSE(repaired.keypoints_from_cache);
  ASSERT_EQ(repaired.cache_warnings.size(), 2u);
  testing::ExpectContains(repaired.cache_warnings[0], poses.string());
  testing::ExpectContains(repaired.cache_warnings[0], "checksum");
  testing::ExpectContains(repaired.cache_warnings[1], keypoints.string());
  ExpectSamePreparation(reference, repaired);

  const LogInputs again = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  EXPECT_TRUE(again.poses_from_cache);
  EXPECT_TRUE(again.keypoints_from_cache);
  ExpectSamePreparation(reference, again);
}

// The key is kept in the entry: it names the code that computed it (a SHA-256 of the reading,
// FLIRT and ICP sources, made by the build), so that changed code never reads old entries.
TEST(PreparationCache, TheKeyNamesTheCodeTheLogAndTheSettings) {
  const std::string dir = testing::MakeTempDir("prep_cache_code");
  PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  std::ifstream file(Entries(dir, "keypoints").at(0), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const std::size_t code = bytes.find("\ncode ");
  ASSERT_NE(code, std::string::npos);
  const std::string hash = bytes.substr(code + 6, 65);
  EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), 64u) << hash;  // 64 hex digits, then \n
  EXPECT_EQ(hash.back(), '\n');
  testing::ExpectContains(bytes, "log crc32:");
  testing::ExpectContains(bytes, "scans 10:40 of ");
  testing::ExpectContains(bytes, "features.min_peak=4:0.34\n");
}

// An entry path taken by something that is not a cache file: named, computed anyway, and the
// entry that cannot be written is a warning, not a lost run.
TEST(PreparationCache, AnEntryThatIsNotAFileIsNamedAndTheRunGoesOn) {
  const std::string dir = testing::MakeTempDir("prep_cache_not_file");
  const LogInputs reference = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  const fs::path keypoints = Entries(dir, "keypoints").at(0);
  fs::remove(keypoints);
  fs::create_directory(keypoints);
  const LogInputs run = PrepareLogInputs(BundledLog(), CachedIcpOptions(dir));
  EXPECT_TRUE(run.poses_from_cache);
  EXPECT_FALSE(run.keypoints_from_cache);
  ASSERT_EQ(run.cache_warnings.size(), 2u);
  testing::ExpectContains(run.cache_warnings[0], keypoints.string() + ": is not a regular file");
  testing::ExpectContains(run.cache_warnings[1], "not cached");
  ExpectSamePreparation(reference, run);
}

TEST(PreparationCache, AnEntryLargerThanTheLimitIsNotReadAndSaysSo) {
  const std::string dir = testing::MakeTempDir("prep_cache_too_large");
  const std::string path = dir + "/entry.bin";
  mapping_internal::WriteCacheEntry(path, "key", std::string(1000, 'p'));
  const auto size = static_cast<std::uint64_t>(fs::file_size(path));
  const mapping_internal::CacheRead whole = mapping_internal::ReadCacheEntry(path, "key", size);
  ASSERT_TRUE(whole.payload.has_value()) << whole.problem;
  EXPECT_EQ(whole.payload->size(), 1000u);
  const mapping_internal::CacheRead refused =
      mapping_internal::ReadCacheEntry(path, "key", size - 1);
  EXPECT_FALSE(refused.payload.has_value());
  testing::ExpectContains(refused.problem, "holds " + std::to_string(size) +
                                               " bytes, more than the " + std::to_string(size - 1));
}

TEST(PreparationCache, AnEntryOfTheWrongSizeIsRefusedSayingWhat) {
  using mapping_internal::DecodeKeypoints;
  using mapping_internal::DecodePoses;
  using mapping_internal::EncodeKeypoints;
  using mapping_internal::EncodePoses;
  const std::vector<Pose2> poses{{1.0, 2.0, 0.5}, {3.0, 4.0, -0.5}};
  EXPECT_EQ(DecodePoses(EncodePoses(poses), 2)[1].y, 4.0);
  ExpectThrowContains<std::runtime_error>([&] { DecodePoses(EncodePoses(poses), 3); },
                                          "poses for 2 scans, the log has 3");
  std::vector<std::vector<Keypoint>> keypoints(3);
  keypoints[1].resize(2);
  keypoints[1][1].descriptor[47] = 0.25F;
  const std::string payload = EncodeKeypoints(keypoints);
  EXPECT_EQ(DecodeKeypoints(payload, 3)[1][1].descriptor[47], 0.25F);
  ExpectThrowContains<std::runtime_error>([&] { DecodeKeypoints(payload, 2); },
                                          "keypoints for 3 scans, the log has 2");
  ExpectThrowContains<std::runtime_error>(
      [&] { DecodeKeypoints(payload.substr(0, payload.size() - 1), 3); }, "ends inside");
  ExpectThrowContains<std::runtime_error>([&] { DecodeKeypoints(payload + "x", 3); },
                                          "1 bytes after the last item");
}

TEST(PreparationCache, ACacheDirectoryThatCannotBeUsedIsAnErrorNamingIt) {
  const std::string file = testing::MakeTempDir("prep_cache_file") + "/not_a_dir";
  std::ofstream(file) << "x";
  ExpectThrowContains<std::invalid_argument>(
      [&] { PrepareLogInputs(BundledLog(), CachedIcpOptions(file)); }, file);
}

}  // namespace
}  // namespace keyplace
