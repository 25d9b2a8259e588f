// keyplace features LOG: FLIRT keypoints of every scan of a log.

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {
namespace {

struct FeaturesOptions {
  std::string input;
  std::string scans = ":";
  std::string tsv_path;
  std::string json_path;
  ConfigOptions config;
};

void RunFeatures(const CLI::App& command, const FeaturesOptions& options) {
  CheckOutputs(command, {{"--tsv", options.tsv_path}, {"--json", options.json_path}});
  const Config config = ResolveConfig(options.config);
  const CarmenLog log = ReadLogWithScans(options.input, ReadingOptions(config));
  const ScanRange range = ParseScanRange(options.scans, log.scans.size());
  const FlirtExtractor extractor(config.features);

  std::vector<std::vector<Keypoint>> keypoints(range.end - range.begin);
  Progress progress("features", keypoints.size());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = range.begin; i < range.end; ++i) {
    const LogScan& scan = log.scans[i];
    keypoints[i - range.begin] = extractor.Extract(scan, LogLaserPose(scan));
    progress.Update(i - range.begin + 1);
  }
  const double seconds_total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.Finish();

  std::vector<std::size_t> counts;
  const std::size_t levels = static_cast<std::size_t>(extractor.config().num_scales);
  std::vector<std::size_t> per_level(levels, 0);
  std::size_t total = 0;
  for (const auto& scan_keypoints : keypoints) {
    counts.push_back(scan_keypoints.size());
    total += scan_keypoints.size();
    for (const auto& keypoint : scan_keypoints) {
      const auto level = static_cast<std::size_t>(keypoint.scale_level);
      if (keypoint.scale_level >= 0 && level < levels) ++per_level[level];
    }
  }
  const std::size_t scans = counts.size();
  std::vector<std::size_t> sorted = counts;
  std::sort(sorted.begin(), sorted.end());
  const double mean = scans > 0 ? static_cast<double>(total) / static_cast<double>(scans) : 0.0;
  const double median = scans == 0 ? 0.0
                        : scans % 2 == 1
                            ? static_cast<double>(sorted[scans / 2])
                            : 0.5 * static_cast<double>(sorted[scans / 2 - 1] + sorted[scans / 2]);
  const double seconds_per_scan = scans > 0 ? seconds_total / static_cast<double>(scans) : 0.0;

  fmt::print("log                 {}\n", options.input);
  fmt::print("scans               {} (of {}, range {}:{})\n", scans, log.scans.size(), range.begin,
             range.end);
  fmt::print("keypoints           {}\n", total);
  fmt::print("per scan            mean {:.2f}, median {:.1f}, min {}, max {}\n", mean, median,
             scans > 0 ? sorted.front() : 0, scans > 0 ? sorted.back() : 0);
  std::string level_text;
  for (std::size_t level = 0; level < levels; ++level) {
    level_text += fmt::format("{}{}", level == 0 ? "" : " / ", per_level[level]);
  }
  fmt::print("per scale level     {}\n", level_text);
  fmt::print("time                {:.3f} ms per scan (detect + describe, one thread)\n",
             1000.0 * seconds_per_scan);

  if (!options.tsv_path.empty()) {
    WriteFileAtomically(options.tsv_path, [&](std::ostream& out) {
      out << "scan\tx\ty\torientation\tscale\n";
      for (std::size_t i = 0; i < keypoints.size(); ++i) {
        for (const auto& keypoint : keypoints[i]) {
          out << fmt::format("{}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\n", range.begin + i,
                             keypoint.position_m.x(), keypoint.position_m.y(),
                             keypoint.orientation_rad, keypoint.scale_m);
        }
      }
    });
  }
  if (!options.json_path.empty()) {
    nlohmann::json json;
    json["log"] = options.input;
    json["scan_begin"] = range.begin;
    json["scan_end"] = range.end;
    json["scans"] = scans;
    json["keypoints"] = total;
    json["keypoints_per_scan_mean"] = mean;
    json["keypoints_per_scan_median"] = median;
    json["keypoints_per_scan_min"] = scans > 0 ? sorted.front() : 0;
    json["keypoints_per_scan_max"] = scans > 0 ? sorted.back() : 0;
    json["keypoints_per_level"] = per_level;
    json["seconds_per_scan_mean"] = seconds_per_scan;
    json["seconds_total"] = seconds_total;
    json["config"] = ConfigJson(config);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterFeaturesCommand(CLI::App& app) {
  auto options = std::make_shared<FeaturesOptions>();
  CLI::App* command = app.add_subcommand(
      "features",
      "Extract FLIRT keypoints (curvature detector + beta-grid descriptor, FLIRTLib defaults; "
      "--set features.KEY=VALUE changes them) from the scans of a log and print statistics.");
  command
      ->add_option("input", options->input,
                   "CARMEN log (.log, .log.gz), ROS 1 bag or ROS 2 bag (directory, .mcap, .db3)")
      ->required()
      ->check(CLI::ExistingPath);
  command
      ->add_option("--scans", options->scans,
                   "Half-open range A:B of 0-based scan indices (e.g. 0:50, :100, 200:)")
      ->default_str(":");
  command->add_option("--tsv", options->tsv_path,
                      "Write one keypoint a line: scan, x, y, orientation, scale (laser frame; "
                      "m, rad; scale = 2 sigma of the detection level)");
  command->add_option("--json", options->json_path, "Write the statistics as JSON to FILE");
  AddConfigOptions(command, options->config);
  command->callback([command, options] { RunFeatures(*command, *options); });
}

}  // namespace keyplace::cli
