#pragma once
// The query side of paper Algorithm 4: builds a query submap from consecutive scans exactly as
// the map's submaps were built (LocalMapper with the map's mapping configuration) and turns it
// into a PlaceQuery. Keeps only what the query needs of each scan (pose, laser mounting,
// keypoints), so memory is bounded by the scans of one submap.

#include <cstddef>
#include <deque>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/mapping/local_mapper.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

class SubmapQueryBuilder {
 public:
  explicit SubmapQueryBuilder(const MappingConfig& mapping);

  /// Adds the next scan (robot pose in any fixed frame, keypoints in the laser frame, the
  /// caller's id of the scan). Returns true when the query submap is complete with it.
  bool AddScan(const LaserScan& scan, const Pose2& T_frame_robot, std::vector<Keypoint> keypoints,
               int scan_id);

  /// The query of the submap as it stands: its stable keypoints in its frame (the first scan's
  /// pose), the pose to estimate = the scan at `evaluated_position` (0-based among the added
  /// scans), for QueryKeypoints::kAllScans every keypoint of every scan, latest first, and the
  /// beams of the latest kDenseQueryScans scans up to `evaluated_position` (PlaceQuery::scans).
  PlaceQuery Query(std::size_t evaluated_position,
                   PlaceRecognitionConfig::QueryKeypoints query_keypoints) const;

  void Reset();

  std::size_t size() const { return scans_.size(); }
  bool empty() const { return scans_.empty(); }
  int scan_id(std::size_t position) const { return scans_[position].scan_id; }
  std::vector<int> scan_ids() const;
  const Pose2& pose(std::size_t position) const { return scans_[position].T_frame_robot; }

 private:
  struct Buffered {
    int scan_id = -1;
    Pose2 T_frame_robot;
    Pose2 T_robot_laser;
    std::vector<Keypoint> keypoints;
    QueryScanPoints points;  // robot frame, a subset of the beams (dense check)
  };
  LocalMapper mapper_;
  std::deque<Buffered> scans_;
};

}  // namespace keyplace
