#include "keyplace/localization/initial_pose.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/config_fields.hpp"
#include "common/shown_text.hpp"
#include "io/atomic_file.hpp"

namespace keyplace {
namespace {

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

// A frame id as ROS names them (letters, digits, '_', '/', '.', '-'): written as is in YAML and
// JSON, so anything else is refused rather than escaped.
void CheckInitialPoseFrameId(const std::string& frame_id) {
  const bool valid = !frame_id.empty() && std::all_of(frame_id.begin(), frame_id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '/' || c == '.' ||
           c == '-';
  });
  if (!valid) {
    throw std::invalid_argument("initial pose: frame id '" + ShownText(frame_id) +
                                "' is not a ROS frame name (letters, digits, _ / . -)");
  }
}

namespace {

// The message's fields in the flow style both YAML and (with quoted keys) JSON take.
std::string MessageText(const InitialPose& pose, bool json) {
  CheckInitialPoseFrameId(pose.frame_id);
  const auto key = [json](const char* name) {
    return json ? "\"" + std::string(name) + "\": " : std::string(name) + ": ";
  };
  const double half_rad = 0.5 * pose.T_map_robot.theta;
  std::string covariance;
  for (const double value : InitialPoseCovariance(pose)) {
    covariance += (covariance.empty() ? "" : ", ") + FormatConfigDouble(value);
  }
  const std::string frame = json ? "\"" + pose.frame_id + "\"" : pose.frame_id;
  return "{" + key("header") + "{" + key("frame_id") + frame + "}, " + key("pose") + "{" +
         key("pose") + "{" + key("position") + "{" + key("x") +
         FormatConfigDouble(pose.T_map_robot.x) + ", " + key("y") +
         FormatConfigDouble(pose.T_map_robot.y) + ", " + key("z") + "0.0}, " + key("orientation") +
         "{" + key("x") + "0.0, " + key("y") + "0.0, " + key("z") +
         FormatConfigDouble(std::sin(half_rad)) + ", " + key("w") +
         FormatConfigDouble(std::cos(half_rad)) + "}}, " + key("covariance") + "[" + covariance +
         "]}}\n";
}

}  // namespace

std::array<double, 36> InitialPoseCovariance(const InitialPose& pose) {
  constexpr std::array<std::size_t, 3> kAxis = {0, 1, 5};  // x, y, yaw among x y z roll pitch yaw
  std::array<double, 36> covariance{};
  for (std::size_t row = 0; row < 3; ++row) {
    for (std::size_t column = 0; column < 3; ++column) {
      covariance[6 * kAxis[row] + kAxis[column]] =
          pose.covariance(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(column));
    }
  }
  return covariance;
}

InitialPose InitialPoseOf(const RelocalizationUpdate& update, const std::string& frame_id) {
  if (update.status != FixStatus::kFixed) {
    throw std::invalid_argument("an initial pose needs a fix; the localizer is " +
                                ToString(update.status));
  }
  CheckInitialPoseFrameId(frame_id);
  InitialPose pose;
  pose.frame_id = frame_id;
  pose.T_map_robot = update.T_world_robot;
  pose.covariance = update.covariance;
  return pose;
}

std::string InitialPoseYaml(const InitialPose& pose) { return MessageText(pose, false); }

std::string InitialPoseJson(const InitialPose& pose) { return MessageText(pose, true); }

void WriteInitialPose(const InitialPose& pose, const std::string& path) {
  const std::string text = EndsWith(path, ".json") ? InitialPoseJson(pose) : InitialPoseYaml(pose);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace keyplace
