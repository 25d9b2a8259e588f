#pragma once
// Laser scans paired with the robot's odometry pose at their stamps, as a robot node receives
// them: two topics whose messages arrive in any order within the same wall time. A scan waits
// until odometry covers its stamp (the pose is interpolated there) and is dropped when a scan
// odometry_wait_s newer comes first. Nothing a sensor or a bag sends throws: an empty scan, NaN
// ranges, too many beams, a stamp that goes back, an odometry pose beyond 1e7 m, a scan without a
// laser pose are dropped with an event saying why; a scan geometry that changes is an event.

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/io/sensor_input.hpp"

namespace keyplace {

/// A scan as keyplace takes it, with the odometry pose at its stamp.
struct SyncedScan {
  LaserScan scan;
  std::string frame_id;
  Pose2 T_odom_robot;
};

/// What one call released: scans ready to process (in stamp order) and events to log.
struct SyncOutput {
  std::vector<SyncedScan> scans;
  std::vector<NodeEvent> events;
};

class SensorSync {
 public:
  /// Odometry samples kept at most: 100 s at 100 Hz while no scan comes.
  static constexpr std::size_t kMaxOdometrySamples = 10000;

  /// `input` says where the laser sits (laser_pose) and how beams are spread (scan_fov_rad).
  /// Throws std::invalid_argument naming the field for an invalid input section or a wait that
  /// is not positive.
  SensorSync(const BagInputConfig& input, double odometry_wait_s);

  /// The next odometry pose; waiting scans it covers are released.
  SyncOutput AddOdometry(const OdometryInput& odometry);
  /// The next scan: released as soon as odometry covers its stamp.
  SyncOutput AddScan(const ScanInput& scan);

  std::size_t scans_received() const { return scans_received_; }
  std::size_t scans_dropped() const { return scans_dropped_; }
  std::size_t scans_waiting() const { return pending_.size(); }
  std::size_t odometry_dropped() const { return odometry_dropped_; }

 private:
  // The scan as keyplace takes it, or nothing (with an event saying why).
  std::optional<LaserScan> Convert(const ScanInput& input, SyncOutput& output);
  void NoteGeometry(const ScanInput& input, const Pose2& T_robot_laser, SyncOutput& output);
  // Releases the waiting scans that odometry covers now.
  void Drain(SyncOutput& output);
  // The odometry pose at `stamp_s`, when the samples cover it.
  std::optional<Pose2> OdometryAt(double stamp_s) const;
  void Drop(const std::string& why, SyncOutput& output);

  struct PendingScan {
    LaserScan scan;
    std::string frame_id;
  };

  BagInputConfig input_;
  double odometry_wait_s_ = 1.0;
  std::optional<Pose2> laser_pose_override_;
  std::deque<OdometryInput> odometry_;       // in stamp order, trimmed to what waiting scans need
  std::deque<PendingScan> pending_;          // scans waiting for odometry, in stamp order
  std::optional<double> last_scan_stamp_s_;  // of the last scan accepted (waiting or released)
  std::optional<ScanInput> geometry_;        // the last scan's geometry (its ranges left empty)
  std::size_t scans_received_ = 0;
  std::size_t scans_dropped_ = 0;
  std::size_t odometry_dropped_ = 0;
};

/// Stamps in log messages: seconds with 6 decimals.
std::string StampText(double stamp_s);

}  // namespace keyplace
