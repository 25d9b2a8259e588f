#pragma once
// Internal: the messages of one rosbag2 storage file as bytes, for ReadRos2Bag: an MCAP file
// (own reader: records, chunks uncompressed, lz4 or zstd; the summary is not needed) or an sqlite3
// file (tables topics and messages).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace keyplace {

/// A topic of a storage file (its messages may be spread over several files of a bag).
struct StorageTopic {
  std::string name;
  std::string type;           // "sensor_msgs/msg/LaserScan"; empty when the file does not say
  std::string serialization;  // "cdr"
};

/// One serialized message and the topic it belongs to.
struct StorageMessage {
  const StorageTopic& topic;
  std::uint64_t log_time_ns = 0;  // the recorder's time
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

using StorageVisitor = std::function<void(const StorageMessage&)>;

/// What reading a file found besides the messages.
struct StorageWalk {
  std::vector<StorageTopic> topics;   // every topic the file declares
  std::vector<std::string> warnings;  // what was dropped, naming the file and byte
  bool time_ordered = false;          // messages were visited in log time order
};

/// The 8 bytes an MCAP file starts (and ends) with.
inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

/// Whether the file starts with the MCAP magic bytes.
bool StartsWithMcapMagic(const std::string& path);

/// Every message of the MCAP file at `path` in file order. A file cut off (no Data End or
/// Footer record, or a record running past the end) is read up to its last complete record or
/// chunk, with a warning naming the file and the byte. Throws std::invalid_argument naming the
/// file (and the chunk's byte) for a file that is not MCAP, a chunk with an unknown compression
/// or one that does not decompress or fails its CRC, a message of an undeclared channel, or a
/// file cut before its first message.
StorageWalk ReadMcapMessages(const std::string& path, const StorageVisitor& visitor);

/// Every message of the rosbag2 sqlite3 file at `path`, in timestamp order, opened read-only.
/// Throws std::invalid_argument naming the file for a database without rosbag2's tables or
/// columns, a damaged database, or a message larger than 256 MiB.
StorageWalk ReadSqliteMessages(const std::string& path, const StorageVisitor& visitor);

}  // namespace keyplace
