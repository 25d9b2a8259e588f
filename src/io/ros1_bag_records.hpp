#pragma once
// Internal: the record layout of a ROS 1 bag (format 2.0), shared by the read through the bag's
// index (ros1_bag_index.cpp) and the walk over its chunks without it (ros1_bag_chunks.cpp).
// A record is a uint32 header length, header fields "name=value" each prefixed by its uint32
// length, a uint32 data length and the data. Chunks (op 5) hold connection (op 7) and message
// (op 2) records, compressed as their "compression" field says.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace keyplace {

inline constexpr char kRos1BagMagic[] = "#ROSBAG V2.0\n";
inline constexpr std::size_t kRos1BagMagicBytes = sizeof(kRos1BagMagic) - 1;

inline constexpr std::uint8_t kOpMessage = 0x02;
inline constexpr std::uint8_t kOpBagHeader = 0x03;
inline constexpr std::uint8_t kOpIndexData = 0x04;
inline constexpr std::uint8_t kOpChunk = 0x05;
inline constexpr std::uint8_t kOpChunkInfo = 0x06;
inline constexpr std::uint8_t kOpConnection = 0x07;

using BagFields = std::map<std::string, std::string>;

/// A connection (op 7): the topic and the message type it carries.
struct BagConnection {
  std::string topic;
  std::string datatype;
  std::string md5sum;
};

std::uint32_t ReadU32(const std::uint8_t* bytes);
std::uint64_t ReadU64(const std::uint8_t* bytes);

/// Header fields; nothing when a field's length runs past the header or a field has no '='.
std::optional<BagFields> ParseFields(const std::uint8_t* bytes, std::size_t size);

/// A 4- or 8-byte little-endian field; nothing when it is missing or of another size.
std::optional<std::uint32_t> FieldU32(const BagFields& fields, const std::string& name);
std::optional<std::uint64_t> FieldU64(const BagFields& fields, const std::string& name);

/// The record's op code; nothing unless its "op" field is one byte.
std::optional<std::uint8_t> FieldOp(const BagFields& fields);

/// The records of a chunk, decompressed as its header `fields` say; `data` is the chunk record's
/// data. Throws std::invalid_argument "SOURCE: chunk at byte OFFSET: why" (`source` names the bag)
/// when the compression is unknown, the size implausible (chunk_limits.hpp) or the data do not
/// decompress to that size.
std::vector<std::uint8_t> DecompressChunk(const std::string& source, const BagFields& fields,
                                          std::vector<std::uint8_t> data, std::uint64_t offset);

/// One record inside a decompressed chunk: where it starts, its header, its data.
struct ChunkRecord {
  std::size_t start = 0;
  const BagFields& fields;
  std::uint8_t op = 0;
  const std::uint8_t* data = nullptr;
  std::uint32_t size = 0;
};

/// Calls `visit` for every record of `chunk` in order, up to the first one that runs past the
/// chunk's end or whose header is damaged: where record starts lie beyond that is unknown. Returns
/// what stopped the walk there ("its record at byte N runs past its end"); nothing when
/// every record was visited.
std::optional<std::string> ForEachChunkRecord(const std::vector<std::uint8_t>& chunk,
                                              const std::function<void(const ChunkRecord&)>& visit);

}  // namespace keyplace
