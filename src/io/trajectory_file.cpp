#include "keyplace/io/trajectory_file.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"

namespace keyplace {
namespace {

// The shortest decimal text that reads back as `value` (max_digits10 digits where needed).
std::string ShortestText(double value) {
  char text[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

}  // namespace

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "tsv") return TrajectoryFormat::kTsv;
  if (name == "tum") return TrajectoryFormat::kTum;
  throw std::invalid_argument("trajectory format '" + name + "': expected tsv or tum");
}

std::string TumLine(const TrajectoryPose& pose) {
  const double half_theta = 0.5 * pose.T_world_robot.theta;
  std::string line;
  for (const double value : {pose.timestamp_s, pose.T_world_robot.x, pose.T_world_robot.y, 0.0, 0.0,
                             0.0, std::sin(half_theta), std::cos(half_theta)}) {
    line += (line.empty() ? "" : " ") + ShortestText(value);
  }
  return line;
}

void WriteTumTrajectory(const std::string& path, const std::vector<TrajectoryPose>& poses) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# timestamp tx ty tz qx qy qz qw\n";
    for (const TrajectoryPose& pose : poses) out << TumLine(pose) << '\n';
  });
}

}  // namespace keyplace
