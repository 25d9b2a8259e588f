// keyplace info LOG: what a log contains.

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace::cli {
namespace {

struct InfoOptions {
  std::string input;
  std::string json_path;
};

double PathLength(const CarmenLog& log) {
  double length_m = 0.0;
  const Pose2* previous = nullptr;
  for (const auto& scan : log.scans) {
    const auto& pose = log.corrected ? scan.corrected_pose : scan.odometry_pose;
    if (!pose) continue;
    if (previous != nullptr) length_m += std::hypot(pose->x - previous->x, pose->y - previous->y);
    previous = &*pose;
  }
  return length_m;
}

nlohmann::json DescribeLog(const CarmenLog& log) {
  nlohmann::json json;
  json["file"] = log.path;
  json["lines"] = log.lines;
  json["scans"] = log.scans.size();
  json["pose_kind"] = log.corrected ? "corrected" : "odometry";
  std::size_t min_beams = 0;
  std::size_t max_beams = 0;
  std::size_t total_beams = 0;
  double fov_deg = 0.0;
  if (!log.scans.empty()) {
    min_beams = max_beams = log.scans.front().size();
    for (const auto& scan : log.scans) {
      min_beams = std::min(min_beams, scan.size());
      max_beams = std::max(max_beams, scan.size());
      total_beams += scan.size();
    }
    const auto& first = log.scans.front();
    if (first.size() > 1) {
      const double step = (first.angles_rad.back() - first.angles_rad.front()) /
                          static_cast<double>(first.size() - 1);
      fov_deg = (first.angles_rad.back() - first.angles_rad.front() + step) * 180.0 / M_PI;
    }
    json["max_range_m"] = first.max_range_m;
  }
  json["beams_per_scan_min"] = min_beams;
  json["beams_per_scan_max"] = max_beams;
  json["beams_total"] = total_beams;
  json["field_of_view_deg"] = fov_deg;
  json["invalid_beams"] = log.invalid_beams;
  json["no_return_beams"] = log.no_return_beams;
  double duration_s = 0.0;
  if (log.scans.size() > 1) {
    duration_s = log.scans.back().logger_timestamp_s - log.scans.front().logger_timestamp_s;
  }
  json["duration_s"] = duration_s;
  json["path_length_m"] = PathLength(log);
  json["odometry_messages"] = log.odometry.size();
  json["graph_vertices"] = log.vertices.size();
  json["graph_edges"] = log.edges.size();
  json["graph_loop_edges"] =
      std::count_if(log.edges.begin(), log.edges.end(), [](const GraphEdge& e) { return e.loop; });
  json["line_counts"] = log.line_counts;
  return json;
}

void PrintLog(const nlohmann::json& json) {
  fmt::print("file            {}\n", json["file"].get<std::string>());
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
  fmt::print("duration        {:.1f} s\n", json["duration_s"].get<double>());
  fmt::print("path length     {:.1f} m\n", json["path_length_m"].get<double>());
  fmt::print("no-return beams {}\n", json["no_return_beams"].get<std::size_t>());
  fmt::print("invalid beams   {} (NaN, infinite, zero or negative ranges)\n",
             json["invalid_beams"].get<std::size_t>());
  fmt::print("lines           {}\n", json["lines"].get<std::size_t>());
  for (const auto& [type, count] : json["line_counts"].items()) {
    fmt::print("  {:<14}{}\n", type, count.get<std::size_t>());
  }
}

void RunInfo(const InfoOptions& options) {
  const CarmenLog log = ReadLogWithScans(options.input);
  const nlohmann::json json = DescribeLog(log);
  PrintLog(json);
  if (!options.json_path.empty()) WriteJson(options.json_path, json);
}

}  // namespace

void RegisterInfoCommand(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info",
      "Describe a CARMEN log: scans, beams, field of view, duration, path length, line "
      "types, invalid beams.");
  command->add_option("input", options->input, "CARMEN log (.log or .log.gz)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--json", options->json_path, "Also write the figures as JSON to FILE");
  command->callback([options] { RunInfo(*options); });
}

}  // namespace keyplace::cli
