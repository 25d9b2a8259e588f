#pragma once
// The place-recognition query of a submap (paper Algorithm 4): shared by `keyplace localize` and
// `keyplace sweep place` so that both evaluate exactly the same queries.

#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/submap.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// The query of `submap` (built from `sequence`): its stable keypoints in the submap frame,
/// p_c = the pose of `evaluated_scan` relative to P_c[0], and, for QueryKeypoints::kAllScans,
/// every keypoint of every scan of the submap in the submap frame, latest scans first (so that
/// merging keeps their keypoints).
PlaceQuery MakeSubmapQuery(const Submap& submap, const ScanSequence& sequence, int evaluated_scan,
                           PlaceRecognitionConfig::QueryKeypoints query_keypoints);

}  // namespace keyplace
