#pragma once
// The whole configuration of keyplace: one section per module, each a config struct with its
// defaults and units. `keyplace dump-config` prints it as YAML; every command reads it from
// `--preset`, then `--config FILE.yaml`, then `--set section.key=value`, and records it in its map
// files and JSON outputs.

#include <string>
#include <utility>
#include <vector>

#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/localization/node_config.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/registration/scan_odometry.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

struct Config {
  BagInputConfig input;          // how a ROS bag becomes a log (README, "With ROS")
  FlirtConfig features;          // FLIRT keypoints (docs/FLIRT.md)
  ScanOdometryConfig odometry;   // ICP scan odometry (docs/REGISTRATION.md)
  MappingConfig mapping;         // stable-keypoint submaps (docs/MAPPING.md)
  PlaceRecognitionConfig place;  // recognition of submaps (docs/PLACE.md)
  SlamConfig slam;               // loop closure and pose graph (docs/SLAM.md); its
                                 // odometry, mapping and place are the sections above
  LocalizerConfig localization;  // streaming localizer; its place is the section above
  EvaluationConfig evaluation;   // evaluation settings (not the method's)
  OccupancyGridConfig grid;      // occupancy grids for navigation stacks (docs/NAVIGATION.md)
  MergeOptions merge;            // keyplace merge (docs/MERGE.md)
  NodeConfig node;               // relocalization node on a robot (docs/ROS.md, "On a robot")
};

/// The SLAM configuration with the odometry, mapping and place sections put in.
SlamConfig ToSlamConfig(const Config& config);
/// The localizer configuration with the place section put in.
LocalizerConfig ToLocalizerConfig(const Config& config);

/// Names of the presets: "default", "paper", "strict" (they differ in the place section; see
/// PlacePreset).
std::vector<std::string> ConfigPresetNames();
/// The default configuration with the named preset's place section; throws std::invalid_argument
/// naming the accepted names.
Config PresetConfig(const std::string& name);

/// Throws std::invalid_argument naming the first invalid field (section.key).
void Validate(const Config& config);

/// One field of the configuration, for documentation.
struct ConfigFieldInfo {
  std::string key;            // "place.ransac.iterations"
  std::string unit;           // "m", "rad", "" ...
  std::string doc;            // one line
  std::string value;          // in `config`
  std::string default_value;  // in Config{}
};
std::vector<ConfigFieldInfo> DescribeConfig(const Config& config);

/// Every field as ("section.key", text value), in table order.
std::vector<std::pair<std::string, std::string>> ConfigKeyValues(const Config& config);

/// Settings from several sources (YAML files, --set assignments, single values) applied in order
/// and validated once, after the last: settings that are valid only together (odometry.min_range_m
/// and max_range_m) may come in any order and from any source. A key that does not exist or a
/// value of the wrong type is refused at once, naming where it came from; an invalid section is
/// refused by Build, naming the settings given to it and where each came from.
class ConfigBuilder {
 public:
  explicit ConfigBuilder(Config start = Config{});

  /// One field from text ("place.min_pairs", "12"); `origin` names it in errors ("my.yaml:3",
  /// "--set"; empty: the key alone).
  ConfigBuilder& Set(const std::string& key, const std::string& value, const std::string& origin);
  /// "section.key=value" (the --set syntax).
  ConfigBuilder& Assign(const std::string& assignment, const std::string& origin = "--set");
  /// YAML text (any subset of the sections and keys); `source` names it, with the line, in errors.
  ConfigBuilder& Yaml(const std::string& yaml, const std::string& source);
  /// A YAML file; std::runtime_error when it cannot be read.
  ConfigBuilder& File(const std::string& path);

  /// The configuration, validated: std::invalid_argument for the first invalid section.
  Config Build() const;

 private:
  Config config_;
  std::vector<std::pair<std::string, std::string>> given_;  // (key=value, origin), in order
};

/// Sets one field from text ("place.min_pairs", "12"), then validates the configuration. Throws
/// std::invalid_argument naming the key for an unknown key, a wrong type or an invalid value. For
/// several settings that depend on each other use ConfigBuilder (validated after the last).
void SetConfigValue(const std::string& key, const std::string& value, Config& config);

/// "section.key=value" (the --set syntax) applied with SetConfigValue.
void ApplyConfigAssignment(const std::string& assignment, Config& config);

/// The configuration as YAML: one mapping per section, nested sections as nested mappings, each
/// field with its unit and doc as a comment. Loading it gives back the same configuration.
std::string ConfigToYaml(const Config& config);

/// Applies a YAML file (any subset of the sections and keys) to `config`, validated after its
/// last key (ConfigBuilder). Throws std::invalid_argument naming the file, line and key for an
/// unknown key, a wrong type, an invalid value or malformed YAML; std::runtime_error when the file
/// cannot be read.
void ApplyConfigFile(const std::string& path, Config& config);
/// The same from YAML text; `source` names it in errors.
void ApplyConfigYaml(const std::string& yaml, const std::string& source, Config& config);

}  // namespace keyplace
