#include "keyplace/localization/map_merge.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "keyplace/place/place_recognizer.hpp"
#include "mapping/map_numbering.hpp"

namespace keyplace {
namespace {

constexpr double kRadPerDegree = M_PI / 180.0;
constexpr int kIdBlock = 1000;

struct Candidate {
  SubmapRecognition recognition;
  Pose2 T_b_submap;  // the recognised B submap's origin in B's frame
};

std::vector<Candidate> RecogniseSubmaps(const GlobalMap& a, const GlobalMap& b,
                                        const PlaceRecognitionConfig& place,
                                        const MergeProgress& progress, std::size_t& queried) {
  const PlaceRecognizer recognizer(PlacesFromMap(a), place);
  const std::vector<Place> b_places = PlacesFromMap(b);
  const auto to_query = static_cast<std::size_t>(std::count_if(
      b_places.begin(), b_places.end(), [](const Place& p) { return !p.positions.empty(); }));
  std::vector<Candidate> candidates;
  for (const Place& query_place : b_places) {
    if (query_place.positions.empty()) continue;
    ++queried;
    PlaceQuery query;
    query.positions = query_place.positions;
    query.descriptors = query_place.descriptors;
    const PlaceMatch match = recognizer.Recognize(query);
    if (progress) progress(queried, to_query);
    if (!match.found) continue;
    const Place& matched = recognizer.places()[static_cast<std::size_t>(match.place_index)];
    // A's submap origin * (B submap origin in its frame) = B submap origin in A's frame.
    const Pose2 T_a_bsubmap = matched.T_world_place * match.T_ref_cur;
    Candidate candidate;
    candidate.recognition.submap_b = query_place.id;
    candidate.recognition.submap_a = match.place_id;
    candidate.recognition.confidence = match.confidence;
    candidate.recognition.T_a_b = T_a_bsubmap * query_place.T_world_place.inverse();
    candidate.T_b_submap = query_place.T_world_place;
    candidates.push_back(candidate);
  }
  return candidates;
}

bool Agree(const Candidate& x, const Candidate& y, const MergeOptions& options) {
  const Pose2 in_x = x.recognition.T_a_b * y.T_b_submap;
  const Pose2 in_y = y.recognition.T_a_b * y.T_b_submap;
  return std::hypot(in_x.x - in_y.x, in_x.y - in_y.y) <= options.agree_m &&
         std::abs(WrapAngle(in_x.theta - in_y.theta)) <= options.agree_deg * kRadPerDegree;
}

// Indices of the largest group of candidates agreeing with one of them (ties: the first).
std::vector<std::size_t> LargestAgreeingGroup(const std::vector<Candidate>& candidates,
                                              const MergeOptions& options) {
  std::vector<std::size_t> best;
  for (const Candidate& centre : candidates) {
    std::vector<std::size_t> group;
    for (std::size_t j = 0; j < candidates.size(); ++j) {
      if (Agree(centre, candidates[j], options)) group.push_back(j);
    }
    if (group.size() > best.size()) best = group;
  }
  return best;
}

// Mean heading of the group's transforms, then the translation that best maps the group's B
// submap origins onto where their recognitions put them.
Pose2 FitTransform(const std::vector<Candidate>& candidates,
                   const std::vector<std::size_t>& group) {
  double sin_sum = 0.0;
  double cos_sum = 0.0;
  Eigen::Vector2d origins_b = Eigen::Vector2d::Zero();
  Eigen::Vector2d origins_a = Eigen::Vector2d::Zero();
  for (const std::size_t k : group) {
    const Candidate& candidate = candidates[k];
    sin_sum += std::sin(candidate.recognition.T_a_b.theta);
    cos_sum += std::cos(candidate.recognition.T_a_b.theta);
    origins_b += candidate.T_b_submap.translation();
    origins_a += (candidate.recognition.T_a_b * candidate.T_b_submap).translation();
  }
  const double count = static_cast<double>(group.size());
  const Pose2 T_rotation(0.0, 0.0, std::atan2(sin_sum, cos_sum));
  const Eigen::Vector2d translation =
      origins_a / count - T_rotation * Eigen::Vector2d(origins_b / count);
  return {translation.x(), translation.y(), T_rotation.theta};
}

// B is taken by value: its submaps move into the result instead of being copied a second time.
GlobalMap Joined(const GlobalMap& a, GlobalMap b_in_a) {
  GlobalMap merged = a;
  const MapNumbering numbering_a = NumberingOf(a);
  const MapNumbering numbering_b = NumberingOf(b_in_a);
  const int id_offset = (numbering_a.last_id / kIdBlock + 2) * kIdBlock - numbering_b.first_id;
  const int scan_offset = numbering_a.last_scan + 1 - numbering_b.first_scan;
  for (Submap& submap : b_in_a.submaps) {
    submap.id += id_offset;
    for (int& scan : submap.scan_indices) scan += scan_offset;
    for (StableKeypoint& keypoint : submap.keypoints) keypoint.scan_index += scan_offset;
    merged.submaps.push_back(std::move(submap));
  }
  merged.source_log = a.source_log + " + " + b_in_a.source_log;
  merged.source_hash.clear();
  merged.source_scans = a.source_scans + b_in_a.source_scans;
  merged.source_keypoints = a.source_keypoints + b_in_a.source_keypoints;
  if (a.pose_source != b_in_a.pose_source) merged.pose_source = "merged";
  return merged;
}

}  // namespace

GlobalMap MovedMap(const GlobalMap& map, const Pose2& T_new_old) {
  GlobalMap moved = map;
  for (Submap& submap : moved.submaps) {
    for (Pose2& pose : submap.poses) pose = T_new_old * pose;
  }
  return moved;
}

MergeResult MergeMaps(const GlobalMap& a, const GlobalMap& b, const PlaceRecognitionConfig& place,
                      const MergeOptions& options, const MergeProgress& progress) {
  Validate(options);
  const auto settings_a = ToKeyValues(a.config);
  const auto settings_b = ToKeyValues(b.config);
  for (std::size_t k = 0; k < settings_a.size(); ++k) {
    if (settings_a[k] != settings_b[k]) {
      throw std::invalid_argument("the maps were made with different mapping settings (mapping." +
                                  settings_a[k].first + " = " + settings_a[k].second + " for " +
                                  a.source_log + ", " + settings_b[k].second + " for " +
                                  b.source_log + "): their keypoints cannot be compared");
    }
  }
  MergeResult result;
  std::vector<Candidate> candidates = RecogniseSubmaps(a, b, place, progress, result.queried);
  const std::vector<std::size_t> group = LargestAgreeingGroup(candidates, options);
  if (static_cast<int>(group.size()) < options.min_agreeing) {
    throw std::invalid_argument(
        "no reliable overlap: " + std::to_string(candidates.size()) + " of " +
        std::to_string(result.queried) + " submaps of " + b.source_log + " were recognised in " +
        a.source_log + ", and the largest group agreeing on where it lies has " +
        std::to_string(group.size()) + " (at least " + std::to_string(options.min_agreeing) +
        " needed): are they the same building?");
  }
  result.T_a_b = FitTransform(candidates, group);
  result.agreeing = group.size();
  for (const std::size_t k : group) candidates[k].recognition.agrees = true;
  for (const Candidate& candidate : candidates)
    result.recognitions.push_back(candidate.recognition);
  result.merged = Joined(a, MovedMap(b, result.T_a_b));
  return result;
}

}  // namespace keyplace
