// keyplace info LOG|MAP: what a log or a map contains; info --check MAP verifies a map file.

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "io/sqlite_magic.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/log_summary.hpp"
#include "keyplace/io/ros2_bag.hpp"
#include "keyplace/io/timestamps.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/store/map_file.hpp"
#include "result_json.hpp"

namespace keyplace::cli {
namespace {

struct InfoOptions {
  std::string input;
  std::string json_path;
  bool skip_bad_lines = false;
  bool check = false;
  ConfigOptions config;  // for a bag, its input section
};

// How the FLASER lines' beams were spread (FlaserSpacingRule) with the scan counts, or null
// without FLASER lines (ROBOTLASER1 lines and bags state their angles).
nlohmann::json FlaserSpacingJson(const CarmenLog& log) {
  const std::string rule = FlaserSpacingRule(log);
  if (rule.empty()) return nullptr;
  return {{"rule", rule},
          {"scans_fov_over_n", log.flaser_scans_fov_over_beams},
          {"scans_fov_over_n_minus_1", log.flaser_scans_fov_over_beams_minus_one}};
}

nlohmann::json DescribeLog(const CarmenLog& log) {
  nlohmann::json json;
  json["file"] = log.path;
  json["format"] = log.format;
  json["file_bytes"] = log.file_bytes;
  json["fingerprint"] = log.fingerprint;
  json["lines"] = log.lines;
  json["scans"] = log.scans.size();
  json["pose_kind"] = log.corrected ? "corrected" : "odometry";
  if (!log.scans.empty()) json["max_range_m"] = log.scans.front().max_range_m;
  json["beams_per_scan_min"] = log.beams_per_scan_min;
  json["beams_per_scan_max"] = log.beams_per_scan_max;
  json["beams_total"] = log.beams_total;
  json["field_of_view_deg"] = log.first_scan_field_of_view_rad * 180.0 / M_PI;
  json["flaser_beam_spacing"] = FlaserSpacingJson(log);
  json["invalid_beams"] = log.invalid_beams;
  json["no_return_beams"] = log.no_return_beams;
  double duration_s = 0.0;
  if (log.scans.size() > 1) {
    duration_s = log.scans.back().logger_timestamp_s - log.scans.front().logger_timestamp_s;
  }
  json["duration_s"] = duration_s;
  const TimestampCheck stamp_check = CheckTimestamps(log.scans, TimestampSource::kLogger);
  json["timestamp_warnings"] = stamp_check.warnings;
  json["timestamps_order_scans"] = stamp_check.CanOrder();
  json["path_length_m"] = LogPathLengthM(log);
  json["odometry_messages"] = log.odometry.size();
  json["graph_vertices"] = log.vertices.size();
  json["graph_edges"] = log.edges.size();
  json["graph_loop_edges"] =
      std::count_if(log.edges.begin(), log.edges.end(), [](const GraphEdge& e) { return e.loop; });
  json["line_counts"] = log.line_counts;
  json["topics"] = nlohmann::json::array();
  for (const LogTopic& topic : log.topics) {
    json["topics"].push_back(
        {{"topic", topic.name}, {"type", topic.type}, {"messages", topic.messages}});
  }
  json["skipped_lines"] = log.skipped_lines;
  json["truncated_last_line"] = log.truncated_last_line;
  json["warnings"] = log.warnings;
  return json;
}

void PrintLog(const nlohmann::json& json) {
  fmt::print("file            {} ({})\n", json["file"].get<std::string>(),
             json["format"].get<std::string>());
  fmt::print("scans           {} ({} poses)\n", json["scans"].get<std::size_t>(),
             json["pose_kind"].get<std::string>());
  const auto min_beams = json["beams_per_scan_min"].get<std::size_t>();
  const auto max_beams = json["beams_per_scan_max"].get<std::size_t>();
  if (min_beams == max_beams) {
    fmt::print("beams per scan  {}\n", min_beams);
  } else {
    fmt::print("beams per scan  {}..{}\n", min_beams, max_beams);
  }
  fmt::print("field of view   {:.1f} deg\n", json["field_of_view_deg"].get<double>());
  if (!json["flaser_beam_spacing"].is_null()) {
    const nlohmann::json& spacing = json["flaser_beam_spacing"];
    fmt::print("beam spacing    {}\n",
               FlaserSpacingText(spacing["scans_fov_over_n"].get<std::size_t>(),
                                 spacing["scans_fov_over_n_minus_1"].get<std::size_t>()));
  }
  fmt::print("duration        {:.1f} s\n", json["duration_s"].get<double>());
  for (const auto& warning : json["timestamp_warnings"]) {
    fmt::print("timestamps      warning: logger timestamps: {}\n", warning.get<std::string>());
  }
  if (!json["timestamps_order_scans"].get<bool>()) {
    fmt::print("timestamps      cannot order the scans: slam and odometry need --order file\n");
  }
  fmt::print("path length     {:.1f} m\n", json["path_length_m"].get<double>());
  fmt::print("no-return beams {}\n", json["no_return_beams"].get<std::size_t>());
  fmt::print("invalid beams   {} (NaN, infinite, zero or negative ranges)\n",
             json["invalid_beams"].get<std::size_t>());
  if (!json["topics"].empty()) {
    fmt::print("messages        {}\n", json["lines"].get<std::size_t>());
    for (const auto& topic : json["topics"]) {
      fmt::print("  {:<14}{:<26}{}\n", topic["topic"].get<std::string>(),
                 topic["type"].get<std::string>(), topic["messages"].get<std::size_t>());
    }
    return;
  }
  fmt::print("lines           {}\n", json["lines"].get<std::size_t>());
  for (const auto& [type, count] : json["line_counts"].items()) {
    fmt::print("  {:<14}{}\n", type, count.get<std::size_t>());
  }
}

// Only a regular file is sniffed: reading the first bytes of a pipe would take them from the log
// reader (`info <(zcat log.gz)` lost its first scans). The log reader refuses an SQLite stream.
bool IsSqliteFile(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  std::array<char, kSqliteMagic.size()> header{};
  std::ifstream in(path, std::ios::binary);
  in.read(header.data(), header.size());
  return StartsWithSqliteMagic(header.data(), static_cast<std::size_t>(in.gcount()));
}

nlohmann::json DescribeMap(const std::string& path, const GlobalMap& map) {
  const MappingStats stats = ComputeStats(map);
  nlohmann::json json;
  json["file"] = path;
  json["file_bytes"] = std::filesystem::file_size(path);
  json["source_log"] = map.source_log;
  json["source_hash"] = map.source_hash;
  json["pose_source"] = map.pose_source;
  json["source_scans"] = map.source_scans;
  AddResultFields(stats, MappingStatsFields(), json);
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  bool first = true;
  for (const auto& submap : map.submaps) {
    for (const auto& pose : submap.poses) {
      min_x = first ? pose.x : std::min(min_x, pose.x);
      min_y = first ? pose.y : std::min(min_y, pose.y);
      max_x = first ? pose.x : std::max(max_x, pose.x);
      max_y = first ? pose.y : std::max(max_y, pose.y);
      first = false;
    }
  }
  json["trajectory_extent_m"] = {max_x - min_x, max_y - min_y};
  nlohmann::json config;
  for (const auto& [key, value] : ToKeyValues(map.config)) config[key] = value;
  json["config"] = config;
  // The whole configuration that made the map (maps of older versions did not record it).
  if (!map.configuration.empty()) {
    Config whole;
    ApplyConfigYaml(map.configuration, path + " (recorded configuration)", whole);
    json["configuration"] = ConfigJson(whole);
    json["configuration_yaml"] = map.configuration;
  }
  return json;
}

void PrintMap(const nlohmann::json& json) {
  fmt::print("map file             {} ({:.1f} KiB)\n", json["file"].get<std::string>(),
             json["file_bytes"].get<double>() / 1024.0);
  fmt::print("built from           {} ({}, {} poses, {} scans)\n",
             json["source_log"].get<std::string>(), json["source_hash"].get<std::string>(),
             json["pose_source"].get<std::string>(), json["source_scans"].get<std::size_t>());
  fmt::print("submaps              {} ({} forced by the scan or grid limit)\n",
             json["submaps"].get<std::size_t>(), json["forced_submaps"].get<std::size_t>());
  fmt::print("stable keypoints     {} of {} ({:.3f}, {:.1f} % less map data)\n",
             json["stable_keypoints"].get<std::size_t>(),
             json["source_keypoints"].get<std::size_t>(), json["compression"].get<double>(),
             100.0 * (1.0 - json["compression"].get<double>()));
  fmt::print("scans per submap     {:.2f}\n", json["scans_per_submap"].get<double>());
  fmt::print("keypoints per submap {:.2f}\n", json["keypoints_per_submap"].get<double>());
  fmt::print("distribution         {:.3f}\n", json["distribution"].get<double>());
  fmt::print("submap path          median {:.2f} m, largest {:.2f} m ({} reached the bound)\n",
             json["median_path_m"].get<double>(), json["max_path_m"].get<double>(),
             json["path_bound_submaps"].get<std::size_t>());
  fmt::print("submap extent        median {:.2f} m, largest {:.2f} m\n",
             json["median_extent_m"].get<double>(), json["max_extent_m"].get<double>());
  fmt::print("trajectory extent    {:.1f} m x {:.1f} m\n",
             json["trajectory_extent_m"][0].get<double>(),
             json["trajectory_extent_m"][1].get<double>());
  if (json.contains("configuration_yaml")) {
    fmt::print("configuration that made the map (a --config file):\n{}",
               json["configuration_yaml"].get<std::string>());
    return;
  }
  fmt::print("mapping parameters (the map records no other configuration)\n");
  for (const auto& [key, value] : json["config"].items()) {
    fmt::print("  {:<27}{}\n", key, value.get<std::string>());
  }
}

// keyplace info --check: every check LoadMap makes, the recorded whole configuration included.
// The input is taken as a map whatever its first bytes, so that a map with a
// damaged header is reported as such.
void CheckMap(const InfoOptions& options) {
  const MapFileCheck check = CheckMapFile(options.input);
  fmt::print("checking map file {}\n", options.input);
  for (const std::string& passed : check.passed) fmt::print("  ok  {}\n", passed);
  fmt::print("{}\n", check.ok() ? "ok" : "failed");
  if (!options.json_path.empty()) {
    nlohmann::json json;
    json["file"] = options.input;
    json["ok"] = check.ok();
    json["schema_version"] = check.schema_version;
    json["checks_passed"] = check.passed;
    json["problem"] = check.problem;
    WriteJson(options.json_path, json);
  }
  if (!check.ok()) throw std::runtime_error(check.problem);
}

void RunInfo(const CLI::App& command, const InfoOptions& options) {
  CheckOutputs(command, {{"--json", options.json_path}});
  if (options.check) {
    CheckMap(options);
    return;
  }
  nlohmann::json json;
  // A rosbag2 sqlite3 file (*.db3) is an SQLite file too, but a log.
  if (IsSqliteFile(options.input) && !IsRos2Bag(options.input)) {
    json = DescribeMap(options.input, LoadMap(options.input));
    PrintMap(json);
  } else {
    CarmenReadOptions reading =
        ReadingOptions(ResolveConfig(options.config), options.skip_bad_lines);
    reading.keep_beams = false;  // a summary: logs larger than memory can be described
    const CarmenLog log = ReadLogWithScans(options.input, reading);
    PrintLogWarnings(log);
    json = DescribeLog(log);
    PrintLog(json);
  }
  if (!options.json_path.empty()) WriteJson(options.json_path, json);
}

}  // namespace

void RegisterInfoCommand(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info",
      "Describe a CARMEN log (scans, beams, field of view, duration, path length, line types, "
      "invalid beams), a ROS 1 or ROS 2 bag (the same, and its topics, types and message counts) "
      "or a map file (submaps, keypoints, the configuration that made it); "
      "--check verifies a map file.");
  command
      ->add_option(
          "input", options->input,
          "CARMEN log (.log, .log.gz), ROS 1 bag, ROS 2 bag (directory, .mcap, .db3) or map "
          "file (.kpm)")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_option("--json", options->json_path, "Also write the figures as JSON to FILE");
  command->add_flag("--skip-bad-lines", options->skip_bad_lines, kSkipBadLinesHelp);
  AddConfigOptions(command, options->config);  // the input section: how a bag is read
  command->add_flag("--check", options->check,
                    "Verify a map file: SQLite header and integrity check, schema, format "
                    "version, content checksum, configuration, every row; print each check and "
                    "'ok', or the problem and exit with status 1");
  command->callback([command, options] { RunInfo(*command, *options); });
}

}  // namespace keyplace::cli
