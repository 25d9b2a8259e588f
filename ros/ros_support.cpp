#include "ros_support.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <tf2/exceptions.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace keyplace::ros1 {
namespace {

// A parameter's value as the text `--set` takes.
std::string ParameterText(XmlRpc::XmlRpcValue& value, const std::string& name) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string>(value);
    case XmlRpc::XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool>(value) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeDouble: {
      char text[32];
      const auto end = std::to_chars(text, text + sizeof(text), static_cast<double>(value)).ptr;
      return std::string(text, end);
    }
    default:
      throw std::invalid_argument("parameter ~" + name + " must be a string, number or boolean");
  }
}

std::vector<std::string> Assignments(const ros::NodeHandle& private_node) {
  std::vector<std::string> assignments;
  XmlRpc::XmlRpcValue value;
  if (!private_node.getParam("set", value)) return assignments;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeArray) {
    for (int i = 0; i < value.size(); ++i) {
      if (value[i].getType() != XmlRpc::XmlRpcValue::TypeString) {
        throw std::invalid_argument("parameter ~set: entry " + std::to_string(i) +
                                    " is not a \"section.key=value\" string");
      }
      assignments.push_back(static_cast<std::string>(value[i]));
    }
  } else if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    std::istringstream words(static_cast<std::string>(value));
    for (std::string word; words >> word;) assignments.push_back(word);
  } else {
    throw std::invalid_argument(
        "parameter ~set must be a list of \"section.key=value\" strings or one such string");
  }
  return assignments;
}

}  // namespace

Config ConfigFromParameters(const ros::NodeHandle& private_node,
                            const std::string& default_preset) {
  std::string preset = default_preset;
  private_node.getParam("preset", preset);
  // As the command line: preset, file, single keys, then ~set, validated once after the last, so
  // settings valid only together may come from any of them.
  ConfigBuilder builder(PresetConfig(preset));
  std::string config_file;
  if (private_node.getParam("config_file", config_file) && !config_file.empty()) {
    builder.File(config_file);
  }
  for (const auto& [key, unused] : ConfigKeyValues(Config{})) {
    std::string name = key;
    for (char& c : name) c = c == '.' ? '/' : c;
    XmlRpc::XmlRpcValue value;
    if (!private_node.getParam(name, value)) continue;
    builder.Set(key, ParameterText(value, name), "parameter ~" + name);
  }
  for (const std::string& assignment : Assignments(private_node)) {
    builder.Assign(assignment, "parameter ~set");
  }
  return builder.Build();
}

std::string RequiredParameter(const ros::NodeHandle& private_node, const std::string& name) {
  std::string value;
  if (!private_node.getParam(name, value) || value.empty()) {
    throw std::invalid_argument("parameter ~" + name + " is required (" +
                                private_node.resolveName(name) + ")");
  }
  return value;
}

double YawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

geometry_msgs::Quaternion QuaternionOf(double yaw_rad) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(0.5 * yaw_rad);
  q.w = std::cos(0.5 * yaw_rad);
  return q;
}

std::optional<Pose2> LookupPose(const tf2_ros::Buffer& buffer, const std::string& parent_frame,
                                const std::string& child_frame, const ros::Time& stamp,
                                const ros::Duration& timeout, std::string* error) {
  try {
    const geometry_msgs::TransformStamped transform =
        buffer.lookupTransform(parent_frame, child_frame, stamp, timeout);
    const geometry_msgs::Vector3& t = transform.transform.translation;
    return Pose2(t.x, t.y, YawOf(transform.transform.rotation));
  } catch (const tf2::TransformException& exception) {
    if (error != nullptr) *error = exception.what();
    return std::nullopt;
  }
}

}  // namespace keyplace::ros1
