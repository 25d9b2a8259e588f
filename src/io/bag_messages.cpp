#include "io/bag_messages.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/shown_text.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {
namespace {

// Longer frame ids are damage, not names: each scan keeps its frame id, and a 1 MB one made a bag
// cost 1.35 GB.
constexpr std::size_t kMaxFrameIdBytes = 1024;

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

// A number in a message: six significant digits (1e+30, not 31 digits of std::to_string).
std::string Shown(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", value);
  return text;
}

double Yaw(const QuaternionFields& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

}  // namespace

double StampSeconds(const StampFields& stamp) {
  // A damaged or negative stamp has no decimal spelling worth keeping: plain arithmetic.
  if (stamp.sec < 0 || stamp.nsec >= 1000000000U) {
    return static_cast<double>(stamp.sec) + 1e-9 * static_cast<double>(stamp.nsec);
  }
  char text[48];
  const int length =
      std::snprintf(text, sizeof(text), "%lld.%09u", static_cast<long long>(stamp.sec), stamp.nsec);
  double result = 0.0;
  std::from_chars(text, text + length, result);
  return result;
}

BagMessageSink::BagMessageSink(const std::string& path, const BagInputConfig& config,
                               double max_coordinate_m, const BagTypeNames& types)
    : path_(path), config_(config), max_coordinate_m_(max_coordinate_m), types_(types) {}

std::set<std::string> BagMessageSink::Topics() const {
  return {config_.scan_topic, config_.odom_topic, kTfTopic, kTfStaticTopic};
}

BagMessageKind BagMessageSink::Classify(const std::string& topic, const std::string& type) {
  BagMessageKind kind = BagMessageKind::kTransforms;
  std::string expected = types_.transforms;
  if (topic == config_.scan_topic) {
    kind = BagMessageKind::kScan;
    expected = types_.scan;
  } else if (topic == config_.odom_topic) {
    kind = BagMessageKind::kOdometry;
    expected = types_.odometry;
  } else if (topic != kTfTopic && topic != kTfStaticTopic) {
    return BagMessageKind::kNone;
  }
  if (type != expected) {
    contents_.wrong_types.try_emplace(topic, type);
    return BagMessageKind::kNone;
  }
  return kind;
}

std::size_t BagMessageSink::NextNumber(BagMessageKind kind) const {
  switch (kind) {
    case BagMessageKind::kScan:
      return contents_.scans.size() + 1;
    case BagMessageKind::kOdometry:
      return contents_.odometry.size() + 1;
    case BagMessageKind::kTransforms:
      return contents_.tf_messages + 1;
    case BagMessageKind::kNone:
      break;
  }
  return 0;
}

void BagMessageSink::Damaged(const std::string& topic, std::size_t number,
                             const std::string& why) const {
  throw std::invalid_argument(path_ + ": topic " + topic + ": message " + std::to_string(number) +
                              " is damaged (" + why + ")");
}

void BagMessageSink::AddScan(const std::string& topic, const ScanFields& scan, double receive_s) {
  const std::size_t number = contents_.scans.size() + 1;
  const std::string where = path_ + ": topic " + topic + ": scan " + std::to_string(number) + ": ";
  if (scan.ranges.size() > kMaxScanBeams) {
    throw std::invalid_argument(where + std::to_string(scan.ranges.size()) +
                                " beams, more than the " + std::to_string(kMaxScanBeams) +
                                " keyplace takes (downsample the scan)");
  }
  if (!(scan.range_max > 0.0F)) throw std::invalid_argument(where + "range_max must be positive");
  LogScan out;
  out.line = number;
  out.timestamp_s = StampSeconds(scan.stamp);
  out.logger_timestamp_s = receive_s;
  out.max_range_m = ShortestDecimal(scan.range_max);
  const double min_range_m = ShortestDecimal(scan.range_min);
  const std::size_t n = scan.ranges.size();
  // scan_fov_rad: spread as a FLASER line of n beams would be (FlaserSpacingOf).
  const double start_rad = config_.scan_fov_rad > 0.0 ? FlaserBeamAngle(0, n, config_.scan_fov_rad)
                                                      : ShortestDecimal(scan.angle_min);
  const double step_rad = config_.scan_fov_rad > 0.0
                              ? (n > 0 ? config_.scan_fov_rad / FlaserSteps(n) : 0.0)
                              : ShortestDecimal(scan.angle_increment);
  if (!std::isfinite(start_rad) || !std::isfinite(step_rad)) {
    throw std::invalid_argument(where + "angle_min and angle_increment must be finite");
  }
  // The bounds the CARMEN reader puts on ROBOTLASER1's angles: a start within +-2 pi, beams
  // spread over at most one turn. angle_increment 0 put every beam on one bearing, 1e30 or an
  // angle_min of 1e30 gave a "field of view" of 2e34 degrees, and all mapped with exit 0.
  if (!(std::abs(start_rad) <= 2.0 * M_PI)) {
    throw std::invalid_argument(where + "angle_min = " + Shown(start_rad) +
                                " rad is not an angle in [-2 pi, 2 pi]");
  }
  const double span_rad = std::abs(step_rad) * static_cast<double>(n > 0 ? n - 1 : 0);
  if ((n > 1 && step_rad == 0.0) || !(span_rad <= 2.0 * M_PI * (1.0 + 1e-9))) {
    throw std::invalid_argument(where + "angle_increment = " + Shown(step_rad) + " rad over " +
                                std::to_string(n) +
                                " beams does not spread them over at most one turn (it must be "
                                "nonzero, |increment| x (beams - 1) <= 2 pi)");
  }
  if (scan.frame_id.size() > kMaxFrameIdBytes) {
    throw std::invalid_argument(where + "header.frame_id '" + ShownText(scan.frame_id) +
                                "' is longer than " + std::to_string(kMaxFrameIdBytes) +
                                " bytes: not a frame id");
  }
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
  contents_.scan_frames.push_back(scan.frame_id);
}

void BagMessageSink::CheckPose(const std::string& topic, std::size_t number, double x_m, double y_m,
                               double yaw_rad) const {
  if (!std::isfinite(yaw_rad)) {
    throw std::invalid_argument(path_ + ": topic " + topic + ": message " + std::to_string(number) +
                                ": the orientation is not finite");
  }
  if (!(std::abs(x_m) <= max_coordinate_m_ && std::abs(y_m) <= max_coordinate_m_)) {
    throw std::invalid_argument(path_ + ": topic " + topic + ": message " + std::to_string(number) +
                                ": position (" + std::to_string(x_m) + ", " + std::to_string(y_m) +
                                ") m lies beyond +-" + std::to_string(max_coordinate_m_) +
                                " m or is not finite");
  }
}

void BagMessageSink::AddOdometry(const std::string& topic, const OdometryFields& odometry,
                                 double receive_s) {
  const std::size_t number = contents_.odometry.size() + 1;
  const double yaw_rad = Yaw(odometry.orientation);
  CheckPose(topic, number, odometry.x_m, odometry.y_m, yaw_rad);
  OdometryMessage out;
  out.pose = Pose2(odometry.x_m, odometry.y_m, yaw_rad);
  out.tv_mps = odometry.linear_x_mps;
  out.rv_radps = odometry.angular_z_radps;
  out.timestamp_s = StampSeconds(odometry.stamp);
  out.logger_timestamp_s = receive_s;
  contents_.odometry.push_back(out);
}

void BagMessageSink::AddTransforms(const std::string& topic,
                                   const std::vector<TransformFields>& transforms) {
  const std::size_t number = ++contents_.tf_messages;
  for (const TransformFields& t : transforms) {
    for (const std::string* frame : {&t.parent_frame, &t.child_frame}) {
      if (frame->size() > kMaxFrameIdBytes) {
        throw std::invalid_argument(path_ + ": topic " + topic + ": message " +
                                    std::to_string(number) + ": frame id '" + ShownText(*frame) +
                                    "' is longer than " + std::to_string(kMaxFrameIdBytes) +
                                    " bytes: not a frame id");
      }
    }
    const double yaw_rad = Yaw(t.rotation);
    CheckPose(topic, number, t.x_m, t.y_m, yaw_rad);
    contents_.tf.Add(t.parent_frame, t.child_frame, StampSeconds(t.stamp),
                     Pose2(t.x_m, t.y_m, yaw_rad), topic == kTfStaticTopic);
  }
}

}  // namespace keyplace
