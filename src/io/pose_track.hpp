#pragma once
// Internal: a robot's poses over time (odometry messages, one tf edge), read at any time by
// linear interpolation, the heading on the circle.

#include <cstddef>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct StampedPose {
  double stamp_s = 0.0;
  Pose2 pose;
};

/// Where a time fell relative to the samples PoseTrack::At used.
struct TrackPosition {
  bool before_first = false;  // earlier than every sample: the first pose was held
  bool after_last = false;    // later than every sample: the last pose was held
  double gap_s = 0.0;         // time between the two samples used (or to the held one)
};

class PoseTrack {
 public:
  PoseTrack() = default;
  /// Samples in any order; sorted by time (ties keep their order).
  explicit PoseTrack(std::vector<StampedPose> samples);

  bool empty() const { return samples_.empty(); }
  std::size_t size() const { return samples_.size(); }
  const std::vector<StampedPose>& samples() const { return samples_; }

  /// The pose at `stamp_s`: between the last sample before it and the first at or after it,
  /// x, y and heading interpolated linearly (the heading along the shorter turn). Outside the
  /// samples' span the nearest end is held. Requires a non-empty track.
  Pose2 At(double stamp_s, TrackPosition* position = nullptr) const;

 private:
  std::vector<StampedPose> samples_;
};

}  // namespace keyplace
