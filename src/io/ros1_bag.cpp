#include "keyplace/io/ros1_bag.hpp"

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <sys/stat.h>
#include <tf2_msgs/TFMessage.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "io/bag_log.hpp"
#include "io/bag_messages.hpp"
#include "io/file_fingerprint.hpp"
#include "io/ros1_bag_records.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

StampFields Stamp(const ros::Time& time) { return {time.sec, time.nsec}; }

QuaternionFields Quaternion(const geometry_msgs::Quaternion& q) { return {q.x, q.y, q.z, q.w}; }

// Whether the strings and arrays of a message fit in its bytes. ros::serialization resizes a
// string or vector to its length field before it reads the elements, so a damaged length made it
// allocate what the field said (the fuzzer: 7.8 GB for a LaserScan's ranges) before the stream
// ran out. Layouts: ROS 1 serialization, little-endian, no padding.
class LengthCheck {
 public:
  LengthCheck(const std::uint8_t* data, std::uint32_t size) : at_(data), left_(size) {}

  bool Skip(std::size_t bytes) {
    if (bytes > left_) return false;
    at_ += bytes;
    left_ -= bytes;
    return true;
  }

  // A uint32 count of elements of at least `element_bytes` each: the count, or nothing when
  // that many cannot fit in what is left.
  std::optional<std::uint32_t> Count(std::size_t element_bytes) {
    if (left_ < 4) return std::nullopt;
    const std::uint32_t count = ReadU32(at_);
    Skip(4);
    if (count > left_ / element_bytes) return std::nullopt;
    return count;
  }

  bool Array(std::size_t element_bytes) {
    const auto count = Count(element_bytes);
    return count && Skip(*count * element_bytes);
  }

  bool Header() { return Skip(12) && Array(1); }  // seq, stamp, frame_id

 private:
  const std::uint8_t* at_;
  std::size_t left_;
};

// The header; angle_min ... range_max (7 float32); ranges and intensities (float32[]).
bool Fits(const sensor_msgs::LaserScan* /*type*/, LengthCheck& check) {
  return check.Header() && check.Skip(std::size_t{7} * 4) && check.Array(4) && check.Array(4);
}

// The header; child_frame_id; pose (7 float64) and its covariance (36); twist (6) and its (36).
bool Fits(const nav_msgs::Odometry* /*type*/, LengthCheck& check) {
  return check.Header() && check.Array(1) && check.Skip(std::size_t{7 + 36 + 6 + 36} * 8);
}

// TransformStamped[]: each a header, child_frame_id and a transform (7 float64).
bool Fits(const tf2_msgs::TFMessage* /*type*/, LengthCheck& check) {
  constexpr std::size_t kTransformBytes = std::size_t{7} * 8;
  const auto count = check.Count(12 + 4 + 4 + kTransformBytes);
  if (!count) return false;
  for (std::uint32_t i = 0; i < *count; ++i) {
    if (!check.Header() || !check.Array(1) || !check.Skip(kTransformBytes)) return false;
  }
  return true;
}

// The bag's messages, deserialized with the ROS 1 message headers, into the shared sink.
class BagDecoder {
 public:
  BagDecoder(const std::string& path, const BagInputConfig& config, double max_coordinate_m)
      : path_(path), sink_(path, config, max_coordinate_m, kRos1TypeNames) {}

  std::set<std::string> Topics() const { return sink_.Topics(); }

  void operator()(const RawBagMessage& message) {
    const BagMessageKind kind = sink_.Classify(message.topic, message.datatype);
    const double receive_s = StampSeconds({message.receive_sec, message.receive_nsec});
    switch (kind) {
      case BagMessageKind::kScan: {
        const auto scan = Decode<sensor_msgs::LaserScan>(message, kind);
        sink_.AddScan(message.topic,
                      {Stamp(scan.header.stamp), scan.header.frame_id, scan.angle_min,
                       scan.angle_increment, scan.range_min, scan.range_max, scan.ranges},
                      receive_s);
        break;
      }
      case BagMessageKind::kOdometry: {
        const auto odometry = Decode<nav_msgs::Odometry>(message, kind);
        const auto& pose = odometry.pose.pose;
        sink_.AddOdometry(message.topic,
                          {Stamp(odometry.header.stamp), pose.position.x, pose.position.y,
                           Quaternion(pose.orientation), odometry.twist.twist.linear.x,
                           odometry.twist.twist.angular.z},
                          receive_s);
        break;
      }
      case BagMessageKind::kTransforms: {
        std::vector<TransformFields> transforms;
        for (const auto& t : Decode<tf2_msgs::TFMessage>(message, kind).transforms) {
          transforms.push_back({Stamp(t.header.stamp), t.header.frame_id, t.child_frame_id,
                                t.transform.translation.x, t.transform.translation.y,
                                Quaternion(t.transform.rotation)});
        }
        sink_.AddTransforms(message.topic, transforms);
        break;
      }
      case BagMessageKind::kNone:
        break;
    }
  }

  BagContents& contents() { return sink_.contents(); }
  void Reset() { sink_.Reset(); }

 private:
  // The message deserialized; one of the expected type name but another definition is an
  // error at once.
  template <class Message>
  Message Decode(const RawBagMessage& message, BagMessageKind kind) const {
    const std::string md5 = ros::message_traits::MD5Sum<Message>::value();
    if (message.md5sum != md5 && message.md5sum != "*") {
      throw std::invalid_argument(path_ + ": topic " + message.topic + ": its " + message.datatype +
                                  " messages have another definition (md5 " + message.md5sum +
                                  ", this keyplace reads " + md5 + ")");
    }
    Message decoded;
    LengthCheck check(message.data, message.size);
    if (!Fits(static_cast<const Message*>(nullptr), check)) {
      sink_.Damaged(message.topic, sink_.NextNumber(kind),
                    "a string or array runs past the message's end");
    }
    try {
      // IStream only reads, but takes a non-const pointer.
      ros::serialization::IStream stream(const_cast<std::uint8_t*>(message.data), message.size);
      ros::serialization::deserialize(stream, decoded);
    } catch (const std::exception& error) {
      sink_.Damaged(message.topic, sink_.NextNumber(kind), error.what());
    }
    return decoded;
  }

  const std::string& path_;
  BagMessageSink sink_;
};

}  // namespace

bool IsRos1Bag(const std::string& path) {
  struct stat status {};
  if (stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return false;
  static constexpr char kMagic[] = "#ROSBAG V2.0\n";
  char head[sizeof(kMagic) - 1] = {};
  std::ifstream file(path, std::ios::binary);
  return file.read(head, sizeof(head)) && std::memcmp(head, kMagic, sizeof(head)) == 0;
}

CarmenLog ReadRos1Bag(const std::string& path, const BagInputConfig& config,
                      double max_coordinate_m) {
  Validate(config);
  BagDecoder decoder(path, config, max_coordinate_m);
  const auto visit = [&decoder](const RawBagMessage& message) { decoder(message); };
  BagSummary summary;
  try {
    summary = VisitIndexedBag(path, decoder.Topics(), visit);
  } catch (const BagIndexError& error) {
    decoder.Reset();
    try {
      summary = VisitBagChunks(path, decoder.Topics(), visit);
    } catch (const std::invalid_argument& walk_error) {
      throw std::invalid_argument(std::string(walk_error.what()) +
                                  "; nor can its index be read: " + error.what());
    }
  }
  CarmenLog log =
      AssembleBagLog(path, config, kRos1TypeNames, summary, std::move(decoder.contents()));
  log.fingerprint = FileFingerprint(path);
  std::error_code ignored;
  log.file_bytes = std::filesystem::file_size(path, ignored);
  return log;
}

}  // namespace keyplace
