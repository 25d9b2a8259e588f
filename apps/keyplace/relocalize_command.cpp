// keyplace relocalize: the kidnapped-robot benchmark (eval/relocalization.hpp). From --starts
// starts spread over the query log a Relocalizer that knows nothing is fed scans and odometry
// until it declares a fix or gives up; every fix it reports is checked against the truth. A log
// without truth is relocalized once, as a robot would be (localization/log_relocalization.hpp).

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/localization/log_relocalization.hpp"
#include "keyplace/store/map_file.hpp"
#include "localize_output.hpp"
#include "query_log.hpp"
#include "relocalize_log_output.hpp"
#include "relocalize_output.hpp"

namespace keyplace::cli {
namespace {

struct RelocalizeOptions {
  QueryLogOptions query;
  std::string map_path;
  std::string self_match = "shared-scan";
  std::string json_path;
  std::string tsv_path;
  std::string fixes_path;
  std::string figure_path;
  std::string initial_pose_path;
  ConfigOptions config;
  int starts = 50;
};

// The first fix of the first start that got one, as the /initialpose message a robot would
// publish at that moment; a note when no start got a fix (nothing is written).
void WriteFirstFix(const std::string& path, const RelocalizeReport& report) {
  const std::optional<FirstFix> first = FirstFixOf(report.records);
  if (!first) {
    fmt::print(stderr, "keyplace: note: no start got a fix; {} not written\n", path);
    return;
  }
  WriteInitialPose(first->fix.initial_pose, path);
  fmt::print("initial pose (first fix, start at scan {}, fix at scan {}) written to {}\n",
             first->start_scan, first->fix.scan, path);
}

// No truth (no --truth, no corrected poses in the log): the log relocalized once from its first
// scan, what the Relocalizer said at each scan.
void RunWithoutTruth(const CLI::App& command, const RelocalizeOptions& options,
                     const Config& config, const GlobalMap& map, const LogInputs& inputs) {
  for (const char* option : {"--tsv", "--figure"}) {
    if (command.count(option) > 0) {
      throw std::invalid_argument(std::string(option) + " needs the truth (the benchmark's " +
                                  "starts): give --truth and --index, or a corrected log");
    }
  }
  if (command.count("--starts") > 0) {
    fmt::print(stderr,
               "keyplace: note: --starts is the benchmark's; without truth the log is "
               "relocalized once, from its first scan\n");
  }
  Progress progress("scans", inputs.log.scans.size());
  const LogRelocalization run =
      RelocalizeLog(map, inputs, ToLocalizerConfig(config),
                    [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  PrintLogRelocalization(run, inputs, options.map_path, map, options.query.log_path);
  if (!options.fixes_path.empty()) WriteScanStatusTsv(options.fixes_path, run);
  if (!options.initial_pose_path.empty()) {
    if (run.first_fix_pose) {
      WriteInitialPose(*run.first_fix_pose, options.initial_pose_path);
    } else {
      fmt::print(stderr, "keyplace: note: no fix; {} not written\n", options.initial_pose_path);
    }
  }
  if (!options.json_path.empty()) {
    nlohmann::json json =
        LogRelocalizationJson(run, inputs, options.map_path, options.query.log_path);
    json["config"] = ConfigJson(config);
    WriteJson(options.json_path, json);
  }
}

void RunRelocalize(const CLI::App& command, const RelocalizeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(command, {{"--json", options.json_path},
                         {"--tsv", options.tsv_path},
                         {"--fixes", options.fixes_path},
                         {"--figure", options.figure_path},
                         {"--initialpose", options.initial_pose_path}});
  if (options.starts < 1) throw std::invalid_argument("--starts must be >= 1");
  const Config config = ResolveConfig(options.config);
  const GlobalMap map = LoadMap(options.map_path);

  QueryLogOptions query_options = options.query;
  // Without --truth or --poses: the log's corrected poses when it has them (the benchmark), else
  // ICP on its odometry (a robot's run).
  if (command.count("--poses") == 0 && query_options.truth_path.empty()) query_options.poses = "";
  const QueryLog query = ReadQueryLog(query_options, config, /*truth_optional=*/true);
  const LogInputs& inputs = query.inputs;
  if (!query.has_truth) {
    RunWithoutTruth(command, options, config, map, inputs);
    return;
  }
  const GroundTruth& truth = query.truth;

  RelocalizeReport report;
  report.map_path = options.map_path;
  report.log_path = options.query.log_path;
  report.first_scan = inputs.first_scan;
  report.end_scan = inputs.first_scan + inputs.log.scans.size();
  report.pose_source = inputs.pose_source;
  report.query_log_is_map_log = TruthIsMapLog(map, truth);
  WarnAboutMapSource(
      options.map_path, map,
      options.query.truth_path.empty() ? options.query.log_path : options.query.truth_path,
      report.query_log_is_map_log);
  report.options =
      RelocalizationOptionsFor(config.evaluation, options.starts,
                               options.self_match == "shared-scan", report.query_log_is_map_log);
  if (!inputs.keypoints_from_cache) {
    report.seconds_keypoints_per_scan =
        inputs.seconds_keypoints / static_cast<double>(inputs.log.scans.size());
  }

  Progress progress("starts", static_cast<std::size_t>(options.starts));
  report.records = RunRelocalization(map, inputs, truth, ToLocalizerConfig(config), report.options,
                                     [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  if (report.records.size() < static_cast<std::size_t>(options.starts)) {
    fmt::print(stderr, "keyplace: note: --starts {} capped to the {} scans with a truth pose\n",
               options.starts, report.records.size());
  }
  report.summary = SummarizeRelocalization(report.records, report.options);
  report.seconds_total = SecondsSince(start);
  PrintRelocalizeReport(report, map);
  if (!options.tsv_path.empty()) WriteStartsTsv(options.tsv_path, report.records);
  if (!options.fixes_path.empty()) WriteFixesTsv(options.fixes_path, report.records);
  if (!options.figure_path.empty()) {
    DrawRelocalization(options.figure_path, report, map, inputs, truth);
  }
  if (!options.initial_pose_path.empty()) WriteFirstFix(options.initial_pose_path, report);
  if (!options.json_path.empty()) {
    nlohmann::json json = RelocalizeJson(report);
    json["config"] = ConfigJson(config);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterRelocalizeCommand(CLI::App& app) {
  auto options = std::make_shared<RelocalizeOptions>();
  CLI::App* command = app.add_subcommand(
      "relocalize",
      "The kidnapped-robot benchmark: from --starts starts spread over the query log the "
      "localizer, knowing nothing, is fed scans and odometry until answers agree on a fix (two, "
      "one of them accepted, or three weak ones along 10 m; docs/LOCALIZATION.md) (or it gives up "
      "after evaluation.give_up_m of travel); it then runs evaluation.follow_m "
      "further and every fix it reports is checked against the truth (0.5 m, 10 deg). Without "
      "truth (no --truth, a log or bag without corrected poses) the log is relocalized once from "
      "its first scan as a robot would be: the status and pose at every scan (--fixes), the "
      "first fix (--initialpose), a summary (--json). Uses the strict preset unless --preset "
      "says otherwise.");
  command->add_option("--map", options->map_path, "Map file (.kpm)")
      ->required()
      ->check(CLI::ExistingFile);
  AddQueryLogOptions(command, options->query,
                     "Odometry fed to the localizer: corrected (the log's), icp (scan matching "
                     "on odometry) or odometry; without --truth and --poses: corrected when the "
                     "log has them, else icp");
  command->add_option("--starts", options->starts, "Number of starts")->capture_default_str();
  command
      ->add_option("--self-match", options->self_match,
                   "shared-scan: on the map's own log, never match a map submap sharing a scan "
                   "with the current query (true revisits only); none: allow it. Another log "
                   "than the map's is never excluded")
      ->check(CLI::IsMember({"shared-scan", "none"}))
      ->capture_default_str();
  // A robot acts on a fix: the strict preset's reference-coverage check keeps wrong fixes out
  // when the map was recorded on another day (docs/RESULTS.md, kidnapped robot).
  options->config.preset = "strict";
  AddConfigOptions(command, options->config);
  command->add_option("--json", options->json_path, "Write the summary as JSON to FILE");
  command->add_option("--tsv", options->tsv_path, "Write one TSV row per start to FILE");
  command->add_option("--fixes", options->fixes_path,
                      "Write one TSV row per fix reported (pose, truth, error, and the covariance "
                      "over x, y, theta derived from the matches) to FILE; without truth one row "
                      "per scan (status, pose when fixed, confidence)");
  command->add_option("--figure", options->figure_path,
                      "Draw the starts, paths and fixes (.png or .svg)");
  command->add_option("--initialpose", options->initial_pose_path,
                      "Write the first fix as a geometry_msgs/PoseWithCovarianceStamped for "
                      "/initialpose (YAML, or JSON for a .json FILE), in the map's frame");
  command->callback([command, options] {
    RunOnWorkerThreads(options->query.threads, [&] { RunRelocalize(*command, *options); });
  });
}

}  // namespace keyplace::cli
