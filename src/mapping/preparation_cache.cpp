#include "mapping/preparation_cache.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>

#include "common/fnv1a64.hpp"
#include "io/atomic_file.hpp"

namespace keyplace::mapping_internal {
namespace {

constexpr char kMagic[] = "KPPREP1\n";
constexpr std::size_t kMagicBytes = sizeof(kMagic) - 1;
constexpr std::uint32_t kByteOrderMark = 0x01020304;
// header: magic, byte order mark, key length; then payload length and checksum.
constexpr std::size_t kFixedBytes = kMagicBytes + 4 + 8 + 8 + 8;

template <typename T>
void Append(std::string& out, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Reads values from a payload front to back; running past its end is an error naming `what`.
class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}

  template <typename T>
  T Next(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (bytes_.size() - at_ < sizeof(T)) {
      throw std::runtime_error(std::string("ends inside ") + what + " at byte " +
                               std::to_string(at_));
    }
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  // The count of items of `item_bytes` each that follow, checked against the bytes left.
  std::size_t Count(const char* what, std::size_t item_bytes) {
    const auto count = Next<std::uint64_t>(what);
    if (count > (bytes_.size() - at_) / item_bytes) {
      throw std::runtime_error(std::to_string(count) + " " + what + " do not fit in the " +
                               std::to_string(bytes_.size() - at_) + " bytes left");
    }
    return static_cast<std::size_t>(count);
  }
  std::string_view Take(std::size_t count) {  // count <= Left(), as Count checked
    const std::size_t begin = at_;
    at_ += count;
    return bytes_.substr(begin, count);
  }
  std::size_t Left() const { return bytes_.size() - at_; }
  std::size_t at() const { return at_; }
  void ExpectEnd() const {
    if (at_ != bytes_.size()) {
      throw std::runtime_error(std::to_string(bytes_.size() - at_) + " bytes after the last item");
    }
  }

 private:
  std::string_view bytes_;
  std::size_t at_ = 0;
};

void ExpectScans(std::size_t found, std::size_t scans, const char* what) {
  if (found != scans) {
    throw std::runtime_error(std::string(what) + " for " + std::to_string(found) +
                             " scans, the log has " + std::to_string(scans));
  }
}

}  // namespace

std::string CacheEntryPath(const std::string& dir, const std::string& kind,
                           const std::string& key) {
  return dir + "/" + kind + "-" + Hex64(Fnv1a64Of(key.data(), key.size())) + ".bin";
}

CacheRead ReadCacheEntry(const std::string& path, const std::string& key, std::uint64_t max_bytes) {
  CacheRead read;
  std::error_code status_error;
  const auto status = std::filesystem::status(path, status_error);
  if (status.type() == std::filesystem::file_type::not_found) return read;  // no entry yet
  if (status.type() != std::filesystem::file_type::regular) {  // a FIFO would never end
    read.problem = "is not a regular file";
    return read;
  }
  const std::uintmax_t size = std::filesystem::file_size(path, status_error);
  if (!status_error && size > max_bytes) {
    read.problem = "holds " + std::to_string(size) + " bytes, more than the " +
                   std::to_string(max_bytes) + " an entry may have";
    return read;
  }
  std::ifstream file(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (!file.is_open() || file.bad()) {
    read.problem = "cannot be read";
    return read;
  }
  if (bytes.size() < kFixedBytes || bytes.compare(0, kMagicBytes, kMagic) != 0) {
    read.problem = "is not a keyplace preparation cache entry";
    return read;
  }
  std::uint32_t mark = 0;
  std::memcpy(&mark, bytes.data() + kMagicBytes, 4);
  if (mark != kByteOrderMark) {
    read.problem = "was written with another byte order (or is damaged)";
    return read;
  }
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, bytes.data() + bytes.size() - 8, 8);
  if (checksum != Fnv1a64Of(bytes.data(), bytes.size() - 8)) {
    read.problem = "fails its checksum (damaged or cut short)";
    return read;
  }
  // The body: after the magic and the byte order mark, before the checksum.
  const std::size_t body_begin = kMagicBytes + 4;
  Reader reader(std::string_view(bytes).substr(body_begin, bytes.size() - 8 - body_begin));
  try {
    const std::size_t key_bytes = reader.Count("key bytes", 1);
    if (reader.Take(key_bytes) != key) return read;  // another key with the same hash: a miss
    const std::size_t payload_bytes = reader.Count("payload bytes", 1);
    if (payload_bytes != reader.Left()) {
      read.problem = "says " + std::to_string(payload_bytes) + " payload bytes and holds " +
                     std::to_string(reader.Left());
      return read;
    }
    // The payload is the rest of the file but its checksum: the file's buffer becomes the
    // payload (header erased in place), no second buffer.
    bytes.resize(bytes.size() - 8);
    bytes.erase(0, body_begin + reader.at());
    read.payload = std::move(bytes);
  } catch (const std::runtime_error& error) {
    read.problem = error.what();
  }
  return read;
}

void WriteCacheEntry(const std::string& path, const std::string& key, const std::string& payload) {
  std::string bytes(kMagic, kMagicBytes);
  bytes.reserve(kFixedBytes + key.size() + payload.size());
  Append(bytes, kByteOrderMark);
  Append(bytes, static_cast<std::uint64_t>(key.size()));
  bytes += key;
  Append(bytes, static_cast<std::uint64_t>(payload.size()));
  bytes += payload;
  Append(bytes, Fnv1a64Of(bytes.data(), bytes.size()));
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

std::string EncodePoses(const std::vector<Pose2>& poses) {
  std::string out;
  out.reserve(8 + poses.size() * 24);
  Append(out, static_cast<std::uint64_t>(poses.size()));
  for (const Pose2& pose : poses) {
    Append(out, pose.x);
    Append(out, pose.y);
    Append(out, pose.theta);
  }
  return out;
}

std::vector<Pose2> DecodePoses(const std::string& payload, std::size_t scans) {
  Reader reader(payload);
  const std::size_t count = reader.Count("poses", 24);
  ExpectScans(count, scans, "poses");
  std::vector<Pose2> poses(count);
  for (Pose2& pose : poses) {
    // Assigned, not constructed: the written theta is already wrapped and stays bit-identical.
    pose.x = reader.Next<double>("a pose");
    pose.y = reader.Next<double>("a pose");
    pose.theta = reader.Next<double>("a pose");
  }
  reader.ExpectEnd();
  return poses;
}

std::string EncodeKeypoints(const std::vector<std::vector<Keypoint>>& keypoints) {
  std::string out;
  Append(out, static_cast<std::uint64_t>(keypoints.size()));
  for (const auto& scan : keypoints) {
    Append(out, static_cast<std::uint64_t>(scan.size()));
    for (const Keypoint& keypoint : scan) {
      Append(out, keypoint.position_m.x());
      Append(out, keypoint.position_m.y());
      Append(out, keypoint.orientation_rad);
      Append(out, keypoint.scale_m);
      Append(out, static_cast<std::int32_t>(keypoint.scale_level));
      Append(out, static_cast<std::int32_t>(keypoint.beam_index));
      Append(out, keypoint.descriptor);
    }
  }
  return out;
}

std::vector<std::vector<Keypoint>> DecodeKeypoints(const std::string& payload, std::size_t scans) {
  constexpr std::size_t kKeypointBytes = 4 * 8 + 2 * 4 + sizeof(BetaGridDescriptor);
  Reader reader(payload);
  const std::size_t count = reader.Count("scans", 8);
  ExpectScans(count, scans, "keypoints");
  std::vector<std::vector<Keypoint>> keypoints(count);
  for (auto& scan : keypoints) {
    scan.resize(reader.Count("keypoints", kKeypointBytes));
    for (Keypoint& keypoint : scan) {
      keypoint.position_m.x() = reader.Next<double>("a keypoint");
      keypoint.position_m.y() = reader.Next<double>("a keypoint");
      keypoint.orientation_rad = reader.Next<double>("a keypoint");
      keypoint.scale_m = reader.Next<double>("a keypoint");
      keypoint.scale_level = reader.Next<std::int32_t>("a keypoint");
      keypoint.beam_index = reader.Next<std::int32_t>("a keypoint");
      keypoint.descriptor = reader.Next<BetaGridDescriptor>("a keypoint");
    }
  }
  reader.ExpectEnd();
  return keypoints;
}

}  // namespace keyplace::mapping_internal
