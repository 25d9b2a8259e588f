#pragma once
// How well `keyplace merge` placed map B in map A, against corrected poses (docs/MERGE.md). Both
// maps come from one log (e.g. its two halves, each mapped in a frame of its own); the corrected
// poses of that log say where each scan truly is.
//
// Each map's frame drifts away from the truth along its own trajectory (ICP or odometry poses),
// so "the true T_a_b" depends on where it is looked at. It is looked at through a pair of scans
// (scan_a of A, scan_b of B) that have corrected poses C: seen from scan_a, B's scan lies at
// C(scan_a)^-1 C(scan_b), so in A's frame it truly lies at P_A(scan_a) C(scan_a)^-1 C(scan_b)
// (P: the map's pose of the scan), while the merge puts it at T_a_b P_B(scan_b). The error is the
// difference of these two poses. Two pairs are reported:
// - at the origins: the first scan of A and of B that have a corrected pose (the maps' first
//   scans, i.e. their origins, when those have one): the frame of B in the frame of A, including
//   both sessions' drift from their start to where they overlap;
// - at each agreeing recognition: the first scans with a corrected pose of its A and B submaps:
//   the error of the merged map where the two sessions meet, free of the drift from the start
//   but not of the drift along B between its recognised submaps (one rigid transform moves all
//   of B); beside it, the error of that recognition's own transform (the place recognition
//   alone).

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relation_error.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

/// Where the merge puts B's scan `scan_b` in A's frame against where it truly lies, seen from A's
/// scan `scan_a`.
struct MergePlacementError {
  int scan_a = -1;  // scan indices of the log's file (as in the maps)
  int scan_b = -1;
  int submap_a = -1;  // ids in A and in B (not the merged map's)
  int submap_b = -1;
  Pose2 estimated_T_a_scan_b;  // T_a_b * P_B(scan_b)
  Pose2 true_T_a_scan_b;       // P_A(scan_a) * C(scan_a)^-1 * C(scan_b)
  PoseError error;             // RelativePoseError(estimated, true)
  // The same with the recognition's own T_a_b (SubmapRecognition::T_a_b) instead of the fitted
  // one; equal to `error` at the origins.
  PoseError recognition_error;
};

struct MergeEvaluation {
  MergePlacementError at_origins;
  std::vector<MergePlacementError> at_recognitions;  // agreeing recognitions with truth poses
  std::size_t recognitions_without_truth = 0;  // agreeing ones whose submaps have no truth scan
  ErrorStats at_recognitions_stats;            // Summarize of at_recognitions' errors
  ErrorStats recognitions_alone_stats;         // ... and of their recognition_error
};

/// Throws std::invalid_argument when map A or B was made from another log than the one whose
/// fingerprint is `log_hash` (CarmenLog::fingerprint): what EvaluateMerge checks first, to be
/// called before the long merge. Maps without a fingerprint (older files) and an empty
/// `log_hash` pass.
void CheckMergeTruthSource(const GlobalMap& a, const GlobalMap& b, const std::string& log_hash);

/// Evaluates `result` (MergeMaps(a, b, ...)) against `truth`: the corrected poses of the log both
/// maps were made from, loaded for the whole file (first_scan 0) so that its scan numbers are the
/// maps' scan indices (LoadGroundTruth(log, 0, file_scans, ...)). `log_hash`: the fingerprint of
/// that log (CarmenLog::fingerprint), or empty not to check. Throws std::invalid_argument when a
/// map was made from another log (its source_hash is not `log_hash`), or when A or B holds no
/// scan with a truth pose.
MergeEvaluation EvaluateMerge(const GlobalMap& a, const GlobalMap& b, const MergeResult& result,
                              const GroundTruth& truth, const std::string& log_hash = "");

}  // namespace keyplace
