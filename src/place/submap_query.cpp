#include "place/submap_query.hpp"

namespace keyplace {

PlaceQuery MakeSubmapQuery(const Submap& submap, const ScanSequence& sequence, int evaluated_scan,
                           PlaceRecognitionConfig::QueryKeypoints query_keypoints) {
  PlaceQuery query;
  query.positions.reserve(submap.keypoints.size());
  query.descriptors.reserve(submap.keypoints.size());
  for (const StableKeypoint& keypoint : submap.keypoints) {
    query.positions.push_back(keypoint.position_m);
    query.descriptors.push_back(keypoint.descriptor);
  }
  query.T_first_evaluated = Between(submap.origin(), sequence.poses[evaluated_scan]);
  if (query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans) {
    for (auto it = submap.scan_indices.rbegin(); it != submap.scan_indices.rend(); ++it) {
      const Pose2 T_first_laser =
          Between(submap.origin(), sequence.poses[*it]) * sequence.scans[*it].T_robot_laser;
      for (const Keypoint& keypoint : sequence.keypoints[*it]) {
        query.all_positions.push_back(T_first_laser * keypoint.position_m);
        query.all_descriptors.push_back(keypoint.descriptor);
      }
    }
  }
  return query;
}

}  // namespace keyplace
