#pragma once
// Internal: numbers and planar poses as the robot node cores' events show them.

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// `value` with `decimals` digits after the point.
inline std::string FixedText(double value, int decimals = 3) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

/// "x m, y m, theta deg" in millimetres and tenths of a degree.
inline std::string PoseText(const Pose2& pose) {
  return FixedText(pose.x) + " m, " + FixedText(pose.y) + " m, " +
         FixedText(pose.theta * 180.0 / M_PI, 1) + " deg";
}

}  // namespace keyplace
