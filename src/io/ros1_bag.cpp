#include "keyplace/io/ros1_bag.hpp"

#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <sys/stat.h>
#include <tf2_msgs/TFMessage.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <utility>

#include "io/file_fingerprint.hpp"
#include "io/ros1_bag_poses.hpp"
#include "io/ros1_bag_source.hpp"

namespace keyplace {
namespace {

constexpr char kTfTopic[] = "/tf";
constexpr char kTfStaticTopic[] = "/tf_static";

// The double of the shortest decimal that reads back as `value`: what a text log holds for a
// float32 field (4.45 rather than 4.449999809...), so a bag and a log written from it agree.
double ShortestDecimal(float value) {
  char text[32];
  const auto written = std::to_chars(text, text + sizeof(text), value);
  double result = 0.0;
  std::from_chars(text, written.ptr, result);
  return result;
}

// sec.nsec as the double nearest to that decimal.
double StampSeconds(std::uint32_t sec, std::uint32_t nsec) {
  char text[32];
  const int length = std::snprintf(text, sizeof(text), "%u.%09u", sec, nsec);
  double result = 0.0;
  std::from_chars(text, text + length, result);
  return result;
}

double Yaw(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

class BagDecoder {
 public:
  BagDecoder(const std::string& path, const BagInputConfig& config, double max_coordinate_m)
      : path_(path), config_(config), max_coordinate_m_(max_coordinate_m) {}

  std::set<std::string> Topics() const {
    return {config_.scan_topic, config_.odom_topic, kTfTopic, kTfStaticTopic};
  }

  void operator()(const RawBagMessage& message) {
    if (message.topic == config_.scan_topic) {
      if (Matches<sensor_msgs::LaserScan>(message)) AddScan(message);
    } else if (message.topic == config_.odom_topic) {
      if (Matches<nav_msgs::Odometry>(message)) AddOdometry(message);
    } else if (Matches<tf2_msgs::TFMessage>(message)) {
      AddTransforms(message, message.topic == kTfStaticTopic);
    }
  }

  BagContents& contents() { return contents_; }
  void Reset() { contents_ = BagContents(); }

 private:
  // Whether the message has type Message; a message of another type is noted for the topic's
  // error (CheckTypes), one of the same name but another definition is an error at once.
  template <class Message>
  bool Matches(const RawBagMessage& message) {
    const std::string expected = ros::message_traits::DataType<Message>::value();
    if (message.datatype != expected) {
      contents_.wrong_types.try_emplace(message.topic, message.datatype);
      return false;
    }
    const std::string md5 = ros::message_traits::MD5Sum<Message>::value();
    if (message.md5sum != md5 && message.md5sum != "*") {
      throw std::invalid_argument(path_ + ": topic " + message.topic + ": its " + expected +
                                  " messages have another definition (md5 " + message.md5sum +
                                  ", this keyplace reads " + md5 + ")");
    }
    return true;
  }

  template <class Message>
  Message Decode(const RawBagMessage& message, std::size_t number) const {
    Message decoded;
    try {
      // IStream only reads, but takes a non-const pointer.
      ros::serialization::IStream stream(const_cast<std::uint8_t*>(message.data), message.size);
      ros::serialization::deserialize(stream, decoded);
    } catch (const std::exception& error) {
      throw std::invalid_argument(path_ + ": topic " + message.topic + ": message " +
                                  std::to_string(number) + " is damaged (" + error.what() + ")");
    }
    return decoded;
  }

  void AddScan(const RawBagMessage& message) {
    const std::size_t number = contents_.scans.size() + 1;
    const auto scan = Decode<sensor_msgs::LaserScan>(message, number);
    const std::string where =
        path_ + ": topic " + message.topic + ": scan " + std::to_string(number) + ": ";
    if (scan.ranges.size() > kMaxScanBeams) {
      throw std::invalid_argument(where + std::to_string(scan.ranges.size()) +
                                  " beams, more than the " + std::to_string(kMaxScanBeams) +
                                  " keyplace takes (downsample the scan)");
    }
    if (!(scan.range_max > 0.0F)) {
      throw std::invalid_argument(where + "range_max must be positive");
    }
    LogScan out;
    out.line = number;
    out.timestamp_s = StampSeconds(scan.header.stamp.sec, scan.header.stamp.nsec);
    out.logger_timestamp_s = StampSeconds(message.receive_sec, message.receive_nsec);
    out.max_range_m = ShortestDecimal(scan.range_max);
    const double min_range_m = ShortestDecimal(scan.range_min);
    const std::size_t n = scan.ranges.size();
    const double start_rad =
        config_.scan_fov_rad > 0.0 ? -0.5 * config_.scan_fov_rad : ShortestDecimal(scan.angle_min);
    const double step_rad = config_.scan_fov_rad > 0.0
                                ? (n > 0 ? config_.scan_fov_rad / static_cast<double>(n) : 0.0)
                                : ShortestDecimal(scan.angle_increment);
    out.ranges_m.resize(n);
    out.angles_rad.resize(n);
    out.valid.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const double range = ShortestDecimal(scan.ranges[i]);
      out.ranges_m[i] = range;
      out.angles_rad[i] = start_rad + static_cast<double>(i) * step_rad;
      if (std::isnan(range) || range <= 0.0 || range < min_range_m) {
        ++contents_.invalid_beams;
      } else if (range >= out.max_range_m) {
        ++contents_.no_return_beams;
      } else {
        out.valid[i] = 1;
      }
    }
    contents_.scans.push_back(std::move(out));
    contents_.scan_frames.push_back(scan.header.frame_id);
  }

  void CheckCoordinates(const RawBagMessage& message, std::size_t number, double x_m,
                        double y_m) const {
    if (!(std::abs(x_m) <= max_coordinate_m_ && std::abs(y_m) <= max_coordinate_m_)) {
      throw std::invalid_argument(path_ + ": topic " + message.topic + ": message " +
                                  std::to_string(number) + ": position (" + std::to_string(x_m) +
                                  ", " + std::to_string(y_m) + ") m lies beyond +-" +
                                  std::to_string(max_coordinate_m_) + " m or is not finite");
    }
  }

  void AddOdometry(const RawBagMessage& message) {
    const std::size_t number = contents_.odometry.size() + 1;
    const auto odometry = Decode<nav_msgs::Odometry>(message, number);
    const auto& pose = odometry.pose.pose;
    CheckCoordinates(message, number, pose.position.x, pose.position.y);
    OdometryMessage out;
    out.pose = Pose2(pose.position.x, pose.position.y, Yaw(pose.orientation));
    out.tv_mps = odometry.twist.twist.linear.x;
    out.rv_radps = odometry.twist.twist.angular.z;
    out.timestamp_s = StampSeconds(odometry.header.stamp.sec, odometry.header.stamp.nsec);
    out.logger_timestamp_s = StampSeconds(message.receive_sec, message.receive_nsec);
    contents_.odometry.push_back(out);
  }

  void AddTransforms(const RawBagMessage& message, bool is_static) {
    const std::size_t number = ++contents_.tf_messages;
    for (const auto& transform : Decode<tf2_msgs::TFMessage>(message, number).transforms) {
      const auto& t = transform.transform;
      CheckCoordinates(message, number, t.translation.x, t.translation.y);
      contents_.tf.Add(transform.header.frame_id, transform.child_frame_id,
                       StampSeconds(transform.header.stamp.sec, transform.header.stamp.nsec),
                       Pose2(t.translation.x, t.translation.y, Yaw(t.rotation)), is_static);
    }
  }

  const std::string& path_;
  const BagInputConfig& config_;
  double max_coordinate_m_;
  BagContents contents_;
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
                                  "; rosbag cannot open it either: " + error.what());
    }
  }
  CarmenLog log = AssembleBagLog(path, config, summary, std::move(decoder.contents()));
  log.fingerprint = FileFingerprint(path);
  std::error_code ignored;
  log.file_bytes = std::filesystem::file_size(path, ignored);
  return log;
}

}  // namespace keyplace
