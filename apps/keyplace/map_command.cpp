// keyplace map LOG: build the global map of stable keypoints (paper Algorithms 1-2).

#include <chrono>
#include <filesystem>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "io/file_fingerprint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"
#include "map_figure.hpp"
#include "paper_tables.hpp"

namespace keyplace::cli {
namespace {

struct MapOptions {
  std::string input;
  std::string poses;
  std::string out_path;
  std::string json_path;
  std::string png_path;
  std::string svg_path;
  ConfigOptions config;
  bool overlap_only = false;
  bool skip_bad_lines = false;
};

void RunMap(const MapOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = ResolveConfig(options.config, [&](Config& c) {
    if (options.overlap_only) {
      c.mapping.use_distribution = false;
      c.mapping.min_stable_keypoints = 0;
    }
  });
  LogInputOptions input_options;
  input_options.reading.skip_bad_lines = options.skip_bad_lines;
  if (!options.poses.empty()) input_options.poses = ParsePoseSource(options.poses);
  input_options.odometry = config.odometry;
  input_options.features = config.features;
  const LogInputs inputs = PrepareLogInputs(options.input, input_options, StageProgressBar());
  PrintLogWarnings(inputs.log);
  const CarmenLog& log = inputs.log;
  const PoseSource source = inputs.pose_source;
  const double read_seconds = inputs.seconds_read;
  const double pose_seconds = inputs.seconds_poses;
  const double keypoint_seconds = inputs.seconds_keypoints;

  Progress map_progress("mapping", log.scans.size());
  GlobalMappingTimings timings;
  GlobalMap map =
      BuildGlobalMap({log.scans, inputs.poses, inputs.keypoints}, config.mapping, &timings,
                     [&](std::size_t next_scan) { map_progress.Update(next_scan); });
  map_progress.Finish();
  map.source_log = inputs.source_log;
  map.source_hash = inputs.source_hash;
  map.pose_source = ToString(source);
  map.configuration = ConfigToYaml(config);
  const MappingStats stats = ComputeStats(map);
  const double seconds_per_submap =
      timings.submap_seconds.empty()
          ? 0.0
          : std::accumulate(timings.submap_seconds.begin(), timings.submap_seconds.end(), 0.0) /
                static_cast<double>(timings.submap_seconds.size());
  // Per submap including its share of pose estimation and keypoint extraction.
  const double seconds_per_submap_all =
      stats.submaps > 0 ? seconds_per_submap +
                              (pose_seconds + keypoint_seconds) / static_cast<double>(stats.submaps)
                        : 0.0;

  if (!options.out_path.empty()) SaveMap(map, options.out_path);
  const std::size_t covered_scans = map.submaps.empty() ? 0 : map.submaps.back().last_scan() + 1;

  fmt::print("log                  {} ({} scans, {} poses)\n", options.input, log.scans.size(),
             ToString(source));
  fmt::print("submaps              {} ({} forced by the scan or grid limit), scans 0..{} of {}\n",
             stats.submaps, stats.forced_submaps, covered_scans, log.scans.size());
  fmt::print("scans per submap     {:.2f}\n", stats.scans_per_submap);
  fmt::print("keypoints per submap {:.2f}\n", stats.keypoints_per_submap);
  fmt::print("compression          {:.3f} ({} stable of {} keypoints: {:.1f} % less map data)\n",
             stats.compression, stats.stable_keypoints, stats.source_keypoints,
             100.0 * (1.0 - stats.compression));
  fmt::print("distribution         {:.3f}\n", stats.distribution);
  fmt::print("time per submap      {:.4f} s mapping, {:.4f} s with poses and keypoints\n",
             seconds_per_submap, seconds_per_submap_all);
  fmt::print(
      "time                 read {:.2f} s, poses {:.2f} s, keypoints {:.2f} s, mapping "
      "{:.2f} s\n",
      read_seconds, pose_seconds, keypoint_seconds, timings.seconds_total);
  const auto dataset = DatasetName(options.input);
  // Table II was measured with the overlap criterion alone, Table VI with all criteria.
  const PaperMappingRow* paper = dataset ? PaperMapping(*dataset) : nullptr;
  if (paper != nullptr && (std::string(paper->table) == "II") != options.overlap_only) {
    paper = nullptr;
  }
  if (paper) {
    fmt::print("\nTable {} ({})   {:>8} {:>8} {:>10} {:>8} {:>8} {:>9}\n", paper->table, *dataset,
               "Compress", "#Scans", "#Keypoints", "Distrib", "#Submaps", "Time (s)");
    fmt::print("  paper          {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               paper->compression, paper->scans_per_submap, paper->keypoints_per_submap,
               paper->distribution, paper->submaps, paper->seconds_per_submap);
    fmt::print("  keyplace       {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               stats.compression, stats.scans_per_submap, stats.keypoints_per_submap,
               stats.distribution, static_cast<int>(stats.submaps), seconds_per_submap_all);
  }
  if (!options.out_path.empty()) fmt::print("\nmap written to {}\n", options.out_path);

  if (!options.png_path.empty() || !options.svg_path.empty()) {
    MapFigureOptions figure;
    figure.title = fmt::format("{}: {} submaps, {} stable keypoints ({} poses)", map.source_log,
                               stats.submaps, stats.stable_keypoints, ToString(source));
    if (!options.png_path.empty()) {
      DrawMapFigure(options.png_path, map, log.scans, inputs.poses, figure);
    }
    if (!options.svg_path.empty()) {
      DrawMapFigure(options.svg_path, map, log.scans, inputs.poses, figure);
    }
  }

  if (!options.json_path.empty()) {
    nlohmann::json json;
    json["log"] = options.input;
    json["dataset"] = dataset ? *dataset : "";
    json["pose_source"] = ToString(source);
    json["scans"] = log.scans.size();
    json["compression"] = stats.compression;
    json["scans_per_submap"] = stats.scans_per_submap;
    json["keypoints_per_submap"] = stats.keypoints_per_submap;
    json["distribution"] = stats.distribution;
    json["submaps"] = stats.submaps;
    json["forced_submaps"] = stats.forced_submaps;
    json["stable_keypoints"] = stats.stable_keypoints;
    json["source_keypoints"] = stats.source_keypoints;
    json["seconds_per_submap"] = seconds_per_submap_all;
    json["seconds_per_submap_mapping_only"] = seconds_per_submap;
    json["seconds_total"] = SecondsSince(start);
    json["seconds_poses"] = pose_seconds;
    json["seconds_keypoints"] = keypoint_seconds;
    json["seconds_mapping"] = timings.seconds_total;
    json["config"] = ConfigJson(config);
    if (paper) {
      json["paper"] = {{"table", paper->table},
                       {"compression", paper->compression},
                       {"scans_per_submap", paper->scans_per_submap},
                       {"keypoints_per_submap", paper->keypoints_per_submap},
                       {"distribution", paper->distribution},
                       {"submaps", paper->submaps},
                       {"seconds_per_submap", paper->seconds_per_submap}};
    }
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
  command->add_option("input", options->input, "CARMEN log (.log or .log.gz)")
      ->required()
      ->check(CLI::ExistingFile);
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
  command->add_flag("--overlap-only", options->overlap_only,
                    "Complete submaps on the overlap criterion alone (paper Section 3.1.3, as "
                    "for Table II): no distribution or keypoint-count criterion");
  command->add_flag("--skip-bad-lines", options->skip_bad_lines, kSkipBadLinesHelp);
  AddConfigOptions(command, options->config);
  command->callback([options] { RunMap(*options); });
}

}  // namespace keyplace::cli
