// VisitBagChunks: a ROS 1 bag (format 2.0) read record by record, for bags rosbag cannot open
// because the index at their end is missing. Record layout (ROS bag format 2.0): uint32 header
// length, header fields "name=value" each prefixed by its uint32 length, uint32 data length,
// data. Chunks (op 5) hold connection (op 7) and message (op 2) records, compressed as the
// chunk's "compression" field says.

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/chunk_limits.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicBytes = sizeof(kMagic) - 1;
constexpr std::uint8_t kOpMessage = 0x02;
constexpr std::uint8_t kOpBagHeader = 0x03;
constexpr std::uint8_t kOpChunk = 0x05;
constexpr std::uint8_t kOpConnection = 0x07;
// A chunk is about 768 KiB by default; a length beyond this is damage, not data.
constexpr std::uint32_t kMaxRecordBytes = 1U << 30;

using Fields = std::map<std::string, std::string>;

std::uint32_t ReadU32(const std::uint8_t* bytes) {
  return static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
         static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
}

// Header fields; nothing when their lengths run past the header.
std::optional<Fields> ParseFields(const std::uint8_t* bytes, std::size_t size) {
  Fields fields;
  std::size_t at = 0;
  while (at < size) {
    if (size - at < 4) return std::nullopt;
    const std::uint32_t length = ReadU32(bytes + at);
    at += 4;
    if (length > size - at) return std::nullopt;
    const std::string field(reinterpret_cast<const char*>(bytes + at), length);
    at += length;
    const auto equals = field.find('=');
    if (equals == std::string::npos) return std::nullopt;
    fields[field.substr(0, equals)] = field.substr(equals + 1);
  }
  return fields;
}

std::uint32_t FieldU32(const Fields& fields, const std::string& name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != 4) return 0;
  return ReadU32(reinterpret_cast<const std::uint8_t*>(it->second.data()));
}

struct Connection {
  std::string topic;
  std::string datatype;
  std::string md5sum;
};

class ChunkWalker {
 public:
  ChunkWalker(const std::string& path, const std::set<std::string>& topics,
              const RawMessageVisitor& visitor)
      : path_(path),
        topics_(topics),
        visitor_(visitor),
        file_(path, std::ios::binary | std::ios::ate) {
    if (!file_) throw std::invalid_argument(path + ": cannot open the bag");
    file_bytes_ = static_cast<std::uint64_t>(file_.tellg());
    file_.seekg(0);
  }

  BagSummary Walk() {
    char magic[kMagicBytes];
    if (!file_.read(magic, kMagicBytes) || std::memcmp(magic, kMagic, kMagicBytes) != 0) {
      throw std::invalid_argument(path_ + ": not a ROS 1 bag (format 2.0)");
    }
    std::uint64_t offset = kMagicBytes;
    std::vector<std::uint8_t> header;
    std::vector<std::uint8_t> data;
    while (true) {
      const std::uint64_t record_offset = offset;
      const ReadResult result = ReadRecord(header, data, offset);
      if (result == ReadResult::kEnd) break;
      if (result == ReadResult::kCut) {
        cut_offset_ = record_offset;
        break;
      }
      const auto fields = ParseFields(header.data(), header.size());
      if (!fields || fields->count("op") == 0 || fields->at("op").size() != 1) {
        cut_offset_ = record_offset;
        damaged_ = true;
        break;
      }
      const auto op = static_cast<std::uint8_t>(fields->at("op")[0]);
      if (op == kOpBagHeader) expected_chunks_ = FieldU32(*fields, "chunk_count");
      if (op == kOpChunk) ReadChunk(*fields, data, record_offset);
    }
    return Summary();
  }

 private:
  enum class ReadResult { kRecord, kEnd, kCut };

  ReadResult ReadRecord(std::vector<std::uint8_t>& header, std::vector<std::uint8_t>& data,
                        std::uint64_t& offset) {
    std::uint8_t length_bytes[4];
    if (!file_.read(reinterpret_cast<char*>(length_bytes), 4)) {
      return file_.gcount() == 0 ? ReadResult::kEnd : ReadResult::kCut;
    }
    // A length beyond the file's end is a cut record: nothing is allocated for it.
    const std::uint32_t header_bytes = ReadU32(length_bytes);
    if (header_bytes > BytesLeft(offset + 4) || !ReadBlock(header, header_bytes)) {
      return ReadResult::kCut;
    }
    if (!file_.read(reinterpret_cast<char*>(length_bytes), 4)) return ReadResult::kCut;
    const std::uint32_t data_bytes = ReadU32(length_bytes);
    if (data_bytes > BytesLeft(offset + 8 + header_bytes) || !ReadBlock(data, data_bytes)) {
      return ReadResult::kCut;
    }
    offset += 8ULL + header_bytes + data_bytes;
    return ReadResult::kRecord;
  }

  std::uint64_t BytesLeft(std::uint64_t offset) const {
    const std::uint64_t left = offset < file_bytes_ ? file_bytes_ - offset : 0;
    return left < kMaxRecordBytes ? left : kMaxRecordBytes;
  }

  bool ReadBlock(std::vector<std::uint8_t>& block, std::uint32_t bytes) {
    block.resize(bytes);
    return bytes == 0 ||
           static_cast<bool>(file_.read(reinterpret_cast<char*>(block.data()), bytes));
  }

  void ReadChunk(const Fields& fields, std::vector<std::uint8_t>& compressed,
                 std::uint64_t offset) {
    const auto compression = fields.find("compression");
    const std::string kind = compression == fields.end() ? "" : compression->second;
    const std::uint32_t size = FieldU32(fields, "size");
    std::vector<std::uint8_t> chunk;
    if (kind == "none") {
      chunk = std::move(compressed);
    } else if (kind == "bz2" || kind == "lz4") {
      if (!PlausibleChunkBytes(size, compressed.size())) {
        FailChunk(offset, "uncompressed size " + std::to_string(size) + " from " +
                              std::to_string(compressed.size()) + " compressed bytes");
      }
      chunk.resize(size);
      unsigned int produced = size;
      auto* in = reinterpret_cast<char*>(compressed.data());
      auto* out = reinterpret_cast<char*>(chunk.data());
      const auto in_bytes = static_cast<unsigned int>(compressed.size());
      const bool ok = kind == "bz2"
                          ? BZ2_bzBuffToBuffDecompress(out, &produced, in, in_bytes, 0, 0) == BZ_OK
                          : roslz4_buffToBuffDecompress(in, in_bytes, out, &produced) == 0;
      if (!ok || produced != size) FailChunk(offset, kind + " data do not decompress");
    } else {
      FailChunk(offset, "unknown compression '" + kind + "' (known: none, bz2, lz4)");
    }
    WalkChunk(chunk, offset);
    ++chunks_;
  }

  [[noreturn]] void FailChunk(std::uint64_t offset, const std::string& why) const {
    throw std::invalid_argument(path_ + ": chunk at byte " + std::to_string(offset) + ": " + why);
  }

  void WalkChunk(const std::vector<std::uint8_t>& chunk, std::uint64_t chunk_offset) {
    std::size_t at = 0;
    while (at < chunk.size()) {
      if (chunk.size() - at < 4) FailChunk(chunk_offset, "a record runs past the chunk's end");
      const std::uint32_t header_bytes = ReadU32(chunk.data() + at);
      if (header_bytes > chunk.size() - at - 4 || chunk.size() - at - 4 - header_bytes < 4) {
        FailChunk(chunk_offset, "a record runs past the chunk's end");
      }
      const std::uint8_t* header = chunk.data() + at + 4;
      const std::uint32_t data_bytes = ReadU32(header + header_bytes);
      const std::uint8_t* data = header + header_bytes + 4;
      if (data_bytes > chunk.data() + chunk.size() - data) {
        FailChunk(chunk_offset, "a record runs past the chunk's end");
      }
      at = static_cast<std::size_t>(data + data_bytes - chunk.data());
      const auto fields = ParseFields(header, header_bytes);
      if (!fields || fields->count("op") == 0) FailChunk(chunk_offset, "a damaged record header");
      const std::string& op = fields->at("op");
      if (op.size() == 1 && static_cast<std::uint8_t>(op[0]) == kOpConnection) {
        AddConnection(*fields, data, data_bytes);
      } else if (op.size() == 1 && static_cast<std::uint8_t>(op[0]) == kOpMessage) {
        VisitMessage(*fields, data, data_bytes, chunk_offset);
      }
    }
  }

  void AddConnection(const Fields& fields, const std::uint8_t* data, std::uint32_t size) {
    const auto connection_fields = ParseFields(data, size);
    Connection connection;
    connection.topic = fields.count("topic") != 0 ? fields.at("topic") : "";
    if (connection_fields) {
      connection.datatype = connection_fields->count("type") ? connection_fields->at("type") : "";
      connection.md5sum = connection_fields->count("md5sum") ? connection_fields->at("md5sum") : "";
    }
    connections_[FieldU32(fields, "conn")] = connection;
  }

  void VisitMessage(const Fields& fields, const std::uint8_t* data, std::uint32_t size,
                    std::uint64_t chunk_offset) {
    const auto it = connections_.find(FieldU32(fields, "conn"));
    if (it == connections_.end()) FailChunk(chunk_offset, "a message of an unknown connection");
    const Connection& connection = it->second;
    ++counts_[connection.topic];
    ++messages_;
    if (topics_.count(connection.topic) == 0) return;
    const auto time = fields.find("time");
    std::uint32_t sec = 0;
    std::uint32_t nsec = 0;
    if (time != fields.end() && time->second.size() == 8) {
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(time->second.data());
      sec = ReadU32(bytes);
      nsec = ReadU32(bytes + 4);
    }
    visitor_({connection.topic, connection.datatype, connection.md5sum, sec, nsec, data, size});
  }

  BagSummary Summary() const {
    if (chunks_ == 0) {
      throw std::invalid_argument(path_ + ": no complete chunk: the bag is cut off or damaged " +
                                  "before its first message (at byte " +
                                  std::to_string(cut_offset_.value_or(kMagicBytes)) + ")");
    }
    BagSummary summary;
    summary.messages = messages_;
    std::map<std::string, std::string> type_of;
    for (const auto& [id, connection] : connections_)
      type_of[connection.topic] = connection.datatype;
    for (const auto& [topic, count] : counts_)
      summary.topics.push_back({topic, type_of[topic], count});
    std::string what = "read " + std::to_string(chunks_) + " complete chunks";
    if (expected_chunks_ > 0)
      what += " of the " + std::to_string(expected_chunks_) + " it announces";
    what += " (" + std::to_string(messages_) + " messages) without the index";
    if (cut_offset_) {
      what += "; dropped " + std::string(damaged_ ? "a damaged record" : "an incomplete record") +
              " at byte " + std::to_string(*cut_offset_) + " and everything after it";
    }
    summary.warnings.push_back(path_ + ": the bag's index is missing or damaged (a recording cut " +
                               "off?): " + what);
    return summary;
  }

  const std::string& path_;
  const std::set<std::string>& topics_;
  const RawMessageVisitor& visitor_;
  std::ifstream file_;
  std::uint64_t file_bytes_ = 0;
  std::map<std::uint32_t, Connection> connections_;
  std::map<std::string, std::size_t> counts_;
  std::size_t messages_ = 0;
  std::size_t chunks_ = 0;
  std::uint32_t expected_chunks_ = 0;
  std::optional<std::uint64_t> cut_offset_;
  bool damaged_ = false;
};

}  // namespace

void CheckBagRecords(const std::string& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  const auto file_bytes = static_cast<std::uint64_t>(file.tellg());
  std::uint64_t offset = kMagicBytes;
  std::vector<std::uint8_t> header;
  const auto fail = [&offset](const std::string& why) {
    throw BagIndexError("record at byte " + std::to_string(offset) + ": " + why);
  };
  while (file && offset < file_bytes) {
    std::uint8_t length_bytes[4];
    file.seekg(static_cast<std::streamoff>(offset));
    if (file_bytes - offset < 8 || !file.read(reinterpret_cast<char*>(length_bytes), 4)) {
      fail("cut off");
    }
    const std::uint32_t header_bytes = ReadU32(length_bytes);
    if (header_bytes > file_bytes - offset - 8) fail("its header runs past the end of the file");
    header.resize(header_bytes);
    if ((header_bytes > 0 && !file.read(reinterpret_cast<char*>(header.data()), header_bytes)) ||
        !file.read(reinterpret_cast<char*>(length_bytes), 4)) {
      fail("cut off");
    }
    const std::uint32_t data_bytes = ReadU32(length_bytes);
    if (data_bytes > file_bytes - offset - 8 - header_bytes) {
      fail("its data run past the end of the file");
    }
    const auto fields = ParseFields(header.data(), header.size());
    if (!fields) fail("a damaged header");
    const auto op = fields->find("op");
    const auto compression = fields->find("compression");
    if (op != fields->end() && op->second == std::string(1, static_cast<char>(kOpChunk)) &&
        compression != fields->end() && compression->second != "none" &&
        !PlausibleChunkBytes(FieldU32(*fields, "size"), data_bytes)) {
      fail("a chunk claiming " + std::to_string(FieldU32(*fields, "size")) +
           " bytes uncompressed from " + std::to_string(data_bytes));
    }
    offset += 8ULL + header_bytes + data_bytes;
  }
}

BagSummary VisitBagChunks(const std::string& path, const std::set<std::string>& topics,
                          const RawMessageVisitor& visitor) {
  return ChunkWalker(path, topics, visitor).Walk();
}

}  // namespace keyplace
