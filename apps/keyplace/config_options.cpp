#include "config_options.hpp"

namespace keyplace::cli {

void AddConfigOptions(CLI::App* command, ConfigOptions& options) {
  command
      ->add_option("--preset", options.preset,
                   "Configuration preset: default, paper (the paper's place recognition) or strict "
                   "(default plus the reference-coverage check, for maps recorded on another day)")
      ->check(CLI::IsMember(ConfigPresetNames()))
      ->capture_default_str();
  command
      ->add_option("--config", options.file,
                   "YAML configuration file (any subset of `keyplace dump-config`)")
      ->check(CLI::ExistingFile);
  command->add_option("--set", options.assignments,
                      "Override one setting, section.key=value (repeatable; keys: keyplace "
                      "dump-config)");
  AddBagOptions(command, options);
}

void AddBagOptions(CLI::App* command, ConfigOptions& options) {
  command->add_option("--scan-topic", options.scan_topic,
                      "ROS bag input: sensor_msgs/LaserScan topic (input.scan_topic, default "
                      "/scan)");
  command->add_option("--odom-topic", options.odom_topic,
                      "ROS bag input: nav_msgs/Odometry topic (input.odom_topic, default /odom; "
                      "without it in the bag: /tf odom -> base_link)");
  command->add_option("--laser-pose", options.laser_pose,
                      "ROS bag input: laser on the robot as x,y,theta (m, m, rad), overriding "
                      "/tf_static and /tf (input.laser_pose)");
}

CarmenReadOptions ReadingOptions(const Config& config, bool skip_bad_lines) {
  CarmenReadOptions reading;
  reading.skip_bad_lines = skip_bad_lines;
  reading.bag = config.input;
  return reading;
}

Config ResolveConfig(const ConfigOptions& options, const std::function<void(Config&)>& after_preset,
                     const std::vector<std::string>& aliases) {
  Config config = PresetConfig(options.preset);
  if (after_preset) after_preset(config);
  ConfigBuilder builder(config);
  if (!options.file.empty()) builder.File(options.file);
  for (const std::string& alias : aliases) builder.Assign(alias, "");
  if (!options.scan_topic.empty())
    builder.Set("input.scan_topic", options.scan_topic, "--scan-topic");
  if (!options.odom_topic.empty())
    builder.Set("input.odom_topic", options.odom_topic, "--odom-topic");
  if (!options.laser_pose.empty())
    builder.Set("input.laser_pose", options.laser_pose, "--laser-pose");
  for (const std::string& assignment : options.assignments) builder.Assign(assignment, "--set");
  return builder.Build();  // validated once, after every source
}

}  // namespace keyplace::cli
