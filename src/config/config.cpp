#include "keyplace/config/config.hpp"

#include <stdexcept>

#include "config/section_tables.hpp"

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

// Validates the section `key` belongs to.
void ValidateSection(const std::string& key, const Config& config) {
  const std::string section = key.substr(0, key.find('.'));
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

void SetConfigValue(const std::string& key, const std::string& value, Config& config) {
  const auto* field = ConfigTable().Find(key);
  if (field == nullptr) throw std::invalid_argument("unknown configuration key '" + key + "'");
  try {
    field->set(value, config);
    ValidateSection(key, config);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(key + ": " + error.what());
  }
}

void ApplyConfigAssignment(const std::string& assignment, Config& config) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw std::invalid_argument("--set '" + assignment + "': expected section.key=value");
  }
  SetConfigValue(assignment.substr(0, equals), assignment.substr(equals + 1), config);
}

}  // namespace keyplace
