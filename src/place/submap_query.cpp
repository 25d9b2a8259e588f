#include "place/submap_query.hpp"

#include <cstddef>

#include "keyplace/place/dense_check.hpp"

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
  // The beams of the latest kDenseQueryScans scans up to the evaluated one (dense check), as
  // SubmapQueryBuilder::Query gives them.
  std::size_t evaluated = 0;
  while (evaluated + 1 < submap.scan_indices.size() &&
         submap.scan_indices[evaluated] != evaluated_scan) {
    ++evaluated;
  }
  const std::size_t first = evaluated + 1 > kDenseQueryScans ? evaluated + 1 - kDenseQueryScans : 0;
  for (std::size_t k = first; k <= evaluated; ++k) {
    const int scan = submap.scan_indices[k];
    query.scans.push_back(InQueryFrame(DenseScanPoints(sequence.scans[scan]),
                                       Between(submap.origin(), sequence.poses[scan])));
  }
  return query;
}

}  // namespace keyplace
