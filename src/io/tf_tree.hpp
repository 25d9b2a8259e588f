#pragma once
// Internal: the planar transforms of a bag's /tf and /tf_static, looked up along the chain of
// parent frames at any time (each dynamic edge interpolated as a PoseTrack).

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "io/pose_track.hpp"
#include "keyplace/common/pose2.hpp"

namespace keyplace {

class TfTree {
 public:
  /// One transform message: T_parent_child at `stamp_s`. A frame keeps the parent it was first
  /// given (tf is a tree); a later message naming another parent for it is ignored.
  void Add(const std::string& parent, const std::string& child, double stamp_s,
           const Pose2& T_parent_child, bool is_static);

  /// T_ancestor_frame at `stamp_s`, composed along the parents of `frame` up to `ancestor`;
  /// nothing when `ancestor` is not among them. `position` (may be null) gets where the time
  /// fell on the dynamic edges (held ends and the widest gap).
  std::optional<Pose2> Lookup(const std::string& ancestor, const std::string& frame, double stamp_s,
                              TrackPosition* position = nullptr) const;

  /// The times of the dynamic transforms on the chain from `ancestor` down to `frame`, sorted,
  /// without repeats (empty when there is no such chain or it is all static).
  std::vector<double> ChainStamps(const std::string& ancestor, const std::string& frame) const;

  /// "parent -> child" of every edge, for messages.
  std::string Describe() const;

 private:
  struct Edge {
    std::string parent;
    std::optional<Pose2> static_pose;  // /tf_static, or nothing
    std::vector<StampedPose> samples;  // /tf
    mutable std::optional<PoseTrack> track;
  };
  // The edges from `frame` up to `ancestor`, or nothing.
  std::optional<std::vector<const Edge*>> Chain(const std::string& ancestor,
                                                const std::string& frame) const;

  std::map<std::string, Edge> edge_of_child_;
};

/// A frame name as tf2 compares them: without leading slashes ("/laser" is "laser").
std::string NormalizeFrame(const std::string& frame);

}  // namespace keyplace
