#include "keyplace/localization/query_builder.hpp"

#include <utility>

#include "keyplace/place/dense_check.hpp"

namespace keyplace {

SubmapQueryBuilder::SubmapQueryBuilder(const MappingConfig& mapping) : mapper_(mapping) {}

bool SubmapQueryBuilder::AddScan(const LaserScan& scan, const Pose2& T_frame_robot,
                                 std::vector<Keypoint> keypoints, int scan_id) {
  // The mapper sees the scan's position in the query as its index: increasing, as in the map.
  const bool complete =
      mapper_.AddScan(static_cast<int>(scans_.size()), scan, T_frame_robot, keypoints);
  scans_.push_back(
      {scan_id, T_frame_robot, scan.T_robot_laser, std::move(keypoints), DenseScanPoints(scan)});
  return complete;
}

PlaceQuery SubmapQueryBuilder::Query(std::size_t evaluated_position,
                                     PlaceRecognitionConfig::QueryKeypoints query_keypoints) const {
  const Submap submap = mapper_.Snapshot();
  const Pose2& T_frame_origin = scans_.front().T_frame_robot;
  PlaceQuery query;
  query.positions.reserve(submap.keypoints.size());
  query.descriptors.reserve(submap.keypoints.size());
  for (const StableKeypoint& keypoint : submap.keypoints) {
    query.positions.push_back(keypoint.position_m);
    query.descriptors.push_back(keypoint.descriptor);
  }
  query.T_first_evaluated = Between(T_frame_origin, scans_[evaluated_position].T_frame_robot);
  if (query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans) {
    // Latest scans first, so that merging near-duplicates keeps their keypoints.
    for (auto it = scans_.rbegin(); it != scans_.rend(); ++it) {
      const Pose2 T_origin_laser = Between(T_frame_origin, it->T_frame_robot) * it->T_robot_laser;
      for (const Keypoint& keypoint : it->keypoints) {
        query.all_positions.push_back(T_origin_laser * keypoint.position_m);
        query.all_descriptors.push_back(keypoint.descriptor);
      }
    }
  }
  const std::size_t first_dense =
      evaluated_position + 1 > kDenseQueryScans ? evaluated_position + 1 - kDenseQueryScans : 0;
  for (std::size_t k = first_dense; k <= evaluated_position; ++k) {
    query.scans.push_back(
        InQueryFrame(scans_[k].points, Between(T_frame_origin, scans_[k].T_frame_robot)));
  }
  return query;
}

void SubmapQueryBuilder::Reset() {
  mapper_.Reset();
  scans_.clear();
}

std::vector<int> SubmapQueryBuilder::scan_ids() const {
  std::vector<int> ids;
  ids.reserve(scans_.size());
  for (const Buffered& scan : scans_) ids.push_back(scan.scan_id);
  return ids;
}

}  // namespace keyplace
