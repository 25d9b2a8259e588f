#include "keyplace/io/ros1_bag.hpp"

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <sys/stat.h>
#include <tf2_msgs/TFMessage.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <utility>

#include "io/bag_log.hpp"
#include "io/bag_messages.hpp"
#include "io/file_fingerprint.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

StampFields Stamp(const ros::Time& time) { return {time.sec, time.nsec}; }

QuaternionFields Quaternion(const geometry_msgs::Quaternion& q) { return {q.x, q.y, q.z, q.w}; }

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
