#pragma once
// Internal: the fields keyplace reads from a bag's LaserScan, Odometry and TFMessage messages,
// whatever their serialization (ROS 1 or ROS 2 CDR), and BagMessageSink, which turns them into
// BagContents the same way for every bag format: stamps, float32 ranges as a text log would give
// them, beam validity, planar poses, coordinate checks.

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "io/bag_log.hpp"
#include "keyplace/io/bag_input_config.hpp"

namespace keyplace {

/// A header stamp; ROS 1 has unsigned seconds, ROS 2 signed ones.
struct StampFields {
  std::int64_t sec = 0;
  std::uint32_t nsec = 0;
};

struct QuaternionFields {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
};

/// sensor_msgs/LaserScan.
struct ScanFields {
  StampFields stamp;
  std::string frame_id;
  float angle_min = 0.0F;
  float angle_increment = 0.0F;
  float range_min = 0.0F;
  float range_max = 0.0F;
  std::vector<float> ranges;
};

/// nav_msgs/Odometry: the pose and the planar twist.
struct OdometryFields {
  StampFields stamp;
  double x_m = 0.0, y_m = 0.0;
  QuaternionFields orientation;
  double linear_x_mps = 0.0;
  double angular_z_radps = 0.0;
};

/// One geometry_msgs/TransformStamped of a tf2_msgs/TFMessage.
struct TransformFields {
  StampFields stamp;
  std::string parent_frame;
  std::string child_frame;
  double x_m = 0.0, y_m = 0.0;
  QuaternionFields rotation;
};

/// sec.nsec as the double nearest to that decimal (what a text log holds).
double StampSeconds(const StampFields& stamp);

/// Which of keyplace's messages a bag message is.
enum class BagMessageKind { kNone, kScan, kOdometry, kTransforms };

class BagMessageSink {
 public:
  /// `path` names the bag in errors; `types` are the format's type names.
  BagMessageSink(const std::string& path, const BagInputConfig& config, double max_coordinate_m,
                 const BagTypeNames& types);

  /// The topics whose messages are read.
  std::set<std::string> Topics() const;

  /// What a message of `type` on `topic` is; a type other than the topic's expected one is
  /// noted for the topic's error (AssembleBagLog) and gives kNone.
  BagMessageKind Classify(const std::string& topic, const std::string& type);

  /// The 1-based number the next message of `kind` gets (for errors naming a message).
  std::size_t NextNumber(BagMessageKind kind) const;

  /// Throws std::invalid_argument: message `number` on `topic` cannot be decoded (`why`).
  [[noreturn]] void Damaged(const std::string& topic, std::size_t number,
                            const std::string& why) const;

  /// `receive_s` is the recorder's time of the message.
  void AddScan(const std::string& topic, const ScanFields& scan, double receive_s);
  void AddOdometry(const std::string& topic, const OdometryFields& odometry, double receive_s);
  void AddTransforms(const std::string& topic, const std::vector<TransformFields>& transforms);

  BagContents& contents() { return contents_; }
  void Reset() { contents_ = BagContents(); }

 private:
  // A finite heading and a position within +-max_coordinate_m.
  void CheckPose(const std::string& topic, std::size_t number, double x_m, double y_m,
                 double yaw_rad) const;

  const std::string& path_;
  const BagInputConfig& config_;
  double max_coordinate_m_;
  const BagTypeNames& types_;
  BagContents contents_;
};

}  // namespace keyplace
