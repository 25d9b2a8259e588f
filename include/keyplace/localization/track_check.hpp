#pragma once
// Whether the robot's latest scans still fit the map where the fix puts them: the dense check
// that vets every answer (place/dense_check.hpp), applied to the track between answers. Answers
// come every metre or less where places are recognised, but odometry can fail between them (a
// wheel slip, a fast turn with a heading jump): the fix then drifts off the map while the filter,
// which only hears answers, keeps reporting it. The scans see it at once: their beams stop ending
// on the map's walls, or pass through them.
//
// The verdict uses the same veto thresholds as the answers (PlaceRecognitionConfig::
// dense_min_hit_fraction, dense_max_see_through) on the latest kDenseQueryScans scans, against
// the occupancy of every map place whose occupied area holds the robot's position: all the map
// saw around it. (One place and its neighbours, as for an answer, left the walls the robot faces
// now out whenever those places had looked the other way: on FR079 and Intel with perfect
// odometry that gave up 5 and 13 right fixes over 100 starts.) Consecutive verdicts are on
// disjoint scans.

#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/place/dense_check.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

enum class TrackFit {
  kUnknown,  // no verdict: not due, the check is off, or too few beams fell on mapped ground
  kFits,     // the scans fit the map at the fix
  kMisfit,   // they do not: too few beams end on the map's walls, or too many pass through them
};

class TrackCheck {
 public:
  /// Adds the next scan with the robot's pose in its odometry frame.
  void AddScan(const LaserScan& scan, const Pose2& T_odom_robot);

  /// The verdict on the latest scans put into the map by T_world_odom, when kDenseQueryScans
  /// scans were added since the last verdict (else kUnknown). `places` with their occupancy
  /// (PlacesFromMap), `config` the recognizer's: its veto thresholds.
  TrackFit Check(const std::vector<Place>& places, const PlaceRecognitionConfig& config,
                 const Pose2& T_world_odom);

  /// The dense score of the last verdict (kFits or kMisfit).
  const DenseScore& last_score() const { return last_score_; }

  void Reset();

 private:
  // The places whose occupied area (world bounding box of their occupied cells) holds
  // `position_m` (world).
  std::vector<int> PlacesAround(const std::vector<Place>& places,
                                const Eigen::Vector2d& position_m);

  std::deque<QueryScanPoints> scans_;  // the latest ones, in the odometry frame
  Pose2 last_T_odom_robot_;
  std::size_t scans_since_check_ = 0;
  std::vector<Eigen::AlignedBox2d> areas_;  // per place, world frame (empty: no occupancy)
  std::vector<int> reference_places_;       // of reference_, the first giving its frame
  std::optional<DenseReference> reference_;
  DenseScore last_score_;
};

}  // namespace keyplace
