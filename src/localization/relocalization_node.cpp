#include "keyplace/localization/relocalization_node.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

#include "common/fixed_text.hpp"
#include "common/latency_window.hpp"
#include "common/period.hpp"
#include "io/atomic_file.hpp"

namespace keyplace {
RelocalizationNode::RelocalizationNode(const GlobalMap& map, const Config& config)
    : config_([&] {
        Validate(config);
        return config;
      }()),
      relocalizer_(map, ToLocalizerConfig(config_), config_.features),
      sync_(config_.input, config_.node.odometry_wait_s) {
  // A search of a large map takes seconds: the robot's scans go on meanwhile.
  relocalizer_.set_background_search(true);
}

NodeOutput RelocalizationNode::AddOdometry(const OdometryInput& odometry) {
  NodeOutput output;
  Release(sync_.AddOdometry(odometry), output);
  if (std::isfinite(odometry.stamp_s)) RepublishIfDue(odometry.stamp_s, false, output);
  return output;
}

NodeOutput RelocalizationNode::AddScan(const ScanInput& scan) {
  NodeOutput output;
  Release(sync_.AddScan(scan), output);
  if (std::isfinite(scan.stamp_s)) RepublishIfDue(scan.stamp_s, false, output);
  return output;
}

NodeOutput RelocalizationNode::Tick(double now_s) {
  // No scan is dropped by the clock: a busy wrapper's clock runs ahead of the messages still
  // queued for it, and a scan's odometry may be among them. Waiting scans are dropped by the
  // stamps of later scans (Drain).
  NodeOutput output;
  if (std::isfinite(now_s)) RepublishIfDue(now_s, true, output);
  return output;
}

NodeOutput RelocalizationNode::Relocalize() {
  NodeOutput output;
  relocalizer_.Reset();
  last_T_odom_robot_.reset();
  status_.status = FixStatus::kSearching;
  status_.confidence = 0.0;
  status_.unconfirmed_m = 0.0;
  status_.pose.reset();
  output.events.push_back({NodeEventLevel::kInfo, "relocalize: fix forgotten, searching again"});
  output.status_due = true;
  return output;
}

void RelocalizationNode::Release(const SyncOutput& synced, NodeOutput& output) {
  output.events.insert(output.events.end(), synced.events.begin(), synced.events.end());
  for (const SyncedScan& next : synced.scans) Process(next.scan, next.T_odom_robot, output);
}

void RelocalizationNode::Process(const LaserScan& scan, const Pose2& T_odom_robot,
                                 NodeOutput& output) {
  const std::string at = "scan at " + StampText(scan.timestamp_s);
  if (last_T_odom_robot_) {
    // A step longer than lost_after_m would lose any fix unconfirmed: the odometry frame jumped
    // (a reset, a glitch), and neither the fix nor the query built so far hold across it.
    const double step_m = TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
    if (step_m > config_.localization.fix.lost_after_m) {
      output.events.push_back(
          {NodeEventLevel::kWarning,
           at + ": the odometry moved " + FixedText(step_m) + " m since the previous scan (more " +
               "than localization.fix.lost_after_m): fix and query forgotten, searching again"});
      if (status_.status == FixStatus::kFixed) ++status_.losses;
      relocalizer_.Reset();
      status_.status = FixStatus::kSearching;
      status_.confidence = 0.0;
      status_.pose.reset();
      output.status_due = true;
    }
  }
  last_T_odom_robot_ = T_odom_robot;

  const auto start = std::chrono::steady_clock::now();
  RelocalizationUpdate update;
  try {
    update = relocalizer_.AddScan(scan, T_odom_robot);
  } catch (const std::exception& error) {
    // A scan the localizer cannot take leaves its query in an unknown state: start a new one.
    relocalizer_.Reset();
    Drop(at + " dropped: " + error.what() + "; searching again", output);
    status_.status = FixStatus::kSearching;
    status_.pose.reset();
    output.status_due = true;
    return;
  }
  const double latency_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  AddLatency(latency_s, kLatencyWindow, latencies_s_);
  ++status_.scans_processed;
  status_.last_scan_stamp_s = scan.timestamp_s;
  output.scans.push_back({scan.timestamp_s, latency_s, update.status,
                          update.answer.has_value() || update.map_search_answer.has_value()});
  Publish(update, scan.timestamp_s, output);
}

void RelocalizationNode::Publish(const RelocalizationUpdate& update, double stamp_s,
                                 NodeOutput& output) {
  const std::string at = "scan at " + StampText(stamp_s);
  if (update.status != status_.status) output.status_due = true;
  status_.status = update.status;
  status_.confidence = update.status == FixStatus::kFixed ? update.confidence : 0.0;
  status_.unconfirmed_m = update.unconfirmed_m;
  // The search's answer was judged last: it is the last answer.
  for (const bool map_search : {false, true}) {
    const std::optional<LocalizationResult>& answer =
        map_search ? update.map_search_answer : update.answer;
    if (!answer) continue;
    ++status_.answers;
    status_.last_answer =
        NodeAnswer{stamp_s,           answer->found, answer->ambiguous,    answer->confidence,
                   answer->submap_id, map_search,    answer->T_world_robot};
    output.status_due = true;
  }
  if (update.lost) {
    ++status_.losses;
    output.events.push_back({NodeEventLevel::kWarning,
                             at + (update.track_misfit ? ": fix lost (the scans no longer fit the "
                                                         "map there: odometry error?)"
                                                       : ": fix lost")});
  }
  if (update.status != FixStatus::kFixed) {
    status_.pose.reset();
    return;
  }
  status_.T_world_odom = update.T_world_odom;
  status_.pose = InitialPoseOf(update, config_.node.map_frame);
  const NodePublish publish = config_.node.publish;
  if (update.new_fix) {
    ++status_.fixes;
    output.events.push_back(
        {NodeEventLevel::kInfo, at + ": fixed at " + PoseText(update.T_world_robot) +
                                    ", confidence " + FixedText(update.confidence)});
    if (publish != NodePublish::kMapToOdom)
      output.initial_poses.push_back({stamp_s, *status_.pose});
  }
  if (publish != NodePublish::kInitialPose) {
    output.transforms.push_back(
        {stamp_s, config_.node.map_frame, config_.input.odom_frame, update.T_world_odom});
    last_transform_s_ = stamp_s;
  }
}

void RelocalizationNode::RepublishIfDue(double now_s, bool clock, NodeOutput& output) {
  if (PeriodElapsed(last_status_s_, now_s, config_.node.status_period_s)) {
    last_status_s_ = now_s;
    output.status_due = true;
  }
  if (clock && status_.status == FixStatus::kFixed &&
      config_.node.publish != NodePublish::kInitialPose &&
      PeriodElapsed(last_transform_s_, now_s, config_.node.status_period_s)) {
    output.transforms.push_back(
        {now_s, config_.node.map_frame, config_.input.odom_frame, status_.T_world_odom});
    last_transform_s_ = now_s;
  }
}

void RelocalizationNode::Drop(const std::string& why, NodeOutput& output) {
  ++scans_failed_;
  output.events.push_back({NodeEventLevel::kWarning, why});
}

NodeStatus RelocalizationNode::status() const {
  NodeStatus status = status_;
  status.scans_received = sync_.scans_received();
  status.scans_dropped = sync_.scans_dropped() + scans_failed_;
  status.scans_waiting = sync_.scans_waiting();
  status.odometry_dropped = sync_.odometry_dropped();
  const LatencySummary latency = SummarizeLatencies(latencies_s_);
  status.latency_mean_s = latency.mean_s;
  status.latency_p99_s = latency.p99_s;
  status.latency_max_s = latency.max_s;
  const MapSearch& search = relocalizer_.map_search();
  status.map_searches = search.searches();
  if (search.searches() > 0) {
    status.map_search_mean_s = search.search_s() / static_cast<double>(search.searches());
  }
  return status;
}

std::string RelocalizationNode::StatusYaml() const {
  const NodeStatus s = status();
  std::ostringstream yaml;
  yaml << std::setprecision(std::numeric_limits<double>::max_digits10);
  yaml << "status: " << ToString(s.status) << "\n";
  yaml << "confidence: " << s.confidence << "\n";
  if (s.pose) {
    yaml << "pose: {frame_id: " << s.pose->frame_id << ", x: " << s.pose->T_map_robot.x
         << ", y: " << s.pose->T_map_robot.y << ", theta: " << s.pose->T_map_robot.theta << "}\n";
    yaml << "covariance_xytheta: [";
    for (int i = 0; i < 9; ++i) yaml << (i ? ", " : "") << s.pose->covariance(i / 3, i % 3);
    yaml << "]\n";
    yaml << "T_map_odom: {x: " << s.T_world_odom.x << ", y: " << s.T_world_odom.y
         << ", theta: " << s.T_world_odom.theta << "}\n";
    yaml << "unconfirmed_m: " << s.unconfirmed_m << "\n";
  }
  if (s.last_answer) {
    const NodeAnswer& a = *s.last_answer;
    yaml << "last_answer: {stamp_s: " << a.stamp_s << ", found: " << (a.found ? "true" : "false")
         << ", ambiguous: " << (a.ambiguous ? "true" : "false") << ", confidence: " << a.confidence
         << ", submap: " << a.submap_id
         << ", source: " << (a.map_search ? "map_search" : "keypoints")
         << ", x: " << a.T_world_robot.x << ", y: " << a.T_world_robot.y
         << ", theta: " << a.T_world_robot.theta << "}\n";
  }
  yaml << "last_scan_stamp_s: " << s.last_scan_stamp_s << "\n";
  yaml << "scans_received: " << s.scans_received << "\n";
  yaml << "scans_processed: " << s.scans_processed << "\n";
  yaml << "scans_dropped: " << s.scans_dropped << "\n";
  yaml << "scans_waiting: " << s.scans_waiting << "\n";
  yaml << "odometry_dropped: " << s.odometry_dropped << "\n";
  yaml << "answers: " << s.answers << "\n";
  yaml << "fixes: " << s.fixes << "\n";
  yaml << "losses: " << s.losses << "\n";
  yaml << "latency_mean_s: " << s.latency_mean_s << "\n";
  yaml << "latency_p99_s: " << s.latency_p99_s << "\n";
  yaml << "latency_max_s: " << s.latency_max_s << "\n";
  yaml << "map_searches: " << s.map_searches << "\n";
  yaml << "map_search_mean_s: " << s.map_search_mean_s << "\n";
  return yaml.str();
}

void RelocalizationNode::SaveStatus(const std::string& path) const {
  const std::string text = StatusYaml();
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace keyplace
