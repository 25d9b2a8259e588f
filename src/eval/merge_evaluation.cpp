#include "keyplace/eval/merge_evaluation.hpp"

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace keyplace {
namespace {

// A scan of a map with its pose in the map and its truth pose.
struct AnchorScan {
  int scan = -1;
  int submap = -1;
  Pose2 P;  // T_map_robot
  Pose2 C;  // corrected T_world_robot
};

bool HasTruth(const GroundTruth& truth, int scan) {
  return scan >= 0 && truth.Has(static_cast<std::size_t>(scan));
}

// The first scan of `submap` (insertion order) with a truth pose.
std::optional<AnchorScan> FirstTruthScan(const Submap& submap, const GroundTruth& truth) {
  for (std::size_t k = 0; k < submap.scan_indices.size(); ++k) {
    const int scan = submap.scan_indices[k];
    if (HasTruth(truth, scan)) {
      return AnchorScan{scan, submap.id, submap.poses[k],
                        truth.Pose(static_cast<std::size_t>(scan))};
    }
  }
  return std::nullopt;
}

// The scan with a truth pose that comes first in the log among all of the map's scans.
AnchorScan FirstTruthScan(const GlobalMap& map, const GroundTruth& truth, const char* name) {
  std::optional<AnchorScan> first;
  for (const Submap& submap : map.submaps) {
    for (std::size_t k = 0; k < submap.scan_indices.size(); ++k) {
      const int scan = submap.scan_indices[k];
      if ((!first || scan < first->scan) && HasTruth(truth, scan)) {
        first = AnchorScan{scan, submap.id, submap.poses[k],
                           truth.Pose(static_cast<std::size_t>(scan))};
      }
    }
  }
  if (!first) {
    throw std::invalid_argument(std::string("merge evaluation: map ") + name + " (" +
                                map.source_log + ") holds no scan with a pose in " +
                                truth.truth_log);
  }
  return *first;
}

MergePlacementError Placement(const AnchorScan& in_a, const AnchorScan& in_b, const Pose2& T_a_b,
                              const Pose2& recognition_T_a_b) {
  MergePlacementError placement;
  placement.scan_a = in_a.scan;
  placement.scan_b = in_b.scan;
  placement.submap_a = in_a.submap;
  placement.submap_b = in_b.submap;
  placement.estimated_T_a_scan_b = T_a_b * in_b.P;
  placement.true_T_a_scan_b = in_a.P * Between(in_a.C, in_b.C);
  placement.error = RelativePoseError(placement.estimated_T_a_scan_b, placement.true_T_a_scan_b);
  placement.recognition_error =
      RelativePoseError(recognition_T_a_b * in_b.P, placement.true_T_a_scan_b);
  return placement;
}

void CheckSource(const GlobalMap& map, const char* name, const std::string& log_hash) {
  if (log_hash.empty() || map.source_hash.empty() || map.source_hash == log_hash) return;
  throw std::invalid_argument(std::string("merge evaluation: map ") + name + " was made from " +
                              map.source_log + " (" + map.source_hash +
                              "), not from the log of the truth (" + log_hash + ")");
}

}  // namespace

void CheckMergeTruthSource(const GlobalMap& a, const GlobalMap& b, const std::string& log_hash) {
  CheckSource(a, "A", log_hash);
  CheckSource(b, "B", log_hash);
}

MergeEvaluation EvaluateMerge(const GlobalMap& a, const GlobalMap& b, const MergeResult& result,
                              const GroundTruth& truth, const std::string& log_hash) {
  CheckMergeTruthSource(a, b, log_hash);
  MergeEvaluation evaluation;
  evaluation.at_origins = Placement(FirstTruthScan(a, truth, "A"), FirstTruthScan(b, truth, "B"),
                                    result.T_a_b, result.T_a_b);
  std::map<int, const Submap*> a_by_id;
  std::map<int, const Submap*> b_by_id;
  for (const Submap& submap : a.submaps) a_by_id[submap.id] = &submap;
  for (const Submap& submap : b.submaps) b_by_id[submap.id] = &submap;
  std::vector<double> translations_m;
  std::vector<double> rotations_deg;
  std::vector<double> alone_translations_m;
  std::vector<double> alone_rotations_deg;
  for (const SubmapRecognition& recognition : result.recognitions) {
    if (!recognition.agrees) continue;
    const auto in_a = a_by_id.find(recognition.submap_a);
    const auto in_b = b_by_id.find(recognition.submap_b);
    if (in_a == a_by_id.end() || in_b == b_by_id.end()) {
      throw std::invalid_argument("merge evaluation: recognition of B submap " +
                                  std::to_string(recognition.submap_b) + " in A submap " +
                                  std::to_string(recognition.submap_a) +
                                  " names a submap the maps do not hold");
    }
    const std::optional<AnchorScan> anchor_a = FirstTruthScan(*in_a->second, truth);
    const std::optional<AnchorScan> anchor_b = FirstTruthScan(*in_b->second, truth);
    if (!anchor_a || !anchor_b) {
      ++evaluation.recognitions_without_truth;
      continue;
    }
    const MergePlacementError& placement = evaluation.at_recognitions.emplace_back(
        Placement(*anchor_a, *anchor_b, result.T_a_b, recognition.T_a_b));
    translations_m.push_back(placement.error.translation_m);
    rotations_deg.push_back(placement.error.rotation_deg);
    alone_translations_m.push_back(placement.recognition_error.translation_m);
    alone_rotations_deg.push_back(placement.recognition_error.rotation_deg);
  }
  evaluation.at_recognitions_stats = Summarize(translations_m, rotations_deg);
  evaluation.recognitions_alone_stats = Summarize(alone_translations_m, alone_rotations_deg);
  return evaluation;
}

}  // namespace keyplace
