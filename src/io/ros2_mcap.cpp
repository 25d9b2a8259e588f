// ReadMcapMessages: an MCAP file (https://mcap.dev/spec) read record by record, front to back,
// without its summary section. Record: uint8 opcode, uint64 content length, content; all numbers
// little endian, strings and byte arrays prefixed by a uint32 length. Chunk records hold
// Schema, Channel and Message records, compressed as the chunk's compression field says.

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "common/shown_text.hpp"
#include "io/chunk_limits.hpp"
#include "io/ros2_storage.hpp"

namespace keyplace {
namespace {

constexpr const char* kMagic = kMcapMagic.data();
constexpr std::size_t kMagicBytes = kMcapMagic.size();
constexpr std::uint8_t kOpFooter = 0x02;
constexpr std::uint8_t kOpSchema = 0x03;
constexpr std::uint8_t kOpChannel = 0x04;
constexpr std::uint8_t kOpMessage = 0x05;
constexpr std::uint8_t kOpChunk = 0x06;
constexpr std::uint8_t kOpDataEnd = 0x0F;
constexpr std::size_t kRecordHeaderBytes = 9;

// Reads the fields of one record's content; false once a field runs past its end.
class Cursor {
 public:
  Cursor(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool U16(std::uint16_t& value) { return Unsigned(2, value); }
  bool U32(std::uint32_t& value) { return Unsigned(4, value); }
  bool U64(std::uint64_t& value) { return Unsigned(8, value); }
  bool String(std::string& text) {
    std::uint32_t length = 0;
    if (!U32(length) || length > size_ - at_) return false;
    text.assign(reinterpret_cast<const char*>(data_ + at_), length);
    at_ += length;
    return true;
  }
  // Bytes prefixed by a uint64 (chunk records) or uint32 length.
  bool Bytes64(const std::uint8_t*& bytes, std::uint64_t& length) {
    if (!U64(length) || length > size_ - at_) return false;
    bytes = data_ + at_;
    at_ += length;
    return true;
  }
  bool Skip32() {
    std::uint32_t length = 0;
    if (!U32(length) || length > size_ - at_) return false;
    at_ += length;
    return true;
  }
  const std::uint8_t* rest() const { return data_ + at_; }
  std::size_t left() const { return size_ - at_; }

 private:
  template <class T>
  bool Unsigned(std::size_t bytes, T& value) {
    if (bytes > size_ - at_) return false;
    std::uint64_t result = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
      result |= static_cast<std::uint64_t>(data_[at_ + i]) << (8 * i);
    }
    value = static_cast<T>(result);
    at_ += bytes;
    return true;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

class McapWalker {
 public:
  McapWalker(const std::string& path, const StorageVisitor& visitor)
      : path_(path), visitor_(visitor), file_(path, std::ios::binary | std::ios::ate) {
    if (!file_) throw std::invalid_argument(path + ": cannot open the MCAP file");
    file_bytes_ = static_cast<std::uint64_t>(file_.tellg());
    file_.seekg(0);
  }

  StorageWalk Walk() {
    char magic[kMagicBytes];
    if (!file_.read(magic, kMagicBytes) || std::memcmp(magic, kMagic, kMagicBytes) != 0) {
      throw std::invalid_argument(path_ + ": not an MCAP file (no MCAP magic bytes)");
    }
    std::uint64_t offset = kMagicBytes;
    std::vector<std::uint8_t> content;
    bool ended = false;
    while (!ended) {
      std::uint8_t opcode = 0;
      if (!ReadRecord(offset, opcode, content)) break;
      const std::uint64_t record_offset = offset;
      offset += kRecordHeaderBytes + content.size();
      if (opcode == kOpChunk) {
        ReadChunk(content, record_offset);
      } else if (opcode == kOpDataEnd || opcode == kOpFooter) {
        ended = true;
      } else {
        Dispatch(opcode, content.data(), content.size(), record_offset);
      }
      ++records_;
    }
    return Summary(ended, offset);
  }

 private:
  // The next record; false at the end of the file or when the record is cut off.
  bool ReadRecord(std::uint64_t offset, std::uint8_t& opcode, std::vector<std::uint8_t>& content) {
    std::uint8_t header[kRecordHeaderBytes];
    if (!file_.read(reinterpret_cast<char*>(header), kRecordHeaderBytes)) return false;
    opcode = header[0];
    std::uint64_t length = 0;
    Cursor(header + 1, 8).U64(length);
    if (length > file_bytes_ - offset - kRecordHeaderBytes) return false;
    content.resize(length);
    return length == 0 || static_cast<bool>(file_.read(reinterpret_cast<char*>(content.data()),
                                                       static_cast<std::streamsize>(length)));
  }

  [[noreturn]] void Fail(std::uint64_t offset, const std::string& why) const {
    throw std::invalid_argument(path_ + ": record at byte " + std::to_string(offset) + ": " + why);
  }

  void ReadChunk(const std::vector<std::uint8_t>& content, std::uint64_t offset) {
    Cursor cursor(content.data(), content.size());
    std::uint64_t start_time = 0;
    std::uint64_t end_time = 0;
    std::uint64_t uncompressed_bytes = 0;
    std::uint32_t crc = 0;
    std::string compression;
    const std::uint8_t* records = nullptr;
    std::uint64_t records_bytes = 0;
    if (!cursor.U64(start_time) || !cursor.U64(end_time) || !cursor.U64(uncompressed_bytes) ||
        !cursor.U32(crc) || !cursor.String(compression) ||
        !cursor.Bytes64(records, records_bytes)) {
      Fail(offset, "a chunk whose fields run past its end");
    }
    const std::uint8_t* plain = records;
    if (compression.empty()) {
      if (uncompressed_bytes != records_bytes) {
        Fail(offset, "an uncompressed chunk of " + std::to_string(records_bytes) +
                         " bytes that claims " + std::to_string(uncompressed_bytes));
      }
    } else {
      if (!PlausibleChunkBytes(uncompressed_bytes, records_bytes)) {
        Fail(offset, "a chunk claiming " + std::to_string(uncompressed_bytes) +
                         " bytes uncompressed from " + std::to_string(records_bytes));
      }
      CheckFrameSize(compression, records, records_bytes, uncompressed_bytes, offset);
      chunk_.resize(uncompressed_bytes);
      Decompress(compression, records, records_bytes, offset);
      plain = chunk_.data();
    }
    if (crc != 0) {
      const auto computed = static_cast<std::uint32_t>(
          crc32_z(crc32_z(0L, Z_NULL, 0), plain, static_cast<z_size_t>(uncompressed_bytes)));
      if (computed != crc) Fail(offset, "a chunk whose records fail their CRC");
    }
    WalkRecords(plain, uncompressed_bytes, offset);
    ++chunks_;
  }

  // A zstd frame that says its size must say the chunk's: checked before the buffer is allocated.
  void CheckFrameSize(const std::string& compression, const std::uint8_t* in,
                      std::uint64_t in_bytes, std::uint64_t uncompressed_bytes,
                      std::uint64_t offset) const {
    if (compression != "zstd") return;
    const unsigned long long frame_bytes = ZSTD_getFrameContentSize(in, in_bytes);
    if (frame_bytes == ZSTD_CONTENTSIZE_ERROR) {
      Fail(offset, "a zstd chunk that does not decompress (no zstd frame)");
    }
    if (frame_bytes != ZSTD_CONTENTSIZE_UNKNOWN && frame_bytes != uncompressed_bytes) {
      Fail(offset, "a zstd chunk of " + std::to_string(frame_bytes) + " bytes that claims " +
                       std::to_string(uncompressed_bytes));
    }
  }

  void Decompress(const std::string& compression, const std::uint8_t* in, std::uint64_t in_bytes,
                  std::uint64_t offset) {
    bool ok = false;
    if (compression == "zstd") {
      const std::size_t produced = ZSTD_decompress(chunk_.data(), chunk_.size(), in, in_bytes);
      ok = ZSTD_isError(produced) == 0 && produced == chunk_.size();
    } else if (compression == "lz4") {
      ok = DecompressLz4(in, in_bytes);
    } else {
      Fail(offset,
           "a chunk with unknown compression '" + compression + "' (known: none, lz4, zstd)");
    }
    if (!ok) Fail(offset, "a " + compression + " chunk that does not decompress");
  }

  // The LZ4 frame format, as MCAP's "lz4" chunks hold it. One context for all chunks: it keeps
  // its block buffers (up to 4 MiB each), which a context per chunk would allocate again.
  bool DecompressLz4(const std::uint8_t* in, std::size_t in_bytes) {
    if (!lz4_) {
      LZ4F_dctx* raw = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)) != 0) return false;
      lz4_.reset(raw);
    }
    LZ4F_resetDecompressionContext(lz4_.get());
    std::size_t out_at = 0;
    std::size_t in_at = 0;
    while (true) {
      std::size_t out_bytes = chunk_.size() - out_at;
      std::size_t in_left = in_bytes - in_at;
      const std::size_t hint = LZ4F_decompress(lz4_.get(), chunk_.data() + out_at, &out_bytes,
                                               in + in_at, &in_left, nullptr);
      if (LZ4F_isError(hint) != 0) return false;
      out_at += out_bytes;
      in_at += in_left;
      if (hint == 0) return out_at == chunk_.size();  // the frame is complete
      if (in_at == in_bytes || (out_bytes == 0 && in_left == 0)) return false;
    }
  }

  struct FreeLz4Context {
    void operator()(LZ4F_dctx* context) const { LZ4F_freeDecompressionContext(context); }
  };

  void WalkRecords(const std::uint8_t* data, std::uint64_t size, std::uint64_t chunk_offset) {
    Cursor cursor(data, size);
    while (cursor.left() > 0) {
      const std::uint8_t opcode = *cursor.rest();
      Cursor header(cursor.rest() + 1, cursor.left() - 1);
      std::uint64_t length = 0;
      if (cursor.left() < kRecordHeaderBytes || !header.U64(length) ||
          length > cursor.left() - kRecordHeaderBytes) {
        Fail(chunk_offset, "a chunk whose records run past its end");
      }
      Dispatch(opcode, cursor.rest() + kRecordHeaderBytes, length, chunk_offset);
      const std::uint8_t* ignored = nullptr;
      std::uint64_t skipped = 0;
      Cursor skip(cursor.rest() + 1, cursor.left() - 1);
      skip.Bytes64(ignored, skipped);
      cursor = Cursor(skip.rest(), skip.left());
    }
  }

  void Dispatch(std::uint8_t opcode, const std::uint8_t* data, std::size_t size,
                std::uint64_t offset) {
    Cursor cursor(data, size);
    if (opcode == kOpSchema) {
      std::uint16_t id = 0;
      std::string name;
      std::string encoding;
      if (!cursor.U16(id) || !cursor.String(name) || !cursor.String(encoding) || !cursor.Skip32()) {
        Fail(offset, "a damaged Schema record");
      }
      schema_names_[id] = name;
    } else if (opcode == kOpChannel) {
      std::uint16_t id = 0;
      std::uint16_t schema_id = 0;
      StorageTopic topic;
      if (!cursor.U16(id) || !cursor.U16(schema_id) || !cursor.String(topic.name) ||
          !cursor.String(topic.serialization)) {
        Fail(offset, "a damaged Channel record");
      }
      const auto schema = schema_names_.find(schema_id);
      if (schema_id != 0 && schema == schema_names_.end()) {
        Fail(offset, "channel " + ShownText(topic.name) + " names schema " +
                         std::to_string(schema_id) + ", which no Schema record before it declares");
      }
      // Schema id 0 is MCAP's "no schema": say so where the type would be shown (it was empty).
      topic.type = schema_id != 0 ? schema->second : "<no schema: schema_id 0>";
      if (channels_.count(id) == 0) order_.push_back(id);
      channels_[id] = std::make_unique<StorageTopic>(std::move(topic));
    } else if (opcode == kOpMessage) {
      std::uint16_t channel = 0;
      std::uint32_t sequence = 0;
      std::uint64_t log_time_ns = 0;
      std::uint64_t publish_time_ns = 0;
      if (!cursor.U16(channel) || !cursor.U32(sequence) || !cursor.U64(log_time_ns) ||
          !cursor.U64(publish_time_ns)) {
        Fail(offset, "a damaged Message record");
      }
      const auto it = channels_.find(channel);
      if (it == channels_.end()) {
        Fail(offset, "a message of channel " + std::to_string(channel) +
                         ", which no Channel record before it declares");
      }
      time_ordered_ = time_ordered_ && log_time_ns >= last_log_time_ns_;
      last_log_time_ns_ = log_time_ns;
      ++messages_;
      visitor_({*it->second, log_time_ns, cursor.rest(), cursor.left()});
    }
    // Other records (header, indexes, statistics, attachments, metadata) are not needed.
  }

  StorageWalk Summary(bool ended, std::uint64_t offset) const {
    StorageWalk walk;
    walk.time_ordered = time_ordered_;
    for (const std::uint16_t id : order_) walk.topics.push_back(*channels_.at(id));
    if (ended) return walk;
    const std::string where = "cut off at byte " + std::to_string(offset) + " of " +
                              std::to_string(file_bytes_) + " (a recording stopped?)";
    if (messages_ == 0) {
      throw std::invalid_argument(path_ + ": " + where + " before its first complete message");
    }
    walk.warnings.push_back(path_ + ": " + where + ": read " + std::to_string(records_) +
                            " complete records (" + std::to_string(chunks_) + " chunks, " +
                            std::to_string(messages_) +
                            " messages); dropped the incomplete record there and everything "
                            "after it");
    return walk;
  }

  const std::string& path_;
  const StorageVisitor& visitor_;
  std::ifstream file_;
  std::uint64_t file_bytes_ = 0;
  std::vector<std::uint8_t> chunk_;
  std::unique_ptr<LZ4F_dctx, FreeLz4Context> lz4_;
  std::map<std::uint16_t, std::string> schema_names_;
  // Stable addresses: StorageMessage refers to its topic.
  std::map<std::uint16_t, std::unique_ptr<StorageTopic>> channels_;
  std::vector<std::uint16_t> order_;
  std::size_t records_ = 0;
  std::size_t chunks_ = 0;
  std::size_t messages_ = 0;
  std::uint64_t last_log_time_ns_ = 0;
  bool time_ordered_ = true;
};

}  // namespace

bool StartsWithMcapMagic(const std::string& path) {
  char head[kMagicBytes] = {};
  std::ifstream file(path, std::ios::binary);
  return file.read(head, kMagicBytes) && std::memcmp(head, kMagic, kMagicBytes) == 0;
}

StorageWalk ReadMcapMessages(const std::string& path, const StorageVisitor& visitor) {
  return McapWalker(path, visitor).Walk();
}

}  // namespace keyplace
