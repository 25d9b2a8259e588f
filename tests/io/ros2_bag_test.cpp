// The ROS 2 bag reader on fixtures written by other projects' writers (tests/io/ros2/
// generate_fixtures.mjs: @mcap/core, @foxglove/rosmsg2-serialization, sql.js) from the first 150
// scans of fr079-raw.log.gz, committed beside that slice in tests/data/ros2/: every storage and
// chunk compression gives the slice's scans, stamps and odometry; damaged and wrong bags give
// errors naming the bag, the topic or file, and the problem.

#include "keyplace/io/ros2_bag.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "io/ros2_cdr.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

namespace fs = std::filesystem;

std::string Fixture(const std::string& name) {
  return testing::SourceDir() + "/tests/data/ros2/" + name;
}

const CarmenLog& SourceSlice() {
  static const CarmenLog log = ReadCarmenLog(Fixture("fr079-raw-first150.log.gz"));
  return log;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// A copy of a fixture directory, to damage.
std::string CopyFixture(const std::string& name) {
  std::string copy = testing::MakeTempDir("ros2bag") + "/" + name;
  fs::copy(Fixture(name), copy, fs::copy_options::recursive);
  return copy;
}

std::string ErrorOf(const std::string& path, const BagInputConfig& config = {}) {
  try {
    ReadRos2Bag(path, config);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "no error";
}

using testing::ExpectContains;

void Replace(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

class Ros2Fixture : public ::testing::TestWithParam<const char*> {};

// The CARMEN line and the bag message hold the same decimal numbers: ranges (2 decimals, exact
// as float32 and back), stamps (sec.nsec of the same decimal). The log's FLASER odometry is the
// original /odom interpolated at the scan stamp and printed with 6 decimals, the bag's the ODOM
// lines (6 decimals) interpolated by keyplace: they agree to the rounding, 2e-6. The bag's beam
// angles are float32 (angle_min -pi/2, increment pi/360): within 1e-6 rad of the log's doubles.
TEST_P(Ros2Fixture, GivesTheScansStampsAndOdometryOfItsSourceSlice) {
  const CarmenLog& source = SourceSlice();
  const CarmenLog bag = ReadCarmenLog(Fixture(GetParam()));
  EXPECT_EQ(bag.format, "ROS 2 bag");
  ASSERT_EQ(source.scans.size(), 150u);
  ASSERT_EQ(bag.scans.size(), source.scans.size());
  for (std::size_t k = 0; k < bag.scans.size(); ++k) {
    const LogScan& want = source.scans[k];
    const LogScan& got = bag.scans[k];
    SCOPED_TRACE("scan " + std::to_string(k));
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got.ranges_m[i], want.ranges_m[i]);
      ASSERT_EQ(static_cast<float>(got.ranges_m[i]), static_cast<float>(want.ranges_m[i]));
      ASSERT_NEAR(got.angles_rad[i], want.angles_rad[i], 1e-6);
      ASSERT_EQ(got.valid[i], want.valid[i]) << "beam " << i;
    }
    EXPECT_EQ(got.timestamp_s, want.timestamp_s);
    EXPECT_EQ(got.logger_timestamp_s, want.logger_timestamp_s);
    EXPECT_NEAR(got.odometry_pose->x, want.odometry_pose->x, 2e-6);
    EXPECT_NEAR(got.odometry_pose->y, want.odometry_pose->y, 2e-6);
    EXPECT_NEAR(WrapAngle(got.odometry_pose->theta - want.odometry_pose->theta), 0.0, 2e-6);
    EXPECT_NEAR(got.logged_laser_pose.x, want.logged_laser_pose.x, 2e-6);
    EXPECT_NEAR(got.logged_laser_pose.y, want.logged_laser_pose.y, 2e-6);
    EXPECT_EQ(got.T_robot_laser.x, -0.04);
    EXPECT_EQ(got.T_robot_laser.theta, 0.0);
  }
  // The odometry samples are the ODOM lines, through a quaternion and back.
  ASSERT_EQ(bag.odometry.size(), source.odometry.size());
  for (std::size_t k = 0; k < bag.odometry.size(); ++k) {
    EXPECT_EQ(bag.odometry[k].timestamp_s, source.odometry[k].timestamp_s);
    EXPECT_NEAR(bag.odometry[k].pose.x, source.odometry[k].pose.x, 1e-12);
    EXPECT_NEAR(WrapAngle(bag.odometry[k].pose.theta - source.odometry[k].pose.theta), 0.0, 1e-12);
  }
  EXPECT_EQ(bag.invalid_beams + bag.no_return_beams, source.invalid_beams + source.no_return_beams);
}

// With the CARMEN spread over pi, the angles are the log's exactly.
TEST_P(Ros2Fixture, TheFieldOfViewOptionGivesTheLogsAnglesExactly) {
  BagInputConfig config;
  config.scan_fov_rad = M_PI;
  const CarmenLog bag = ReadRos2Bag(Fixture(GetParam()), config);
  EXPECT_EQ(bag.scans.at(7).angles_rad, SourceSlice().scans.at(7).angles_rad);
}

INSTANTIATE_TEST_SUITE_P(Storages, Ros2Fixture,
                         ::testing::Values("mcap-none", "mcap-zstd", "mcap-lz4", "sqlite3",
                                           "mcap-tf"));

TEST(Ros2Bag, EveryStorageAndCompressionReadsTheSame) {
  const CarmenLog reference = ReadRos2Bag(Fixture("mcap-none"));
  for (const char* name : {"mcap-zstd", "mcap-lz4", "sqlite3", "mcap-tf"}) {
    SCOPED_TRACE(name);
    const CarmenLog log = ReadRos2Bag(Fixture(name));
    ASSERT_EQ(log.scans.size(), reference.scans.size());
    for (std::size_t k = 0; k < log.scans.size(); ++k) {
      EXPECT_EQ(log.scans[k].ranges_m, reference.scans[k].ranges_m);
      EXPECT_EQ(log.scans[k].angles_rad, reference.scans[k].angles_rad);
      EXPECT_EQ(log.scans[k].odometry_pose->x, reference.scans[k].odometry_pose->x);
      EXPECT_EQ(log.scans[k].odometry_pose->theta, reference.scans[k].odometry_pose->theta);
      EXPECT_EQ(log.scans[k].logger_timestamp_s, reference.scans[k].logger_timestamp_s);
    }
  }
}

TEST(Ros2Bag, ListsTopicsTypesAndCounts) {
  const CarmenLog log = ReadRos2Bag(Fixture("sqlite3"));
  ASSERT_EQ(log.topics.size(), 3u);
  EXPECT_EQ(log.topics[0].name, "/odom");
  EXPECT_EQ(log.topics[0].type, "nav_msgs/msg/Odometry");
  EXPECT_EQ(log.topics[0].messages, SourceSlice().odometry.size());
  EXPECT_EQ(log.topics[1].name, "/scan");
  EXPECT_EQ(log.topics[1].messages, 150u);
  EXPECT_EQ(log.topics[2].name, "/tf_static");
  EXPECT_EQ(log.topics[2].type, "tf2_msgs/msg/TFMessage");
  EXPECT_EQ(log.lines, SourceSlice().odometry.size() + 151);
  const CarmenLog tf = ReadRos2Bag(Fixture("mcap-tf"));
  EXPECT_EQ(tf.topics[1].name, "/tf");
  ExpectContains(tf.warnings.at(0), Fixture("mcap-tf") + ": no topic /odom: odometry from /tf");
}

TEST(Ros2Bag, TheMetadataFileOrOneStorageFileReadsAsTheDirectory) {
  const CarmenLog whole = ReadRos2Bag(Fixture("mcap-lz4"));
  for (const std::string& path :
       {Fixture("mcap-lz4/metadata.yaml"), Fixture("mcap-lz4/mcap-lz4_0.mcap")}) {
    EXPECT_TRUE(IsRos2Bag(path)) << path;
    const CarmenLog log = ReadCarmenLog(path);
    ASSERT_EQ(log.scans.size(), whole.scans.size());
    EXPECT_EQ(log.scans.back().ranges_m, whole.scans.back().ranges_m);
  }
  const std::string db3 = Fixture("sqlite3/sqlite3_0.db3");
  EXPECT_TRUE(IsRos2Bag(db3));
  EXPECT_EQ(ReadCarmenLog(db3).scans.size(), 150u);
  EXPECT_FALSE(IsRos2Bag(Fixture("fr079-raw-first150.log.gz")));
}

TEST(Ros2Bag, AMissingScanTopicListsTheBagsTopics) {
  BagInputConfig config;
  config.scan_topic = "/base_scan";
  const std::string error = ErrorOf(Fixture("mcap-zstd"), config);
  ExpectContains(error, Fixture("mcap-zstd") + ": no topic /base_scan (input.scan_topic");
  ExpectContains(error, "sensor_msgs/msg/LaserScan on /scan (--scan-topic /scan)");
  ExpectContains(error, "/scan (sensor_msgs/msg/LaserScan, 150)");
}

TEST(Ros2Bag, AMessageOfAnotherTypeOnTheScanTopicIsAnErrorNamingBoth) {
  BagInputConfig config;
  config.scan_topic = "/odom";
  ExpectContains(ErrorOf(Fixture("sqlite3"), config),
                 Fixture("sqlite3") + ": topic /odom holds nav_msgs/msg/Odometry messages, not " +
                     "sensor_msgs/msg/LaserScan");
}

TEST(Ros2Bag, NoOdometryIsAnErrorNamingTopicAndFrames) {
  BagInputConfig config;
  config.odom_topic = "/wheel_odom";
  const std::string error = ErrorOf(Fixture("mcap-none"), config);
  ExpectContains(error, Fixture("mcap-none") + ": no odometry: no topic /wheel_odom");
  ExpectContains(error, "transform chain odom -> base_link");
}

TEST(Ros2Bag, NoLaserPoseIsAnErrorSuggestingTheOption) {
  BagInputConfig config;
  config.base_frame = "base_footprint";
  const std::string error = ErrorOf(Fixture("mcap-none"), config);
  ExpectContains(error, Fixture("mcap-none") + ": no transform base_footprint -> laser");
  ExpectContains(error, "on /scan");
  ExpectContains(error, "--laser-pose x,y,theta");
  config.laser_pose = "0.1,0,0";
  EXPECT_EQ(ReadRos2Bag(Fixture("mcap-none"), config).scans.at(0).T_robot_laser.x, 0.1);
}

TEST(Ros2Bag, ADirectoryWithoutMetadataIsAnError) {
  const std::string folder = testing::MakeTempDir("ros2empty");
  EXPECT_TRUE(IsRos2Bag(folder));
  ExpectContains(ErrorOf(folder), folder + ": a directory without metadata.yaml");
  // Through ReadCarmenLog too: a directory is never a CARMEN log.
  EXPECT_THROW(ReadCarmenLog(folder), std::invalid_argument);
}

TEST(Ros2Bag, AnUnknownStorageOrBagCompressionIsAnError) {
  const std::string bag = CopyFixture("mcap-zstd");
  const std::string metadata = bag + "/metadata.yaml";
  const std::string original = ReadBytes(metadata);
  std::string text = original;
  Replace(text, "storage_identifier: mcap", "storage_identifier: rosbags");
  WriteBytes(metadata, text);
  ExpectContains(ErrorOf(bag), metadata + ": unknown storage 'rosbags'");
  text = original;
  Replace(text, "compression_format: \"\"", "compression_format: zstd");
  Replace(text, "compression_mode: \"\"", "compression_mode: FILE");
  WriteBytes(metadata, text);
  ExpectContains(ErrorOf(bag), metadata + ": compression 'zstd' (mode FILE) is unknown");
}

TEST(Ros2Bag, AnUnknownChunkCompressionNamesTheFileAndChunk) {
  const std::string bag = CopyFixture("mcap-zstd");
  const std::string file = bag + "/mcap-zstd_0.mcap";
  std::string bytes = ReadBytes(file);
  Replace(bytes, std::string("\x04\0\0\0zstd", 8), std::string("\x04\0\0\0brot", 8));
  WriteBytes(file, bytes);
  const std::string error = ErrorOf(bag);
  ExpectContains(error, file + ": record at byte ");
  ExpectContains(error, "unknown compression 'brot' (known: none, lz4, zstd)");
}

TEST(Ros2Bag, AChunkFailingItsCrcIsAnError) {
  const std::string bag = CopyFixture("mcap-none");
  const std::string file = bag + "/mcap-none_0.mcap";
  std::string bytes = ReadBytes(file);
  bytes[bytes.size() / 3] = static_cast<char>(bytes[bytes.size() / 3] ^ 0x10);
  WriteBytes(file, bytes);
  ExpectContains(ErrorOf(bag), file + ": record at byte ");
  ExpectContains(ErrorOf(bag), "fail their CRC");
}

TEST(Ros2Bag, ACutMcapIsReadUpToItsLastCompleteChunkWithAWarning) {
  const CarmenLog whole = ReadRos2Bag(Fixture("mcap-lz4"));
  const std::string bytes = ReadBytes(Fixture("mcap-lz4/mcap-lz4_0.mcap"));
  const std::string cut = testing::MakeTempDir("ros2cut") + "/cut.mcap";
  const std::size_t kept_bytes = bytes.size() * 3 / 5;
  WriteBytes(cut, bytes.substr(0, kept_bytes));
  const CarmenLog log = ReadCarmenLog(cut);
  ASSERT_GT(log.scans.size(), 10u);
  ASSERT_LT(log.scans.size(), whole.scans.size());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    EXPECT_EQ(log.scans[k].ranges_m, whole.scans[k].ranges_m);
  }
  ASSERT_FALSE(log.warnings.empty());
  // The storage's warning comes first, then the held odometry at the end of the cut.
  ExpectContains(log.warnings.front(), cut + ": cut off at byte ");
  ExpectContains(log.warnings.front(), " of " + std::to_string(kept_bytes) + " (a recording");
  // Cut inside the first chunk: nothing to read.
  WriteBytes(cut, bytes.substr(0, 600));
  ExpectContains(ErrorOf(cut), cut + ": cut off at byte ");
  ExpectContains(ErrorOf(cut), "before its first complete message");
}

TEST(Ros2Bag, ADamagedMessageNamesTopicAndNumber) {
  const std::string bag = CopyFixture("sqlite3");
  const std::string file = bag + "/sqlite3_0.db3";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  // The third scan loses its beams: its ranges sequence runs past the message's end.
  const char* cut =
      "UPDATE messages SET data = substr(data, 1, 80) WHERE id = (SELECT id FROM messages "
      "WHERE topic_id = (SELECT id FROM topics WHERE name = '/scan') ORDER BY timestamp "
      "LIMIT 1 OFFSET 2)";
  ASSERT_EQ(sqlite3_exec(db, cut, nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  const std::string error = ErrorOf(bag);
  ExpectContains(error, bag + ": topic /scan: message 3 is damaged (byte ");
  ExpectContains(error, "runs past the message's end");
}

TEST(Ros2Bag, AnSqliteFileWithoutRosbag2TablesIsAnError) {
  const std::string file = testing::MakeTempDir("ros2sqlite") + "/other.db3";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE topics(id INTEGER)", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  ExpectContains(ErrorOf(file), file + ": not a rosbag2 sqlite3 file: it lacks the tables");
}

// A database file made by `sql`, as a hostile or damaged bag might be.
std::string SqliteFileOf(const std::string& name, const char* sql) {
  const std::string file = testing::MakeTempDir("ros2sqlite") + "/" + name;
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);
  return file;
}

constexpr const char* kTopicsTable =
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
    "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
    "INSERT INTO topics VALUES (1, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr', '');";

// An endless recursive view in place of the messages table: reading it would never end (and
// fill the temp directory sorting it). It must be refused without being run.
TEST(Ros2Bag, MessagesAsAnEndlessViewIsRefusedUnrun) {
  const std::string sql =
      std::string(kTopicsTable) +
      "CREATE VIEW messages AS WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n) "
      "SELECT i AS id, 1 AS topic_id, i AS timestamp, zeroblob(1000) AS data FROM n "
      "ORDER BY i DESC;";
  const std::string file = SqliteFileOf("view.db3", sql.c_str());
  ExpectContains(ErrorOf(file), file +
                                    ": not a rosbag2 sqlite3 file: 'messages' is a view, not an "
                                    "ordinary table (a hostile or damaged file, not read further)");
}

// A generated data column would make every blob whatever the file says, e.g. 200 MB of zeros.
TEST(Ros2Bag, AGeneratedDataColumnIsRefused) {
  const std::string sql =
      std::string(kTopicsTable) +
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp "
      "INTEGER NOT NULL, data BLOB GENERATED ALWAYS AS (zeroblob(200000000)) VIRTUAL);"
      "INSERT INTO messages (topic_id, timestamp) VALUES (1, 5);";
  const std::string file = SqliteFileOf("generated.db3", sql.c_str());
  ExpectContains(ErrorOf(file), file +
                                    ": not a rosbag2 sqlite3 file: column messages.data is hidden "
                                    "or generated, not stored");
}

// A recording cut short: the header counts more pages than the file holds.
TEST(Ros2Bag, ACutSqliteFileIsAnErrorSayingSo) {
  const std::string bag = CopyFixture("sqlite3");
  const std::string file = bag + "/sqlite3_0.db3";
  std::filesystem::resize_file(file, 300000);
  ExpectContains(ErrorOf(bag), file +
                                   ": cut off at byte 300000: its SQLite header counts 129 "
                                   "pages of 4096 bytes (528384 bytes)");
}

// Two rows whose blobs share one chain of overflow pages read without any SQLite error and cost
// no SQLite steps: a hostile file could make every small row as long as the file. quick_check
// finds the shared page before any row is read.
TEST(Ros2Bag, RowsSharingPagesAreRefusedBeforeAnyIsRead) {
  const std::string sql =
      std::string("PRAGMA page_size = 512;") + kTopicsTable +
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp "
      "INTEGER NOT NULL, data BLOB NOT NULL);"
      "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, 5, "
      "CAST(replace(hex(zeroblob(5057)), '00', 'A') AS BLOB)), (1, 6, "
      "CAST(replace(hex(zeroblob(5057)), '00', 'B') AS BLOB));";
  const std::string file = SqliteFileOf("shared.db3", sql.c_str());
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // Each row keeps a few bytes of its blob in its cell, followed by the number of its first
  // overflow page (big-endian); the overflow pages hold runs of ~500 bytes.
  const auto first_overflow_page = [&](char marker) {
    std::size_t run_start = std::string::npos;
    for (std::size_t k = 0; k < bytes.size(); ++k) {
      if (bytes[k] == marker) {
        if (run_start == std::string::npos) run_start = k;
      } else if (run_start != std::string::npos) {
        const std::size_t run = k - run_start;
        if (run >= 20 && run < 100) return k;  // the cell's local part ends here
        run_start = std::string::npos;
      }
    }
    ADD_FAILURE() << "no cell of the '" << marker << "' row found";
    return std::size_t{0};
  };
  const std::size_t pointer_a = first_overflow_page('A');
  const std::size_t pointer_b = first_overflow_page('B');
  ASSERT_NE(pointer_a, pointer_b);
  bytes.replace(pointer_b, 4, bytes.substr(pointer_a, 4));  // B's blob is now A's chain
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  ExpectContains(ErrorOf(file), file + ": damaged sqlite3 file: SQLite's quick_check says '");
}

TEST(Ros2Bag, MessagesWithoutAnIdPrimaryKeyAreRefused) {
  const std::string sql =
      std::string(kTopicsTable) +
      "CREATE TABLE messages(id INTEGER, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
      "data BLOB NOT NULL);";
  const std::string file = SqliteFileOf("no-key.db3", sql.c_str());
  ExpectContains(ErrorOf(file), file +
                                    ": not a rosbag2 sqlite3 file: messages.id is not the "
                                    "table's primary key");
}

// rosbag2's resilient storage preset writes in write-ahead-log mode: after a crash the messages
// since the last checkpoint are only in FILE-wal, which an immutable read would silently drop.
TEST(Ros2Bag, AWriteAheadLogBesideTheBagIsAnErrorSayingHowToMergeIt) {
  const std::string bag = CopyFixture("sqlite3");
  const std::string file = bag + "/sqlite3_0.db3";
  const std::string copy = testing::MakeTempDir("ros2wal") + "/crashed.db3";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "PRAGMA journal_mode = WAL; PRAGMA wal_autocheckpoint = 0; "
                         "UPDATE messages SET timestamp = timestamp + 1 WHERE id = 1;",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  // Copied while the writer is still open: the state a crash leaves.
  fs::copy_file(file, copy);
  fs::copy_file(file + "-wal", copy + "-wal");
  sqlite3_close(db);
  ASSERT_GT(fs::file_size(copy + "-wal"), 0U);
  ExpectContains(ErrorOf(copy), copy + ": its write-ahead log " + copy +
                                    "-wal holds messages not yet in the file");
}

// rosbag2 plays messages by (timestamp, id), whatever order the rows were written in.
TEST(Ros2Bag, MessagesAreReadInStampOrderWhateverTheRowOrder) {
  const std::string bag = CopyFixture("sqlite3");
  const std::string file = bag + "/sqlite3_0.db3";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  // The rows in reverse: ids counted down, so the file order is against the time order.
  ASSERT_EQ(sqlite3_exec(db,
                         "CREATE TABLE reversed AS SELECT * FROM messages ORDER BY timestamp "
                         "DESC, id DESC; DELETE FROM messages; INSERT INTO messages (topic_id, "
                         "timestamp, data) SELECT topic_id, timestamp, data FROM reversed; DROP "
                         "TABLE reversed; VACUUM;",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const CarmenLog original = ReadRos2Bag(Fixture("sqlite3"));
  const CarmenLog reversed = ReadRos2Bag(bag);
  ASSERT_EQ(reversed.scans.size(), original.scans.size());
  for (std::size_t k = 0; k < original.scans.size(); ++k) {
    EXPECT_EQ(reversed.scans[k].timestamp_s, original.scans[k].timestamp_s) << k;
    EXPECT_EQ(reversed.scans[k].ranges_m, original.scans[k].ranges_m) << k;
    EXPECT_EQ(reversed.scans[k].odometry_pose->x, original.scans[k].odometry_pose->x) << k;
  }
  ASSERT_EQ(reversed.odometry.size(), original.odometry.size());
  for (std::size_t k = 0; k < original.odometry.size(); ++k) {
    EXPECT_EQ(reversed.odometry[k].timestamp_s, original.odometry[k].timestamp_s) << k;
  }
}

// The same LaserScan in both byte orders (the fuzz seeds: one written by
// @foxglove/rosmsg2-serialization, its fields byte-swapped by hand into the big-endian one).
TEST(Ros2Cdr, BigAndLittleEndianMessagesDecodeAlike) {
  const std::string seeds = testing::SourceDir() + "/tests/fuzz/corpus/ros2_cdr/";
  const std::string little = ReadBytes(seeds + "LaserScan.cdr");
  const std::string big = ReadBytes(seeds + "LaserScan-big-endian.cdr");
  ASSERT_EQ(big[1], 0);
  ASSERT_EQ(little[1], 1);
  const auto decode = [](const std::string& bytes) {
    return DecodeRos2LaserScan(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  };
  const ScanFields a = decode(little);
  const ScanFields b = decode(big);
  EXPECT_EQ(a.frame_id, "laser");
  EXPECT_EQ(b.frame_id, "laser");
  EXPECT_EQ(a.stamp.sec, b.stamp.sec);
  EXPECT_EQ(a.stamp.nsec, b.stamp.nsec);
  EXPECT_EQ(a.angle_increment, b.angle_increment);
  EXPECT_EQ(a.range_max, 80.0F);
  ASSERT_EQ(a.ranges.size(), 24u);
  EXPECT_EQ(a.ranges, b.ranges);
  EXPECT_EQ(a.ranges[0], 1.67F);  // fr079-raw.log.gz's first beam
  // Cut anywhere, the message is an error naming the byte, never a read past its end.
  for (std::size_t size = 0; size < little.size(); ++size) {
    EXPECT_THROW(decode(little.substr(0, size)), CdrError) << size;
  }
}

// Issue 31: one storage file listed 2000 times made a 450 KB bag read as 300 000 scans.
TEST(Ros2Bag, AStorageFileListedTwiceIsRefused) {
  const std::string bag = CopyFixture("mcap-none");
  const std::string metadata = bag + "/metadata.yaml";
  std::string text = ReadBytes(metadata);
  Replace(text, "    - mcap-none_0.mcap\n  files:",
          "    - mcap-none_0.mcap\n    - ./mcap-none_0.mcap\n  files:");
  WriteBytes(metadata, text);
  ExpectContains(ErrorOf(bag), metadata +
                                   ": lists the storage file ./mcap-none_0.mcap more than "
                                   "once (relative_file_paths)");
}

// Issue 31: a metadata.yaml was read whole whatever its size (/dev/zero: until memory ran out);
// duplicate keys resolved to one of their values, a second document was ignored.
TEST(Ros2Bag, MetadataIsReadUpToItsLimitAndAsOneDocumentWithoutDuplicateKeys) {
  const std::string bag = CopyFixture("mcap-none");
  const std::string metadata = bag + "/metadata.yaml";
  const std::string original = ReadBytes(metadata);
  fs::remove(metadata);
  fs::create_symlink("/dev/zero", metadata);
  try {  // std::runtime_error, as for a metadata file that cannot be opened
    ReadRos2Bag(metadata);
    FAIL() << "/dev/zero read as metadata";
  } catch (const std::runtime_error& error) {
    ExpectContains(error.what(),
                   metadata + ": larger than 16 MiB, the limit of a rosbag2 metadata file");
  }
  fs::remove(metadata);
  std::string text = original;
  Replace(text, "  storage_identifier: mcap\n",
          "  storage_identifier: mcap\n  storage_identifier: sqlite3\n");
  WriteBytes(metadata, text);
  ExpectContains(ErrorOf(bag), metadata + ":4: the key 'storage_identifier' is given twice");
  WriteBytes(metadata, original + "---\n" + original);
  ExpectContains(ErrorOf(bag), "a second YAML document");
}

// Sets the float32 field of every /scan message of an sqlite3 bag at `field` (0 angle_min,
// 1 angle_max, 2 angle_increment), after the CDR header, stamp and frame id.
void SetScanAngleField(const std::string& db3, int field, float value) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db3.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* rows = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db,
                               "SELECT id, data FROM messages WHERE topic_id = (SELECT id FROM "
                               "topics WHERE name = '/scan')",
                               -1, &rows, nullptr),
            SQLITE_OK);
  std::vector<std::pair<sqlite3_int64, std::string>> changed;
  ASSERT_EQ(sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr), SQLITE_OK);
  while (sqlite3_step(rows) == SQLITE_ROW) {
    std::string data(static_cast<const char*>(sqlite3_column_blob(rows, 1)),
                     static_cast<std::size_t>(sqlite3_column_bytes(rows, 1)));
    std::uint32_t frame_bytes = 0;  // little-endian CDR (the fixtures' encoding)
    std::memcpy(&frame_bytes, data.data() + 12, 4);
    // The payload starts after the 4-byte encapsulation header; floats align to 4 within it.
    std::size_t at = 16 + frame_bytes;
    at = 4 + ((at - 4 + 3) / 4) * 4 + 4 * static_cast<std::size_t>(field);
    std::memcpy(data.data() + at, &value, 4);
    changed.emplace_back(sqlite3_column_int64(rows, 0), std::move(data));
  }
  sqlite3_finalize(rows);
  ASSERT_FALSE(changed.empty());
  for (const auto& [id, data] : changed) {
    sqlite3_stmt* update = nullptr;
    ASSERT_EQ(
        sqlite3_prepare_v2(db, "UPDATE messages SET data = ? WHERE id = ?", -1, &update, nullptr),
        SQLITE_OK);
    sqlite3_bind_blob(update, 1, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    sqlite3_bind_int64(update, 2, id);
    ASSERT_EQ(sqlite3_step(update), SQLITE_DONE);
    sqlite3_finalize(update);
  }
  ASSERT_EQ(sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
}

// Issue 31: angle_increment 0 or 1e30 and angle_min 1e30 ("field of view 2.06e34 deg") mapped with
// exit 0; the bounds are those of the CARMEN reader's ROBOTLASER1 angles.
TEST(Ros2Bag, ScanAnglesBeyondOneTurnAreRefused) {
  const struct {
    int field;
    float value;
    const char* expected;
  } cases[] = {
      {2, 0.0F, ": topic /scan: scan 1: angle_increment = 0 rad over 360 beams"},
      {2, 1e30F, ": topic /scan: scan 1: angle_increment = 1e+30 rad over 360 beams"},
      {2, 0.0175F * 1.02F, "does not spread them over at most one turn"},
      {0, 1e30F, ": topic /scan: scan 1: angle_min = 1e+30 rad"},
      {0, -7.0F, "is not an angle in [-2 pi, 2 pi]"},
  };
  for (const auto& bad : cases) {
    SCOPED_TRACE(bad.expected);
    const std::string bag = CopyFixture("sqlite3");
    SetScanAngleField(bag + "/sqlite3_0.db3", bad.field, bad.value);
    ExpectContains(ErrorOf(bag), bad.expected);
  }
  // A scan turning the other way (negative increment) within one turn still reads.
  const std::string bag = CopyFixture("sqlite3");
  SetScanAngleField(bag + "/sqlite3_0.db3", 2, -0.0174F);
  EXPECT_EQ(ReadRos2Bag(bag).scans.size(), 150u);
}

// Issue 31: an MCAP channel with schema_id 0 ("no schema") was shown with an empty type.
TEST(Ros2Bag, AChannelWithoutSchemaIsShownAsSuch) {
  const std::string bag = CopyFixture("mcap-none");
  const std::string file = bag + "/mcap-none_0.mcap";
  std::string bytes = ReadBytes(file);
  // The first chunk (at byte 59) holds the /scan channel; its CRC (0 = unchecked) is cleared.
  ASSERT_EQ(bytes[59], '\x06');
  std::memset(bytes.data() + 59 + 9 + 24, 0, 4);
  const std::size_t topic = bytes.find(std::string("\x05\x00\x00\x00/scan", 9));
  ASSERT_NE(topic, std::string::npos);
  std::memset(bytes.data() + topic - 2, 0, 2);  // schema_id, after the channel id
  WriteBytes(file, bytes);
  ExpectContains(ErrorOf(bag), bag +
                                   ": topic /scan holds <no schema: schema_id 0> messages, not "
                                   "sensor_msgs/msg/LaserScan");
}

// Issue 31: text in messages.timestamp read as 0 (SQLite converts what it is asked to).
TEST(Ros2Bag, ATimestampThatIsNoIntegerIsRefused) {
  const std::string bag = CopyFixture("sqlite3");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((bag + "/sqlite3_0.db3").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "UPDATE messages SET timestamp = 'noon' WHERE id = (SELECT min(id) FROM "
                         "messages)",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  ExpectContains(ErrorOf(bag), ": messages.timestamp is text, not an integer (nanoseconds)");
}

}  // namespace
}  // namespace keyplace
