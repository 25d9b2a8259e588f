#pragma once
// The configuration options every command takes: --preset NAME, --config FILE.yaml and repeated
// --set section.key=value (keyplace dump-config lists the keys).

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "keyplace/config/config.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace::cli {

struct ConfigOptions {
  std::string preset = "default";
  std::string file;
  std::vector<std::string> assignments;
  // ROS bag flags, short for --set input.scan_topic=..., input.odom_topic=..., input.laser_pose=...
  std::string scan_topic;
  std::string odom_topic;
  std::string laser_pose;
};

/// Registers --preset, --config and --set on `command`.
void AddConfigOptions(CLI::App* command, ConfigOptions& options);

/// Registers --scan-topic, --odom-topic and --laser-pose (AddConfigOptions does too).
void AddBagOptions(CLI::App* command, ConfigOptions& options);

/// How every command reads its log or bag: options.bag from the config's input section.
CarmenReadOptions ReadingOptions(const Config& config, bool skip_bad_lines = false);

/// The effective configuration: the preset, then `after_preset` (a command's own defaults), then
/// the file, then `aliases` (section.key=value from everyday flags such as --mu), then --set.
Config ResolveConfig(const ConfigOptions& options,
                     const std::function<void(Config&)>& after_preset = {},
                     const std::vector<std::string>& aliases = {});

}  // namespace keyplace::cli
