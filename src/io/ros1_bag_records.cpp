#include "io/ros1_bag_records.hpp"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <stdexcept>
#include <utility>

#include "io/chunk_limits.hpp"

namespace keyplace {
namespace {

[[noreturn]] void FailChunk(const std::string& source, std::uint64_t offset,
                            const std::string& why) {
  throw std::invalid_argument(source + ": chunk at byte " + std::to_string(offset) + ": " + why);
}

}  // namespace

std::uint32_t ReadU32(const std::uint8_t* bytes) {
  return static_cast<std::uint32_t>(bytes[0]) | static_cast<std::uint32_t>(bytes[1]) << 8 |
         static_cast<std::uint32_t>(bytes[2]) << 16 | static_cast<std::uint32_t>(bytes[3]) << 24;
}

std::uint64_t ReadU64(const std::uint8_t* bytes) {
  return static_cast<std::uint64_t>(ReadU32(bytes)) | static_cast<std::uint64_t>(ReadU32(bytes + 4))
                                                          << 32;
}

std::optional<BagFields> ParseFields(const std::uint8_t* bytes, std::size_t size) {
  BagFields fields;
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

std::optional<std::uint32_t> FieldU32(const BagFields& fields, const std::string& name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != 4) return std::nullopt;
  return ReadU32(reinterpret_cast<const std::uint8_t*>(it->second.data()));
}

std::optional<std::uint64_t> FieldU64(const BagFields& fields, const std::string& name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != 8) return std::nullopt;
  return ReadU64(reinterpret_cast<const std::uint8_t*>(it->second.data()));
}

std::optional<std::uint8_t> FieldOp(const BagFields& fields) {
  const auto it = fields.find("op");
  if (it == fields.end() || it->second.size() != 1) return std::nullopt;
  return static_cast<std::uint8_t>(it->second[0]);
}

std::vector<std::uint8_t> DecompressChunk(const std::string& source, const BagFields& fields,
                                          std::vector<std::uint8_t> data, std::uint64_t offset) {
  const auto compression = fields.find("compression");
  const std::string kind = compression == fields.end() ? "" : compression->second;
  if (kind == "none") return data;
  if (kind != "bz2" && kind != "lz4") {
    FailChunk(source, offset, "unknown compression '" + kind + "' (known: none, bz2, lz4)");
  }
  const std::uint32_t size = FieldU32(fields, "size").value_or(0);
  if (!PlausibleChunkBytes(size, data.size())) {
    FailChunk(source, offset,
              "uncompressed size " + std::to_string(size) + " from " + std::to_string(data.size()) +
                  " compressed bytes");
  }
  std::vector<std::uint8_t> chunk(size);
  unsigned int produced = size;
  auto* in = reinterpret_cast<char*>(data.data());
  auto* out = reinterpret_cast<char*>(chunk.data());
  const auto in_bytes = static_cast<unsigned int>(data.size());
  const bool ok = kind == "bz2"
                      ? BZ2_bzBuffToBuffDecompress(out, &produced, in, in_bytes, 0, 0) == BZ_OK
                      : roslz4_buffToBuffDecompress(in, in_bytes, out, &produced) == 0;
  if (!ok || produced != size) FailChunk(source, offset, kind + " data do not decompress");
  return chunk;
}

std::optional<std::string> ForEachChunkRecord(
    const std::vector<std::uint8_t>& chunk, const std::function<void(const ChunkRecord&)>& visit) {
  std::size_t at = 0;
  while (at < chunk.size()) {
    const std::size_t start = at;
    const std::string past_end =
        "its record at byte " + std::to_string(start) + " runs past its end";
    const std::size_t left = chunk.size() - at;
    if (left < 4) return past_end;
    const std::uint32_t header_bytes = ReadU32(chunk.data() + at);
    if (header_bytes > left - 4 || left - 4 - header_bytes < 4) return past_end;
    const std::uint8_t* header = chunk.data() + at + 4;
    const std::uint32_t data_bytes = ReadU32(header + header_bytes);
    const std::uint8_t* data = header + header_bytes + 4;
    if (data_bytes > chunk.data() + chunk.size() - data) return past_end;
    at = static_cast<std::size_t>(data + data_bytes - chunk.data());
    const auto fields = ParseFields(header, header_bytes);
    if (!fields || fields->count("op") == 0) {
      return "its record at byte " + std::to_string(start) + " has a damaged header";
    }
    // An op of another length than one byte is no record keyplace reads: 0 stands for it.
    visit({start, *fields, FieldOp(*fields).value_or(0), data, data_bytes});
  }
  return std::nullopt;
}

}  // namespace keyplace
