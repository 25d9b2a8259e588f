#include "io/ros2_cdr.hpp"

#include <cstring>
#include <string>

namespace keyplace {
namespace {

// Encapsulation identifiers (OMG DDS-XTypes, 7.6.3.1.2): plain CDR, big and little endian.
constexpr std::uint8_t kCdrBigEndian = 0x00;
constexpr std::uint8_t kCdrLittleEndian = 0x01;
constexpr std::size_t kEncapsulationBytes = 4;

class CdrReader {
 public:
  CdrReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {
    if (size < kEncapsulationBytes) Fail("shorter than the 4-byte encapsulation header");
    if (data[0] != 0x00 || (data[1] != kCdrBigEndian && data[1] != kCdrLittleEndian)) {
      Fail("encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) +
           " is not plain CDR (0,0 big endian or 0,1 little endian)");
    }
    little_endian_ = data[1] == kCdrLittleEndian;
    at_ = kEncapsulationBytes;
  }

  std::uint32_t U32() { return static_cast<std::uint32_t>(Unsigned(4)); }
  std::int32_t I32() { return static_cast<std::int32_t>(U32()); }
  float F32() {
    const auto bits = static_cast<std::uint32_t>(Unsigned(4));
    float value = 0.0F;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }
  double F64() {
    const std::uint64_t bits = Unsigned(8);
    double value = 0.0;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }
  void SkipF64(std::size_t count) {
    Align(8);
    Need(count * 8);
    at_ += count * 8;
  }

  // A CDR string: uint32 length including the terminating zero byte, then the bytes.
  std::string String() {
    const std::uint32_t length = U32();
    Need(length);
    if (length == 0) return {};
    if (data_[at_ + length - 1] != 0) Fail("a string without its terminating zero byte");
    std::string text(reinterpret_cast<const char*>(data_ + at_), length - 1);
    at_ += length;
    return text;
  }

  // A sequence length, checked against the bytes left for elements of at least `element_bytes`.
  std::uint32_t SequenceLength(std::size_t element_bytes) {
    const std::uint32_t count = U32();
    if (element_bytes > 0 && count > (size_ - at_) / element_bytes) {
      Fail("a sequence of " + std::to_string(count) + " elements runs past the message's end");
    }
    return count;
  }

  std::vector<float> F32Sequence() {
    const std::uint32_t count = SequenceLength(4);
    std::vector<float> values(count);
    for (float& value : values) value = F32();
    return values;
  }
  void SkipF32Sequence() {
    const std::uint32_t count = SequenceLength(4);
    if (count > 0) Align(4);
    at_ += static_cast<std::size_t>(count) * 4;
  }

  StampFields Stamp() {
    StampFields stamp;
    stamp.sec = I32();
    stamp.nsec = U32();
    return stamp;
  }
  QuaternionFields Quaternion() {
    QuaternionFields q;
    q.x = F64();
    q.y = F64();
    q.z = F64();
    q.w = F64();
    return q;
  }

  [[noreturn]] void Fail(const std::string& why) const {
    throw CdrError("byte " + std::to_string(at_) + " of " + std::to_string(size_) + ": " + why);
  }

 private:
  void Align(std::size_t bytes) {
    const std::size_t offset = (at_ - kEncapsulationBytes) % bytes;
    if (offset != 0) {
      Need(bytes - offset);
      at_ += bytes - offset;
    }
  }
  void Need(std::size_t bytes) const {
    if (bytes > size_ - at_) Fail("the message ends " + std::to_string(bytes) + " bytes early");
  }
  std::uint64_t Unsigned(std::size_t bytes) {
    Align(bytes);
    Need(bytes);
    std::uint64_t value = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
      const std::size_t shift = little_endian_ ? i : bytes - 1 - i;
      value |= static_cast<std::uint64_t>(data_[at_ + i]) << (8 * shift);
    }
    at_ += bytes;
    return value;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
  bool little_endian_ = true;
};

// geometry_msgs/TransformStamped: header, child_frame_id, translation, rotation.
TransformFields Transform(CdrReader& reader) {
  TransformFields t;
  t.stamp = reader.Stamp();
  t.parent_frame = reader.String();
  t.child_frame = reader.String();
  t.x_m = reader.F64();
  t.y_m = reader.F64();
  reader.F64();  // z
  t.rotation = reader.Quaternion();
  return t;
}

// The smallest TransformStamped: stamp 8, two empty strings 8, seven float64 56 bytes.
constexpr std::size_t kMinTransformBytes = 72;

}  // namespace

ScanFields DecodeRos2LaserScan(const std::uint8_t* data, std::size_t size) {
  CdrReader reader(data, size);
  ScanFields scan;
  scan.stamp = reader.Stamp();
  scan.frame_id = reader.String();
  scan.angle_min = reader.F32();
  reader.F32();  // angle_max
  scan.angle_increment = reader.F32();
  reader.F32();  // time_increment
  reader.F32();  // scan_time
  scan.range_min = reader.F32();
  scan.range_max = reader.F32();
  scan.ranges = reader.F32Sequence();
  reader.SkipF32Sequence();  // intensities
  return scan;
}

OdometryFields DecodeRos2Odometry(const std::uint8_t* data, std::size_t size) {
  CdrReader reader(data, size);
  OdometryFields odometry;
  odometry.stamp = reader.Stamp();
  reader.String();  // header.frame_id
  reader.String();  // child_frame_id
  odometry.x_m = reader.F64();
  odometry.y_m = reader.F64();
  reader.F64();  // z
  odometry.orientation = reader.Quaternion();
  reader.SkipF64(36);  // pose covariance
  odometry.linear_x_mps = reader.F64();
  reader.F64();  // linear y
  reader.F64();  // linear z
  reader.F64();  // angular x
  reader.F64();  // angular y
  odometry.angular_z_radps = reader.F64();
  reader.SkipF64(36);  // twist covariance
  return odometry;
}

std::vector<TransformFields> DecodeRos2TfMessage(const std::uint8_t* data, std::size_t size) {
  CdrReader reader(data, size);
  const std::uint32_t count = reader.SequenceLength(kMinTransformBytes);
  std::vector<TransformFields> transforms;
  transforms.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) transforms.push_back(Transform(reader));
  return transforms;
}

}  // namespace keyplace
