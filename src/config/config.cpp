#include "keyplace/config/config.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/shown_text.hpp"
#include "config/section_tables.hpp"
#include "config/spelling.hpp"

namespace keyplace {
namespace {

// The whole configuration as one table. SlamConfig and LocalizerConfig embed copies of other
// sections; their tables leave those out, and ToSlamConfig / ToLocalizerConfig put them in.
const ConfigFields<Config>& ConfigTable() {
  static const ConfigFields<Config> fields = [] {
    ConfigFields<Config> table("config");
    table.Nested("input", &Config::input, BagInputConfigFields())
        .Nested("features", &Config::features, FlirtConfigFields())
        .Nested("odometry", &Config::odometry, ScanOdometryConfigFields())
        .Nested("mapping", &Config::mapping, MappingConfigFields())
        .Nested("place", &Config::place, PlaceConfigFields())
        .Nested("slam", &Config::slam, SlamConfigFields())
        .Nested("localization", &Config::localization, LocalizerConfigFields())
        .Nested("evaluation", &Config::evaluation, EvaluationConfigFields())
        .Nested("grid", &Config::grid, OccupancyGridConfigFields())
        .Nested("merge", &Config::merge, MergeOptionsFields())
        .Nested("node", &Config::node, NodeConfigFields());
    return table;
  }();
  return fields;
}

std::vector<std::string> ConfigKeys() {
  std::vector<std::string> keys;
  for (const auto& field : ConfigTable().fields()) keys.push_back(field.doc.name);
  return keys;
}

// Switches removed after they were measured worse than their default (docs/REGISTRATION.md,
// "Removed options"), and the settings that only they used. Maps and dumps of earlier versions
// record them: a switch at its old default (false: the method as it is now) and the settings
// that had no effect without it are accepted and ignored; a switch turned on is refused, naming
// why, since the method it asks for no longer exists.
const std::vector<std::string>& RemovedSwitches() {
  static const std::vector<std::string> keys = {"odometry.sparse_normals_from_map",
                                                "odometry.odometry_prior"};
  return keys;
}

const std::vector<std::string>& RemovedSettings() {
  static const std::vector<std::string> keys = {
      "odometry.prior_point_sigma_m", "odometry.prior_sigma_base_m",
      "odometry.prior_sigma_per_m",   "odometry.prior_sigma_base_rad",
      "odometry.prior_sigma_per_rad", "odometry.prior_sigma_rad_per_m"};
  return keys;
}

// True when `key` is a removed one whose `value` changes nothing (see above); throws for a
// removed switch turned on.
bool IgnoredRemovedKey(const std::string& key, const std::string& value) {
  const auto named = [&](const std::vector<std::string>& keys) {
    return std::find(keys.begin(), keys.end(), key) != keys.end();
  };
  if (named(RemovedSettings())) return true;
  if (!named(RemovedSwitches())) return false;
  if (value == "false" || value == "0") return true;
  throw std::invalid_argument(key +
                              " was removed: measured worse than without it "
                              "(docs/REGISTRATION.md, \"Removed options\"); leave it out");
}

// The sections in table order, each validated as a whole (slam and localization with the shared
// sections put in, as they run).
const std::vector<std::string>& SectionNames() {
  static const std::vector<std::string> names = {"input", "features", "odometry",     "mapping",
                                                 "place", "slam",     "localization", "evaluation",
                                                 "grid",  "merge",    "node"};
  return names;
}

void ValidateSection(const std::string& section, const Config& config) {
  if (section == "input") Validate(config.input);
  if (section == "features") ValidateFlirtConfig(config.features);
  if (section == "odometry") ValidateScanOdometryConfig(config.odometry);
  if (section == "mapping") Validate(config.mapping);
  if (section == "place") Validate(config.place);
  if (section == "slam") Validate(ToSlamConfig(config));
  if (section == "localization") Validate(ToLocalizerConfig(config));
  if (section == "evaluation") Validate(config.evaluation);
  if (section == "grid") Validate(config.grid);
  if (section == "merge") Validate(config.merge);
  if (section == "node") Validate(config.node);
}

std::string SectionOf(const std::string& key) { return key.substr(0, key.find('.')); }

// The error of an invalid section with the settings given to it: one setting is named as
// "origin: key: error" (as a wrong type is), several are listed with their origins.
std::string ExplainInvalidSection(const std::string& section, const std::string& error,
                                  const std::vector<std::pair<std::string, std::string>>& given) {
  std::vector<std::pair<std::string, std::string>> in_section;  // last value of each key
  for (const auto& [assignment, origin] : given) {
    const std::string key = assignment.substr(0, assignment.find('='));
    if (SectionOf(key) != section) continue;
    const auto same_key = [&](const auto& entry) {
      return entry.first.substr(0, entry.first.find('=')) == key;
    };
    in_section.erase(std::remove_if(in_section.begin(), in_section.end(), same_key),
                     in_section.end());
    in_section.emplace_back(assignment, origin);
  }
  if (in_section.size() == 1) {
    const auto& [assignment, origin] = in_section.front();
    return (origin.empty() ? "" : origin + ": ") + assignment.substr(0, assignment.find('=')) +
           ": " + error;
  }
  std::string text = section + ": " + error;
  if (in_section.empty()) return text;
  text += " (settings of " + section + " given:";
  for (const auto& [assignment, origin] : in_section) {
    text += " " + assignment + (origin.empty() ? "" : " from " + origin) + ";";
  }
  text.back() = ')';
  return text;
}

}  // namespace

SlamConfig ToSlamConfig(const Config& config) {
  SlamConfig slam = config.slam;
  slam.odometry = config.odometry;
  slam.mapping = config.mapping;
  slam.place = config.place;
  return slam;
}

LocalizerConfig ToLocalizerConfig(const Config& config) {
  LocalizerConfig localization = config.localization;
  localization.place = config.place;
  return localization;
}

std::vector<std::string> ConfigPresetNames() { return {"default", "paper", "strict"}; }

Config PresetConfig(const std::string& name) {
  Config config;
  config.place = PlacePreset(name);
  return config;
}

void Validate(const Config& config) {
  Validate(config.input);
  ValidateFlirtConfig(config.features);
  ValidateScanOdometryConfig(config.odometry);
  Validate(config.mapping);
  Validate(config.place);
  Validate(ToSlamConfig(config));
  Validate(ToLocalizerConfig(config));
  Validate(config.evaluation);
  Validate(config.grid);
  Validate(config.merge);
  Validate(config.node);
}

std::vector<ConfigFieldInfo> DescribeConfig(const Config& config) {
  static const Config defaults;
  std::vector<ConfigFieldInfo> info;
  for (const auto& field : ConfigTable().fields()) {
    info.push_back(
        {field.doc.name, field.doc.unit, field.doc.doc, field.get(config), field.get(defaults)});
  }
  return info;
}

std::vector<std::pair<std::string, std::string>> ConfigKeyValues(const Config& config) {
  return ConfigTable().ToKeyValues(config);
}

ConfigBuilder::ConfigBuilder(Config start) : config_(std::move(start)) {}

ConfigBuilder& ConfigBuilder::Set(const std::string& key, const std::string& value,
                                  const std::string& origin) {
  const std::string where = origin.empty() ? "" : origin + ": ";
  const auto* field = ConfigTable().Find(key);
  if (field == nullptr) {
    try {
      if (IgnoredRemovedKey(key, value)) return *this;
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(where + error.what());
    }
    throw std::invalid_argument(where + "unknown configuration key '" + ShownText(key) + "'" +
                                DidYouMean(key, ConfigKeys()));
  }
  try {
    field->set(value, config_);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(where + ShownText(key) + ": " + error.what());
  }
  given_.emplace_back(key + "=" + value, origin);
  return *this;
}

ConfigBuilder& ConfigBuilder::Assign(const std::string& assignment, const std::string& origin) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw std::invalid_argument("--set '" + ShownText(assignment) +
                                "': expected section.key=value");
  }
  return Set(assignment.substr(0, equals), assignment.substr(equals + 1), origin);
}

Config ConfigBuilder::Build() const {
  for (const std::string& section : SectionNames()) {
    try {
      ValidateSection(section, config_);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(ExplainInvalidSection(section, error.what(), given_));
    }
  }
  return config_;
}

void SetConfigValue(const std::string& key, const std::string& value, Config& config) {
  config = ConfigBuilder(config).Set(key, value, "").Build();
}

void ApplyConfigAssignment(const std::string& assignment, Config& config) {
  config = ConfigBuilder(config).Assign(assignment, "").Build();
}

}  // namespace keyplace
