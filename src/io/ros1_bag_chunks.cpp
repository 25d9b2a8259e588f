// VisitBagChunks: a ROS 1 bag (format 2.0) read record by record, for bags whose index cannot be
// read because it is missing (a recording cut off) or damaged (record layout:
// ros1_bag_records.hpp).

#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/ros1_bag_records.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

// A chunk is about 768 KiB by default; a length beyond this is damage, not data.
constexpr std::uint32_t kMaxRecordBytes = 1U << 30;

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
    char magic[kRos1BagMagicBytes];
    if (!file_.read(magic, kRos1BagMagicBytes) ||
        std::memcmp(magic, kRos1BagMagic, kRos1BagMagicBytes) != 0) {
      throw std::invalid_argument(path_ + ": not a ROS 1 bag (format 2.0)");
    }
    std::uint64_t offset = kRos1BagMagicBytes;
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
      const auto op = fields ? FieldOp(*fields) : std::nullopt;
      if (!op) {
        cut_offset_ = record_offset;
        damaged_ = true;
        break;
      }
      if (*op == kOpBagHeader) expected_chunks_ = FieldU32(*fields, "chunk_count").value_or(0);
      if (*op == kOpChunk) ReadChunk(*fields, std::exchange(data, {}), record_offset);
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

  void ReadChunk(const BagFields& fields, std::vector<std::uint8_t> compressed,
                 std::uint64_t offset) {
    const std::vector<std::uint8_t> chunk =
        DecompressChunk(path_, fields, std::move(compressed), offset);
    const auto damage = ForEachChunkRecord(chunk, [this, offset](const ChunkRecord& record) {
      if (record.op == kOpConnection) AddConnection(record.fields, record.data, record.size);
      if (record.op == kOpMessage) VisitMessage(record.fields, record.data, record.size, offset);
    });
    if (damage) FailChunk(offset, *damage);
    ++chunks_;
  }

  [[noreturn]] void FailChunk(std::uint64_t offset, const std::string& why) const {
    throw std::invalid_argument(path_ + ": chunk at byte " + std::to_string(offset) + ": " + why);
  }

  void AddConnection(const BagFields& fields, const std::uint8_t* data, std::uint32_t size) {
    const auto connection_fields = ParseFields(data, size);
    BagConnection connection;
    connection.topic = fields.count("topic") != 0 ? fields.at("topic") : "";
    if (connection_fields) {
      connection.datatype = connection_fields->count("type") ? connection_fields->at("type") : "";
      connection.md5sum = connection_fields->count("md5sum") ? connection_fields->at("md5sum") : "";
    }
    connections_[FieldU32(fields, "conn").value_or(0)] = connection;
  }

  void VisitMessage(const BagFields& fields, const std::uint8_t* data, std::uint32_t size,
                    std::uint64_t chunk_offset) {
    const auto it = connections_.find(FieldU32(fields, "conn").value_or(0));
    if (it == connections_.end()) FailChunk(chunk_offset, "a message of an unknown connection");
    const BagConnection& connection = it->second;
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
                                  std::to_string(cut_offset_.value_or(kRos1BagMagicBytes)) + ")");
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
  std::map<std::uint32_t, BagConnection> connections_;
  std::map<std::string, std::size_t> counts_;
  std::size_t messages_ = 0;
  std::size_t chunks_ = 0;
  std::uint32_t expected_chunks_ = 0;
  std::optional<std::uint64_t> cut_offset_;
  bool damaged_ = false;
};

}  // namespace

BagSummary VisitBagChunks(const std::string& path, const std::set<std::string>& topics,
                          const RawMessageVisitor& visitor) {
  return ChunkWalker(path, topics, visitor).Walk();
}

}  // namespace keyplace
