#include "keyplace/io/log_summary.hpp"

#include <cmath>

namespace keyplace {

double LogPathLengthM(const CarmenLog& log) {
  double length_m = 0.0;
  const Pose2* previous = nullptr;
  for (const auto& scan : log.scans) {
    const auto& pose = log.corrected ? scan.corrected_pose : scan.odometry_pose;
    if (!pose) continue;
    if (previous != nullptr) length_m += std::hypot(pose->x - previous->x, pose->y - previous->y);
    previous = &*pose;
  }
  return length_m;
}

std::string FlaserSpacingRule(const CarmenLog& log) {
  const std::size_t over_n = log.flaser_scans_fov_over_beams;
  const std::size_t over_n_minus_one = log.flaser_scans_fov_over_beams_minus_one;
  if (over_n + over_n_minus_one == 0) return "";
  if (over_n_minus_one == 0) return ToString(FlaserSpacing::kFovOverBeams);
  if (over_n == 0) return ToString(FlaserSpacing::kFovOverBeamsMinusOne);
  return "mixed";
}

std::string FlaserSpacingText(std::size_t over_n, std::size_t over_n_minus_one) {
  const char* even = "step fov/n from -fov/2 (even beam count, FLIRTLib's convention)";
  const char* odd = "step fov/(n-1), first and last beam at -fov/2 and +fov/2 (odd beam count)";
  if (over_n_minus_one == 0) return even;
  if (over_n == 0) return odd;
  return std::to_string(over_n) + " FLASER scans " + even + "; " +
         std::to_string(over_n_minus_one) + " " + odd;
}

}  // namespace keyplace
