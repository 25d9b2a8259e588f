#pragma once
// Multi-session maps: where map B (another day, its own frame) lies in map A, found by
// recognising B's submaps in A, and the two joined into one map in A's frame (docs/MERGE.md).

#include <cstddef>
#include <functional>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/common/result_fields.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/place/place_config.hpp"

namespace keyplace {

struct MergeOptions {
  // The transform is accepted when at least this many of B's submaps were recognised in A with
  // transforms that agree: one recognition can be wrong, several that agree are not by chance.
  int min_agreeing = 3;
  // Two recognitions agree when they put a B submap origin within these of each other.
  double agree_m = 1.0;
  double agree_deg = 10.0;
};

/// Throws std::invalid_argument naming the first invalid field.
void Validate(const MergeOptions& options);

/// One submap of B recognised in A.
struct SubmapRecognition {
  int submap_b = 0;  // ids
  int submap_a = 0;
  double confidence = 0.0;
  Pose2 T_a_b;          // B's frame in A's frame, as this recognition alone says
  bool agrees = false;  // with the accepted transform
};

struct MergeResult {
  GlobalMap merged;         // A's submaps, then B's moved into A's frame (new ids and scan numbers)
  Pose2 T_a_b;              // B's frame in A's frame: the fit to the agreeing recognitions
  std::size_t queried = 0;  // B submaps with keypoints, each recognised against A
  std::vector<SubmapRecognition> recognitions;  // the accepted ones (PlaceMatch::found)
  std::size_t agreeing = 0;
};

/// The figures of a merge and of each recognition (T_a_b aside, a pose): the keys of `keyplace
/// merge --json` and the properties of Python's MergeResult / SubmapRecognition.
const ResultFields<MergeResult>& MergeResultFields();
const ResultFields<SubmapRecognition>& SubmapRecognitionFields();

/// Progress: (B submaps recognised, B submaps to recognise: those with keypoints), after each.
using MergeProgress = std::function<void(std::size_t, std::size_t)>;

/// Recognises every submap of B in A with `place`, takes the largest group of recognitions that
/// agree on B's frame, fits T_a_b to it (mean heading, then the least-squares translation of the
/// group's B submap origins) and joins the maps: B's ids start at the second thousand after A's
/// last (no B submap is a map neighbour of an A submap at any verification reach below 1000)
/// and its scan numbers follow A's. The merged map belongs to no
/// single log (empty source_hash). Throws std::invalid_argument when the maps were made with
/// different mapping settings, or when fewer than options.min_agreeing recognitions agree (no
/// reliable overlap: saying how many were found and how many agreed).
MergeResult MergeMaps(const GlobalMap& a, const GlobalMap& b, const PlaceRecognitionConfig& place,
                      const MergeOptions& options = {}, const MergeProgress& progress = {});

/// `map` moved rigidly: every pose P becomes T_new_old * P (keypoints and occupancy stay in their
/// submap frames).
GlobalMap MovedMap(const GlobalMap& map, const Pose2& T_new_old);

}  // namespace keyplace
