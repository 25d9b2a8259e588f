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

namespace {

const ConfigFields<FixPolicy>& FixPolicyFields() {
  using C = FixPolicy;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("FixPolicy");
    table
        .Int("confirmations", &C::confirmations, "",
             "accepted answers that must agree through odometry before a fix")
        .Double("agree_m", &C::agree_m, "m", "two answers agree within this distance (now) ...")
        .Double("agree_per_m", &C::agree_per_m, "m/m",
                "... plus this per metre travelled between them (odometry drift)")
        .Double("agree_deg", &C::agree_deg, "deg", "... and this angle")
        .Double("window_m", &C::window_m, "m",
                "answers older than this odometry distance are forgotten while searching")
        .Double("lost_after_m", &C::lost_after_m, "m",
                "a fix no answer confirmed over this odometry distance is lost")
        .Double("contradiction_confidence", &C::contradiction_confidence, "",
                "one accepted answer this confident contradicting the fix loses it at once")
        .Double("map_sigma_m", &C::map_sigma_m, "m",
                "the map's own position error, added to a fix's covariance from the matches")
        .Double("map_sigma_deg", &C::map_sigma_deg, "deg",
                "the map's own heading error, added likewise");
    return table;
  }();
  return fields;
}

}  // namespace

const ConfigFields<LocalizerConfig>& LocalizerConfigFields() {
  using C = LocalizerConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("LocalizerConfig");
    table
        .Int("max_query_scans", &C::max_query_scans, "",
             "a query submap not complete after this many scans is recognised as it stands")
        .Double("query_every_m", &C::query_every_m, "m",
                "also answer from the query as it stands every time the robot travelled this far "
                "(0 = only complete queries)")
        .Nested("fix", &C::fix, FixPolicyFields());
    return table;
  }();
  return fields;
}

const ConfigFields<EvaluationConfig>& EvaluationConfigFields() {
  using C = EvaluationConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("EvaluationConfig");
    table
        .Double("local_relation_max_dt_s", &C::local_relation_max_dt_s, "s",
                "relations with |t_b - t_a| below this are local, the others loop")
        .Double("relation_stamp_tolerance_s", &C::relation_stamp_tolerance_s, "s",
                "a relation stamp matches the scan with the nearest stamp within this")
        .Double("min_matched_relations", &C::min_matched_relations, "",
                "no relation error when fewer than this fraction of the relations matched")
        .Int("truth_max_gap_scans", &C::truth_max_gap_scans, "",
             "slam loops are checked when their origins are this close to a corrected scan")
        .Double("revisit_radius_m", &C::revisit_radius_m, "m",
                "a localize query is revisitable with a map scan this close to its true pose")
        .Double("revisit_angle_deg", &C::revisit_angle_deg, "deg",
                "... and a heading this close (recall_revisitable)")
        .Double("give_up_m", &C::give_up_m, "m",
                "relocalize: a start without a fix is given up after this odometry distance")
        .Double("follow_m", &C::follow_m, "m",
                "relocalize: fixes are checked over this distance after the first one")
        .Double("grid_tolerance_m", &C::grid_tolerance_m, "m",
                "slam --grid: occupied cells agree with the corrected-pose grid within this");
    return table;
  }();
  return fields;
}

void Validate(const EvaluationConfig& config) {
  if (!(config.local_relation_max_dt_s > 0.0)) {
    throw std::invalid_argument("EvaluationConfig.local_relation_max_dt_s must be positive");
  }
  if (!(config.relation_stamp_tolerance_s >= 0.0 && config.relation_stamp_tolerance_s <= 1.0)) {
    throw std::invalid_argument("EvaluationConfig.relation_stamp_tolerance_s must lie in [0, 1] s");
  }
  if (!(config.min_matched_relations >= 0.0 && config.min_matched_relations <= 1.0)) {
    throw std::invalid_argument("EvaluationConfig.min_matched_relations must lie in [0, 1]");
  }
  if (config.truth_max_gap_scans < 0) {
    throw std::invalid_argument("EvaluationConfig.truth_max_gap_scans must be >= 0");
  }
  if (!(config.grid_tolerance_m >= 0.0 && config.grid_tolerance_m <= 10.0)) {
    throw std::invalid_argument("EvaluationConfig.grid_tolerance_m must be in [0, 10] m");
  }
  if (!(config.give_up_m > 0.0) || !(config.follow_m >= 0.0)) {
    throw std::invalid_argument(
        "EvaluationConfig.give_up_m must be positive and EvaluationConfig.follow_m >= 0");
  }
  if (!(config.revisit_radius_m >= 0.0)) {
    throw std::invalid_argument("EvaluationConfig.revisit_radius_m must be >= 0");
  }
  if (!(config.revisit_angle_deg >= 0.0 && config.revisit_angle_deg <= 180.0)) {
    throw std::invalid_argument("EvaluationConfig.revisit_angle_deg must be in [0, 180]");
  }
}

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
