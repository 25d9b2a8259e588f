// keyplace map LOG: build the global map of stable keypoints (paper Algorithms 1-2).

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"
#include "map_figure.hpp"
#include "paper_tables.hpp"
#include "result_json.hpp"

namespace keyplace::cli {
namespace {

struct MapOptions {
  std::string input;
  std::string poses;
  std::string out_path;
  std::string json_path;
  std::string png_path;
  std::string svg_path;
  std::string grid_path;
  std::string scans;
  ConfigOptions config;
  bool overlap_only = false;
  bool skip_bad_lines = false;
  std::string cache_dir;
  bool start_at_origin = false;
  int threads = 0;
};

// Table II was measured with the overlap criterion alone, Table VI with all criteria.
const PaperMappingRow* PaperRow(const std::string& log_path, bool overlap_only) {
  const auto dataset = DatasetName(log_path);
  const PaperMappingRow* paper = dataset ? PaperMapping(*dataset) : nullptr;
  if (paper != nullptr && (std::string(paper->table) == "II") != overlap_only) return nullptr;
  return paper;
}

void PrintMapReport(const MapOptions& options, const LogInputs& inputs, const LogMap& result) {
  const MappingStats& stats = result.stats;
  const std::size_t scans = inputs.log.scans.size();
  // Submap scan indices are scans of the file (MapLog), like --scans.
  const std::size_t end = inputs.first_scan + scans;
  const std::size_t covered =
      result.map.submaps.empty()
          ? inputs.first_scan
          : static_cast<std::size_t>(result.map.submaps.back().last_scan()) + 1;
  if (inputs.first_scan == 0 && scans == inputs.file_scans) {
    fmt::print("log                  {} ({} scans, {} poses)\n", options.input, scans,
               ToString(inputs.pose_source));
  } else {
    fmt::print("log                  {} (scans {}:{} of {}, {} poses)\n", options.input,
               inputs.first_scan, end, inputs.file_scans, ToString(inputs.pose_source));
  }
  fmt::print("submaps              {} ({} forced by the scan or grid limit), scans {}..{} of {}\n",
             stats.submaps, stats.forced_submaps, inputs.first_scan, covered, end);
  fmt::print("scans per submap     {:.2f}\n", stats.scans_per_submap);
  fmt::print("keypoints per submap {:.2f}\n", stats.keypoints_per_submap);
  fmt::print("compression          {:.3f} ({} stable of {} keypoints: {:.1f} % less map data)\n",
             stats.compression, stats.stable_keypoints, stats.source_keypoints,
             100.0 * (1.0 - stats.compression));
  fmt::print("distribution         {:.3f}\n", stats.distribution);
  fmt::print("submap path          median {:.2f} m, largest {:.2f} m ({} reached the bound)\n",
             stats.median_path_m, stats.max_path_m, stats.path_bound_submaps);
  fmt::print("submap extent        median {:.2f} m, largest {:.2f} m\n", stats.median_extent_m,
             stats.max_extent_m);
  fmt::print("time per submap      {:.4f} s mapping, {:.4f} s with poses and keypoints\n",
             result.seconds_per_submap_mapping, result.seconds_per_submap);
  fmt::print(
      "time                 read {:.2f} s, poses {:.2f} s, keypoints {:.2f} s, mapping "
      "{:.2f} s\n",
      inputs.seconds_read, inputs.seconds_poses, inputs.seconds_keypoints,
      result.timings.seconds_total);
  if (const PaperMappingRow* paper = PaperRow(options.input, options.overlap_only)) {
    fmt::print("\nTable {} ({})   {:>8} {:>8} {:>10} {:>8} {:>8} {:>9}\n", paper->table,
               *DatasetName(options.input), "Compress", "#Scans", "#Keypoints", "Distrib",
               "#Submaps", "Time (s)");
    fmt::print("  paper          {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               paper->compression, paper->scans_per_submap, paper->keypoints_per_submap,
               paper->distribution, paper->submaps, paper->seconds_per_submap);
    fmt::print("  keyplace       {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               stats.compression, stats.scans_per_submap, stats.keypoints_per_submap,
               stats.distribution, static_cast<int>(stats.submaps), result.seconds_per_submap);
  }
  if (!options.out_path.empty()) fmt::print("\nmap written to {}\n", options.out_path);
}

void DrawFigures(const MapOptions& options, const LogInputs& inputs, const LogMap& result) {
  MapFigureOptions figure;
  figure.first_scan = inputs.first_scan;
  figure.title = fmt::format("{}: {} submaps, {} stable keypoints ({} poses)",
                             result.map.source_log, result.stats.submaps,
                             result.stats.stable_keypoints, ToString(inputs.pose_source));
  for (const std::string& path : {options.png_path, options.svg_path}) {
    if (!path.empty()) DrawMapFigure(path, result.map, inputs.log.scans, inputs.poses, figure);
  }
}

nlohmann::json MapJson(const MapOptions& options, const LogInputs& inputs, const LogMap& result) {
  const MappingStats& stats = result.stats;
  const auto dataset = DatasetName(options.input);
  nlohmann::json json;
  json["log"] = options.input;
  json["dataset"] = dataset ? *dataset : "";
  json["pose_source"] = ToString(inputs.pose_source);
  json["scans"] = inputs.log.scans.size();
  json["first_scan"] = inputs.first_scan;
  json["scans_in_log"] = inputs.file_scans;
  json["skipped_lines"] = inputs.log.skipped_lines;
  AddResultFields(stats, MappingStatsFields(), json);
  json["seconds_per_submap"] = result.seconds_per_submap;
  json["seconds_per_submap_mapping_only"] = result.seconds_per_submap_mapping;
  json["seconds_poses"] = inputs.seconds_poses;
  json["seconds_keypoints"] = inputs.seconds_keypoints;
  // With --cache the two times above are those of reading the cache.
  json["poses_from_cache"] = inputs.poses_from_cache;
  json["keypoints_from_cache"] = inputs.keypoints_from_cache;
  json["seconds_mapping"] = result.timings.seconds_total;
  if (const PaperMappingRow* paper = PaperRow(options.input, options.overlap_only)) {
    json["paper"] = {{"table", paper->table},
                     {"compression", paper->compression},
                     {"scans_per_submap", paper->scans_per_submap},
                     {"keypoints_per_submap", paper->keypoints_per_submap},
                     {"distribution", paper->distribution},
                     {"submaps", paper->submaps},
                     {"seconds_per_submap", paper->seconds_per_submap}};
  }
  return json;
}

void RunMap(const CLI::App& command, const MapOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto outputs = GridOutputs(options.grid_path);
  outputs.insert(outputs.end(), {{"--out", options.out_path},
                                 {"--json", options.json_path},
                                 {"--png", options.png_path},
                                 {"--svg", options.svg_path}});
  CheckOutputs(command, outputs);
  const Config config = ResolveConfig(options.config, [&](Config& c) {
    if (options.overlap_only) {
      c.mapping.use_distribution = false;
      c.mapping.min_stable_keypoints = 0;
    }
  });
  LogInputOptions input_options = LogInputOptionsFor(config);
  input_options.reading.skip_bad_lines = options.skip_bad_lines;
  if (!options.poses.empty()) input_options.poses = ParsePoseSource(options.poses);
  input_options.start_at_origin = options.start_at_origin;
  input_options.cache_dir = options.cache_dir;
  ApplyScanRange(options.scans, input_options);
  const LogInputs inputs = PrepareLogInputs(options.input, input_options, StageProgressBar());
  PrintInputsWarnings(inputs);
  Progress progress("mapping", inputs.log.scans.size());
  LogMap result = MapLog(inputs, config.mapping, [&](std::size_t next) { progress.Update(next); });
  progress.Finish();
  result.map.configuration = ConfigToYaml(config);
  // Built before anything is written: a grid that cannot be made (grid.max_cells) leaves no
  // output of this run behind.
  std::optional<OccupancyGrid> grid;
  if (!options.grid_path.empty()) grid = LogOccupancyGrid(inputs, config.grid);
  if (!options.out_path.empty()) SaveMap(result.map, options.out_path);
  PrintMapReport(options, inputs, result);
  if (grid) WriteGrid(options.grid_path, *grid, config.grid);
  DrawFigures(options, inputs, result);
  if (!options.json_path.empty()) {
    nlohmann::json json = MapJson(options, inputs, result);
    json["seconds_total"] = SecondsSince(start);
    json["config"] = ConfigJson(config);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterMapCommand(CLI::App& app) {
  auto options = std::make_shared<MapOptions>();
  CLI::App* command = app.add_subcommand(
      "map",
      "Build a global map of submaps of stable FLIRT keypoints from a log (paper Algorithms 1-2) "
      "and print the mapping criteria of the paper's Section 5.1.");
  command
      ->add_option("input", options->input,
                   "CARMEN log (.log, .log.gz), ROS 1 bag or ROS 2 bag (directory, .mcap, .db3)")
      ->required()
      ->check(CLI::ExistingPath);
  command
      ->add_option("--poses", options->poses,
                   "Pose of each scan: corrected (the log's SLAM poses), odometry (raw "
                   "odometry) or icp (scan matching initialised by odometry). Default: "
                   "corrected when the log has corrected poses, else icp")
      ->check(CLI::IsMember({"corrected", "odometry", "icp"}));
  command->add_option("--out", options->out_path, "Write the map to this file (.kpm, SQLite)");
  command->add_option("--json", options->json_path, "Write the figures as JSON to FILE");
  command->add_option("--png", options->png_path,
                      "Draw the map (scan points, stable keypoints, submap origins) as PNG");
  command->add_option("--svg", options->svg_path, "Draw the map as SVG");
  command->add_option("--grid", options->grid_path,
                      "Write an occupancy grid of the scans at their poses for ROS map_server / "
                      "nav2 (FILE.yaml and FILE.pgm; settings: --set grid.KEY=VALUE)");
  command->add_flag("--overlap-only", options->overlap_only,
                    "Complete submaps on the overlap criterion alone (paper Section 3.1.3, as "
                    "for Table II): no distribution or keypoint-count criterion");
  command->add_option("--scans", options->scans,
                      "Map only the scans A:B of the log (e.g. 0:700, the first part of a "
                      "time split); the map's scan indices stay those of the whole file");
  command->add_flag("--skip-bad-lines", options->skip_bad_lines, kSkipBadLinesHelp);
  command->add_option("--cache", options->cache_dir, kCacheHelp);
  command->add_flag("--start-at-origin", options->start_at_origin,
                    "Express the map in the frame of its first scan's pose, as a robot's own "
                    "frame of one session (for keyplace merge)");
  AddConfigOptions(command, options->config);
  command
      ->add_option("--threads", options->threads,
                   "Worker threads of the keypoint extraction (0 = all cores); the map does not "
                   "depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->callback([command, options] {
    RunOnWorkerThreads(options->threads, [&] { RunMap(*command, *options); });
  });
}

}  // namespace keyplace::cli
