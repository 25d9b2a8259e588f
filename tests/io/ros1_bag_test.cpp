// The ROS 1 bag reader on the real bags of ../shared/data: fr079.orig.bag against the CARMEN log
// rebuilt from it (fr079-raw.log.gz), fr-clinic.orig.bag, and damaged copies of fr079.

#include "keyplace/io/ros1_bag.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/io/carmen_log.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string Fr079Bag() { return testing::SharedFile("data/fr079.orig.bag"); }

// The settings that reproduce fr079-raw.log.gz (shared/data/README.md): the log's laser offset
// (the bag's /tf_static has the opposite sign) and its beam spacing (pi/360; the bag says pi/359).
BagInputConfig Fr079AsLog() {
  BagInputConfig config;
  config.laser_pose = "-0.04,0,0";
  config.scan_fov_rad = M_PI;
  return config;
}

const CarmenLog& Fr079FromBag() {
  static const CarmenLog log = ReadRos1Bag(Fr079Bag(), Fr079AsLog());
  return log;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string WriteBytes(const std::string& name, const std::string& bytes) {
  std::string path = testing::MakeTempDir("ros1bag") + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

CarmenReadOptions Reading(const BagInputConfig& config) {
  CarmenReadOptions options;
  options.bag = config;
  return options;
}

std::string ErrorOf(const std::string& path, const BagInputConfig& config) {
  try {
    ReadCarmenLog(path, Reading(config));
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "no error";
}

using testing::ExpectContains;

long Microseconds(double stamp_s) { return std::lround(stamp_s * 1e6); }

TEST(Ros1Bag, Fr079GivesTheScansAndOdometryOfTheLogRebuiltFromIt) {
  const CarmenLog& bag = Fr079FromBag();
  const CarmenLog log = ReadCarmenLog(testing::SharedFile("data/fr079-raw.log.gz"));
  EXPECT_EQ(bag.format, "ROS 1 bag");
  ASSERT_EQ(bag.scans.size(), 4934u);
  ASSERT_EQ(log.scans.size(), bag.scans.size());
  std::size_t beams = 0;
  for (std::size_t k = 0; k < bag.scans.size(); ++k) {
    const LogScan& b = bag.scans[k];
    const LogScan& l = log.scans[k];
    ASSERT_EQ(Microseconds(b.timestamp_s), Microseconds(l.timestamp_s)) << "scan " << k;
    ASSERT_EQ(b.size(), l.size()) << "scan " << k;
    for (std::size_t i = 0; i < b.size(); ++i, ++beams) {
      ASSERT_EQ(static_cast<float>(b.ranges_m[i]), static_cast<float>(l.ranges_m[i]));
      // The shortest decimal of the float32 is what the log's text holds: the same double.
      ASSERT_EQ(b.ranges_m[i], l.ranges_m[i]) << "scan " << k << " beam " << i;
      ASSERT_EQ(b.angles_rad[i], l.angles_rad[i]) << "scan " << k << " beam " << i;
      ASSERT_EQ(b.valid[i], l.valid[i]) << "scan " << k << " beam " << i;
    }
    const Pose2& bo = *b.odometry_pose;
    const Pose2& lo = *l.odometry_pose;
    ASSERT_NEAR(bo.x, lo.x, 1e-6) << "scan " << k;
    ASSERT_NEAR(bo.y, lo.y, 1e-6) << "scan " << k;
    ASSERT_NEAR(WrapAngle(bo.theta - lo.theta), 0.0, 1e-6) << "scan " << k;
    ASSERT_NEAR(b.logged_laser_pose.x, l.logged_laser_pose.x, 1e-6) << "scan " << k;
    ASSERT_NEAR(b.logged_laser_pose.y, l.logged_laser_pose.y, 1e-6) << "scan " << k;
    ASSERT_EQ(b.max_range_m, l.max_range_m);
  }
  EXPECT_EQ(beams, 4934u * 360u);
  EXPECT_EQ(bag.invalid_beams, log.invalid_beams);
  EXPECT_EQ(bag.no_return_beams, log.no_return_beams);
  // The log's ODOM lines are the /odom messages (6 decimals).
  ASSERT_EQ(bag.odometry.size(), log.odometry.size());
  for (std::size_t k = 0; k < bag.odometry.size(); ++k) {
    ASSERT_NEAR(bag.odometry[k].pose.x, log.odometry[k].pose.x, 1e-6);
    ASSERT_EQ(Microseconds(bag.odometry[k].timestamp_s), Microseconds(log.odometry[k].timestamp_s));
  }
}

TEST(Ros1Bag, Fr079ListsItsTopicsAndTakesTheLaserPoseFromTfStatic) {
  const CarmenLog bag = ReadRos1Bag(Fr079Bag());
  ASSERT_EQ(bag.topics.size(), 4u);
  const std::pair<const char*, std::size_t> expected[] = {
      {"/odom", 8951}, {"/scan", 4934}, {"/tf", 8951}, {"/tf_static", 1}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(bag.topics[i].name, expected[i].first);
    EXPECT_EQ(bag.topics[i].messages, expected[i].second);
  }
  EXPECT_EQ(bag.topics[1].type, "sensor_msgs/LaserScan");
  // /tf_static: base_link -> laser at x = +0.04 m (the converter's sign; README).
  EXPECT_NEAR(bag.scans.at(0).T_robot_laser.x, 0.04, 1e-9);
  EXPECT_NEAR(bag.scans.at(0).T_robot_laser.y, 0.0, 1e-9);
  // Without the override the beams are where the messages put them: -pi/2 + i pi/359.
  EXPECT_NEAR(bag.scans[0].angles_rad.front(), -M_PI / 2, 1e-6);
  EXPECT_NEAR(bag.scans[0].angles_rad.back(), M_PI / 2, 1e-6);
  // The first scan precedes the first /odom message by 10 ms: held, and said so.
  ASSERT_FALSE(bag.warnings.empty());
  ExpectContains(bag.warnings.back(), "1 of 4934 scans lie before the first or after the last");
}

TEST(Ros1Bag, FrClinicReads) {
  const CarmenLog bag = ReadCarmenLog(testing::SharedFile("data/fr-clinic.orig.bag"));
  ASSERT_EQ(bag.scans.size(), 6917u);
  EXPECT_NEAR(bag.scans[0].T_robot_laser.x, 0.22, 1e-9);
  for (const LogScan& scan : bag.scans) ASSERT_TRUE(scan.odometry_pose.has_value());
  // Its 198 s odometry gap is reported.
  ASSERT_FALSE(bag.warnings.empty());
  ExpectContains(bag.warnings.back(), "scans lie in odometry gaps over 1.000 s");
}

TEST(Ros1Bag, ContentDecidesNotTheName) {
  const std::string renamed = WriteBytes("fr079.log.gz", ReadBytes(Fr079Bag()));
  EXPECT_EQ(ReadCarmenLogWithScans(renamed).scans.size(), 4934u);
}

TEST(Ros1Bag, AMissingScanTopicListsTheTopics) {
  BagInputConfig config;
  config.scan_topic = "/base_scan";
  const std::string error = ErrorOf(Fr079Bag(), config);
  ExpectContains(error, Fr079Bag());
  ExpectContains(error, "no topic /base_scan");
  // The scan topics first, as the flag that reads the first of them.
  ExpectContains(error, "sensor_msgs/LaserScan on /scan (--scan-topic /scan)");
  ExpectContains(error, "/scan (sensor_msgs/LaserScan, 4934)");
  ExpectContains(error, "/odom (nav_msgs/Odometry, 8951)");
}

TEST(Ros1Bag, AMessageOfTheWrongTypeOnTheTopicIsNamed) {
  BagInputConfig config;
  config.scan_topic = "/odom";
  const std::string error = ErrorOf(Fr079Bag(), config);
  ExpectContains(error, Fr079Bag());
  ExpectContains(error, "topic /odom holds nav_msgs/Odometry messages, not sensor_msgs/LaserScan");
}

TEST(Ros1Bag, ATruncatedBagIsReadUpToItsLastCompleteChunk) {
  const std::string bytes = ReadBytes(Fr079Bag());
  const std::string cut = WriteBytes("cut.bag", bytes.substr(0, bytes.size() * 6 / 10));
  const CarmenLog log = ReadCarmenLog(cut, Reading(Fr079AsLog()));
  const CarmenLog& whole = Fr079FromBag();
  ASSERT_GT(log.scans.size(), 1000u);
  ASSERT_LT(log.scans.size(), whole.scans.size());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    ASSERT_EQ(log.scans[k].timestamp_s, whole.scans[k].timestamp_s) << "scan " << k;
    ASSERT_EQ(log.scans[k].ranges_m, whole.scans[k].ranges_m) << "scan " << k;
  }
  ASSERT_FALSE(log.warnings.empty());
  ExpectContains(log.warnings.front(), cut + ": the bag's index is missing or damaged");
  ExpectContains(log.warnings.front(), "of the 20 it announces");
  ExpectContains(log.warnings.front(), "dropped an incomplete record at byte");
}

TEST(Ros1Bag, ABagCutBeforeItsFirstChunkEndsIsAnError) {
  const std::string cut = WriteBytes("stub.bag", ReadBytes(Fr079Bag()).substr(0, 6000));
  const std::string error = ErrorOf(cut, {});
  ExpectContains(error, cut + ": no complete chunk");
  ExpectContains(error, "nor can its index be read: record at byte 4117: its data run past");
}

// A cut bag's chunk claiming 512 MiB uncompressed from 95 kB of bz2 is refused before anything
// that large is allocated (laser data do not compress 1000-fold).
TEST(Ros1Bag, AChunkClaimingAnImplausibleSizeIsRefused) {
  std::string bytes = ReadBytes(Fr079Bag()).substr(0, 150000);
  const auto size_field = bytes.find("size=", bytes.find("compression=bz2"));
  ASSERT_NE(size_field, std::string::npos);
  bytes.replace(size_field + 5, 4, std::string("\0\0\0\x20", 4));
  const std::string path = WriteBytes("huge.bag", bytes);
  const std::string error = ErrorOf(path, {});
  ExpectContains(error, path + ": chunk at byte 4117: uncompressed size 536870912 from ");
}

TEST(Ros1Bag, AnUnknownCompressionIsNamed) {
  std::string bytes = ReadBytes(Fr079Bag());
  std::size_t patched = 0;
  for (auto at = bytes.find("compression=bz2"); at != std::string::npos;
       at = bytes.find("compression=bz2", at + 1)) {
    bytes.replace(at, 15, "compression=zst");
    ++patched;
  }
  ASSERT_EQ(patched, 20u);
  const std::string path = WriteBytes("zst.bag", bytes);
  const std::string error = ErrorOf(path, {});
  ExpectContains(error, path + ": topic /");
  ExpectContains(error, "zst");
}

// The position of the byte `at` bytes into the first index entry of the `n`th (from 0) index data
// record of fr079.orig.bag: header fields are written in name order, "ver" last, then the data
// length, then the entries (uint32 sec, nsec, offset in the chunk's records).
std::size_t IndexEntryByte(const std::string& bytes, int n, std::size_t at) {
  std::size_t op = bytes.find(std::string("op=\x04", 4));
  for (int i = 0; i < n; ++i) op = bytes.find(std::string("op=\x04", 4), op + 1);
  const std::size_t ver = bytes.find("ver=", op);
  EXPECT_NE(op, std::string::npos);
  EXPECT_EQ(ver, op + 8);  // "op=\x04", then the length of "ver=..."
  return ver + 8 + 4 + at;
}

std::uint32_t U32At(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = value << 8 | static_cast<std::uint8_t>(bytes[at + i]);
  return value;
}

void SetU32At(std::string& bytes, std::size_t at, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>(value >> (8 * i) & 0xFF);
}

// rosbag reads a message where the index says, without checking (the fuzzer's finding: a header
// parsed beyond the chunk's buffer). The first index data record is /tf_static's, one entry at
// byte 2235 of the first chunk (at byte 4117); one byte further is inside that message.
TEST(Ros1Bag, AnIndexEntryOffTheStartOfAMessageIsRefused) {
  std::string bytes = ReadBytes(Fr079Bag());
  const std::size_t offset = IndexEntryByte(bytes, 0, 8);
  ASSERT_EQ(U32At(bytes, offset), 2235u);
  SetU32At(bytes, offset, 2236);
  const std::string path = WriteBytes("entry-off-start.bag", bytes);
  ExpectContains(ErrorOf(path, {}), path +
                                        ": index entry for topic /tf_static points at byte 2236 "
                                        "of the chunk at byte 4117, which is not where a message "
                                        "record starts");
}

// The /tf_static entry pointed at the first /scan message (the next record's first entry).
TEST(Ros1Bag, AnIndexEntryAtAnotherTopicsMessageIsRefused) {
  std::string bytes = ReadBytes(Fr079Bag());
  const std::uint32_t scan_offset = U32At(bytes, IndexEntryByte(bytes, 1, 8));
  SetU32At(bytes, IndexEntryByte(bytes, 0, 8), scan_offset);
  const std::string path = WriteBytes("entry-at-scan.bag", bytes);
  ExpectContains(ErrorOf(path, {}), path + ": index entry for topic /tf_static points at byte " +
                                        std::to_string(scan_offset) +
                                        " of the chunk at byte 4117, a message of topic /scan");
}

// rosbag would make a ros::Time of 2^32 - 1 s and 2 s in nanoseconds, which throws a
// std::runtime_error while it opens the bag.
TEST(Ros1Bag, AnIndexEntryWithNanosecondsPastOneSecondIsRefused) {
  std::string bytes = ReadBytes(Fr079Bag());
  SetU32At(bytes, IndexEntryByte(bytes, 0, 0), 0xFFFFFFFFU);
  SetU32At(bytes, IndexEntryByte(bytes, 0, 4), 2000000000U);
  const std::string path = WriteBytes("entry-nsec.bag", bytes);
  ExpectContains(ErrorOf(path, {}), path +
                                        ": index entry for topic /tf_static has a time of "
                                        "4294967295 s and 2000000000 ns");
}

// An index that is not where the bag header says is no index: the chunks are read without it, as
// for a recording cut off before its index was written.
TEST(Ros1Bag, AnIndexPositionWhereNoRecordStartsIsReadWithoutTheIndex) {
  std::string bytes = ReadBytes(Fr079Bag());
  const std::size_t index_pos = bytes.find("index_pos=") + 10;
  SetU32At(bytes, index_pos, U32At(bytes, index_pos) + 1);
  const std::string path = WriteBytes("index-pos.bag", bytes);
  const CarmenLog log = ReadCarmenLog(path, Reading(Fr079AsLog()));
  EXPECT_EQ(log.scans.size(), 4934u);
  ASSERT_FALSE(log.warnings.empty());
  ExpectContains(log.warnings.front(), path + ": the bag's index is missing or damaged");
}

// Issue 31: a bag header counting 0 chunks (chunk_count=0) made the index hold no chunk, and the
// bag read as "the bag has no topics". The header disagrees with the file: its chunks are walked,
// with the warning of a damaged index.
TEST(Ros1Bag, AChunkCountOtherThanTheFilesIsADamagedIndex) {
  std::string bytes = ReadBytes(Fr079Bag());
  const std::size_t chunk_count = bytes.find("chunk_count=") + 12;
  ASSERT_EQ(U32At(bytes, chunk_count), 20u);
  SetU32At(bytes, chunk_count, 0);
  const std::string path = WriteBytes("chunk-count-0.bag", bytes);
  const CarmenLog log = ReadCarmenLog(path, Reading(Fr079AsLog()));
  EXPECT_EQ(log.scans.size(), 4934u);
  ASSERT_FALSE(log.warnings.empty());
  ExpectContains(log.warnings.front(), path + ": the bag's index is missing or damaged");
}

// The fuzzer's input (tests/fuzz/regressions/ros1_bag/): rosbag's written bag of a /tf_static, a
// /tf and a /scan message with an index entry pointing near the end of the chunk; rosbag read a
// header beyond the chunk's buffer (AddressSanitizer: heap-buffer-overflow in ros::Header::parse).
TEST(Ros1Bag, TheFuzzersIndexOffsetInputIsRefusedNamingTheBag) {
  const std::string path = testing::SourceDir() +
                           "/tests/fuzz/regressions/ros1_bag/rosbag-index-offset-heap-overflow.bag";
  const std::string error = ErrorOf(path, {});
  ExpectContains(error, path + ": index entry for topic ");
  ExpectContains(error, "which is not where a message record starts");
}

// The fuzzer's second input: a cut bag (read by the chunk walk) whose first /scan message has a
// ranges length of 1.9 G floats; ros::serialization resized the vector to it (7.8 GB) before
// finding the message too short.
TEST(Ros1Bag, TheFuzzersScanLengthInputIsRefusedNamingTheBag) {
  const std::string path =
      testing::SourceDir() + "/tests/fuzz/regressions/ros1_bag/laserscan-ranges-length-7.8-gb.bag";
  ExpectContains(ErrorOf(path, {}), path +
                                        ": topic /scan: message 1 is damaged (a string or array "
                                        "runs past the message's end)");
}

}  // namespace
}  // namespace keyplace
