#include "io/pose_track.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace keyplace {

PoseTrack::PoseTrack(std::vector<StampedPose> samples) : samples_(std::move(samples)) {
  std::stable_sort(
      samples_.begin(), samples_.end(),
      [](const StampedPose& a, const StampedPose& b) { return a.stamp_s < b.stamp_s; });
}

Pose2 PoseTrack::At(double stamp_s, TrackPosition* position) const {
  TrackPosition where;
  const auto after =
      std::lower_bound(samples_.begin(), samples_.end(), stamp_s,
                       [](const StampedPose& sample, double t) { return sample.stamp_s < t; });
  Pose2 pose;
  if (after == samples_.begin()) {
    where.before_first = stamp_s < samples_.front().stamp_s;
    where.gap_s = samples_.front().stamp_s - stamp_s;
    pose = samples_.front().pose;
  } else if (after == samples_.end()) {
    where.after_last = true;
    where.gap_s = stamp_s - samples_.back().stamp_s;
    pose = samples_.back().pose;
  } else {
    const StampedPose& first = *(after - 1);
    const StampedPose& second = *after;
    where.gap_s = second.stamp_s - first.stamp_s;
    const double weight = where.gap_s > 0.0 ? (stamp_s - first.stamp_s) / where.gap_s : 0.0;
    const double turn_rad = WrapAngle(second.pose.theta - first.pose.theta);
    pose = Pose2(first.pose.x + weight * (second.pose.x - first.pose.x),
                 first.pose.y + weight * (second.pose.y - first.pose.y),
                 first.pose.theta + weight * turn_rad);
  }
  if (position != nullptr) *position = where;
  return pose;
}

}  // namespace keyplace
