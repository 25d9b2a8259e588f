#include "io/bag_log.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <utility>

#include "common/shown_text.hpp"
#include "io/pose_track.hpp"

namespace keyplace {
namespace {

// Scans farther than this from the odometry samples they are interpolated between (or held
// from) are counted in a warning: the pose there is a guess (fr-clinic has a 198 s gap).
constexpr double kLongOdometryGapS = 1.0;

std::string TopicList(const BagSummary& summary) {
  if (summary.topics.empty()) return "no topics";
  // Bounded: names come from the bag, and a message must not grow with them.
  constexpr std::size_t kShown = 20;
  std::string text;
  std::size_t shown = 0;
  for (const LogTopic& topic : summary.topics) {
    if (shown++ == kShown) {
      text += ", and " + std::to_string(summary.topics.size() - kShown) + " more";
      break;
    }
    text += (text.empty() ? "" : ", ") + ShownText(topic.name) + " (" + ShownText(topic.type) +
            ", " + std::to_string(topic.messages) + ")";
  }
  return text;
}

const LogTopic* FindTopic(const BagSummary& summary, const std::string& name) {
  for (const LogTopic& topic : summary.topics) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

std::string Seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", seconds);
  return text;
}

class PoseAssembler {
 public:
  PoseAssembler(const std::string& path, const BagInputConfig& config, const BagTypeNames& types,
                const BagSummary& summary, BagContents& contents)
      : path_(path), config_(config), types_(types), summary_(summary), contents_(contents) {}

  void CheckScans() const {
    const std::string& topic = config_.scan_topic;
    if (FindTopic(summary_, topic) == nullptr) {
      Fail("no topic " + topic + " (input.scan_topic, --scan-topic); " + ScanTopicHint() +
           "; the bag has " + TopicList(summary_));
    }
    CheckType(topic, types_.scan);
    if (contents_.scans.empty()) Fail("topic " + topic + " holds no scan");
  }

  // The topics of the scan type, as the flag that would read the first.
  std::string ScanTopicHint() const {
    std::string names;
    for (const LogTopic& candidate : summary_.topics) {
      if (candidate.type == types_.scan) names += (names.empty() ? "" : ", ") + candidate.name;
    }
    if (names.empty()) return std::string("no topic holds ") + types_.scan;
    return std::string(types_.scan) + " on " + names + " (--scan-topic " +
           names.substr(0, names.find(',')) + ")";
  }

  // Fills odometry_pose of every scan and CarmenLog::odometry.
  void AddOdometry(CarmenLog& log) {
    const std::string& topic = config_.odom_topic;
    if (FindTopic(summary_, topic) != nullptr) {
      CheckType(topic, types_.odometry);
      if (contents_.odometry.empty()) Fail("topic " + topic + " holds no odometry message");
      std::vector<StampedPose> samples;
      for (const OdometryMessage& message : contents_.odometry) {
        samples.push_back({message.timestamp_s, message.pose});
      }
      const PoseTrack track(std::move(samples));
      Interpolate(log,
                  [&](double stamp_s, TrackPosition* where) { return track.At(stamp_s, where); });
      log.odometry = std::move(contents_.odometry);
      return;
    }
    const std::vector<double> stamps =
        contents_.tf.ChainStamps(config_.odom_frame, config_.base_frame);
    if (stamps.empty()) {
      Fail("no odometry: no topic " + topic + " (input.odom_topic, --odom-topic) and no moving " +
           "transform chain " + config_.odom_frame + " -> " + config_.base_frame +
           " (input.odom_frame, input.base_frame) in /tf (" + contents_.tf.Describe() +
           "); the bag has " + TopicList(summary_));
    }
    const auto lookup = [&](double stamp_s, TrackPosition* where) {
      return *contents_.tf.Lookup(config_.odom_frame, config_.base_frame, stamp_s, where);
    };
    log.warnings.push_back(path_ + ": no topic " + topic + ": odometry from /tf " +
                           config_.odom_frame + " -> " + config_.base_frame);
    Interpolate(log, lookup);
    for (const double stamp_s : stamps) {
      OdometryMessage message;
      message.pose = lookup(stamp_s, nullptr);
      message.timestamp_s = message.logger_timestamp_s = stamp_s;
      log.odometry.push_back(message);
    }
  }

  // Sets T_robot_laser and logged_laser_pose of every scan.
  void AddLaserPose(CarmenLog& log) const {
    const std::optional<Pose2> given = ParseLaserPose(config_.laser_pose);
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      LogScan& scan = log.scans[i];
      if (given) {
        scan.T_robot_laser = *given;
      } else {
        const std::string& frame = contents_.scan_frames[i];
        const auto T_base_laser = contents_.tf.Lookup(config_.base_frame, frame, scan.timestamp_s);
        if (!T_base_laser) {
          Fail("no transform " + config_.base_frame + " -> " + ShownText(NormalizeFrame(frame)) +
               " (the frame of scan " + std::to_string(i + 1) + " on " + config_.scan_topic +
               ") in /tf_static or /tf (" + contents_.tf.Describe() +
               "); give the laser pose on the robot: --laser-pose x,y,theta (input.laser_pose)");
        }
        scan.T_robot_laser = *T_base_laser;
      }
      scan.logged_laser_pose = *scan.odometry_pose * scan.T_robot_laser;
    }
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::invalid_argument(path_ + ": " + what);
  }

  void CheckType(const std::string& topic, const std::string& expected) const {
    const auto wrong = contents_.wrong_types.find(topic);
    if (wrong != contents_.wrong_types.end()) {
      Fail("topic " + topic + " holds " + wrong->second + " messages, not " + expected +
           "; the bag has " + TopicList(summary_));
    }
  }

  template <class Lookup>
  void Interpolate(CarmenLog& log, const Lookup& lookup) {
    std::size_t held = 0;
    std::size_t in_gaps = 0;
    double longest_gap_s = 0.0;
    for (LogScan& scan : log.scans) {
      TrackPosition where;
      scan.odometry_pose = lookup(scan.timestamp_s, &where);
      if (where.before_first || where.after_last) ++held;
      if (where.gap_s > kLongOdometryGapS) ++in_gaps;
      longest_gap_s = std::max(longest_gap_s, where.gap_s);
    }
    std::string what;
    if (held > 0) {
      what = std::to_string(held) + " of " + std::to_string(log.scans.size()) +
             " scans lie before the first or after the last odometry sample (the end pose is "
             "held)";
    }
    if (in_gaps > 0) {
      what += (what.empty() ? "" : "; ") + std::to_string(in_gaps) + " of " +
              std::to_string(log.scans.size()) + " scans lie in odometry gaps over " +
              Seconds(kLongOdometryGapS) + " s";
    }
    if (!what.empty()) {
      log.warnings.push_back(path_ + ": " + what + "; the longest gap is " +
                             Seconds(longest_gap_s) + " s");
    }
  }

  const std::string& path_;
  const BagInputConfig& config_;
  const BagTypeNames& types_;
  const BagSummary& summary_;
  BagContents& contents_;
};

}  // namespace

CarmenLog AssembleBagLog(const std::string& path, const BagInputConfig& config,
                         const BagTypeNames& types, const BagSummary& summary,
                         BagContents&& contents) {
  PoseAssembler assembler(path, config, types, summary, contents);
  assembler.CheckScans();
  CarmenLog log;
  log.path = path;
  log.format = types.format;
  log.topics = summary.topics;
  log.warnings = summary.warnings;
  log.scans = std::move(contents.scans);
  assembler.AddOdometry(log);
  assembler.AddLaserPose(log);
  log.lines = summary.messages;
  log.invalid_beams = contents.invalid_beams;
  log.no_return_beams = contents.no_return_beams;
  return log;
}

}  // namespace keyplace
