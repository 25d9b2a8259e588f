// keyplace slam LOG: online SLAM with loop closure by place recognition (paper Section 6.2.2)
// through the library (eval/slam_evaluation.hpp): options, the run and its evaluation, then the
// figures printed beside the paper's and written as JSON / TSV / pictures (slam_output.hpp).

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/slam_evaluation.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/io/trajectory_file.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"
#include "paper_tables.hpp"
#include "slam_output.hpp"

namespace keyplace::cli {
namespace {

struct SlamOptions {
  std::string input;
  std::string out_path;
  std::string trajectory_path;
  std::string trajectory_format = "tsv";
  std::string truth_path;
  std::string index_path;
  std::string relations_path;
  std::string json_path;
  std::string loops_path;
  std::string grid_path;
  std::string figures_dir;
  std::string order = "logger";
  ConfigOptions config;
};

// The log's scans; SLAM estimates the poses itself, and the keypoints are extracted beside it.
LogInputs PrepareInputs(const std::string& path, const Config& config) {
  LogInputOptions options = LogInputOptionsFor(config);
  options.compute_poses = false;
  options.keypoints = false;
  return PrepareLogInputs(path, options, StageProgressBar());
}

SlamRun Run(const LogInputs& inputs, const Config& config, ProcessingOrder order) {
  Progress progress("slam", inputs.log.scans.size());
  SlamRun run = RunSlamOnLog(inputs, ToSlamConfig(config), config.features, order,
                             [&](std::size_t done, std::size_t) { progress.Update(done); });
  progress.Finish();
  run.map.configuration = ConfigToYaml(config);
  return run;
}

// The grid at the SLAM poses, for --grid and for the check against the corrected poses (a map
// locally right but globally bent shows there, not in the relation errors). A grid --grid asks
// for that cannot be made (grid.max_cells) throws, before any output of the run is written; when
// only the check wanted it, `note` says why there is none.
std::optional<OccupancyGrid> SlamGrid(const SlamRun& run, const LogInputs& inputs,
                                      const Config& config, bool written, bool checked,
                                      std::string& note) {
  if (written) return SlamOccupancyGrid(run, inputs, config.grid);
  if (!checked) return std::nullopt;
  try {
    return SlamOccupancyGrid(run, inputs, config.grid);
  } catch (const std::invalid_argument& error) {
    note = error.what();
    return std::nullopt;
  }
}

// The grid check, printed; none (and a note printed) when a grid could not be made.
std::optional<GridAgreement> CheckGrid(const std::optional<OccupancyGrid>& grid,
                                       const LogInputs& inputs, const GroundTruth& truth,
                                       const SlamEvaluation& evaluation, const Config& config,
                                       std::string note) {
  std::optional<GridAgreement> agreement;
  if (grid && evaluation.accuracy) {
    try {
      agreement = EvaluateSlamGrid(*grid, inputs, truth, *evaluation.accuracy, config.grid,
                                   config.evaluation.grid_tolerance_m);
    } catch (const std::invalid_argument& error) {  // the corrected-pose grid (grid.max_cells)
      note = error.what();
    }
  }
  if (agreement) {
    PrintGridAgreement(*agreement);
  } else if (!note.empty()) {
    fmt::print("grid agreement     not computed: {}\n", note);
  }
  return agreement;
}

void WriteTrajectory(const SlamOptions& options, const SlamRun& run) {
  if (ParseTrajectoryFormat(options.trajectory_format) == TrajectoryFormat::kTum) {
    std::vector<TrajectoryPose> poses;
    for (const OnlineSlam::ScanPose& pose : run.trajectory) {
      poses.push_back({pose.timestamp_s, pose.T_world_robot});
    }
    WriteTumTrajectory(options.trajectory_path, poses);
  } else {
    WriteTrajectoryTsv(options.trajectory_path, run);
  }
}

void RunSlam(const CLI::App& command, const SlamOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.truth_path.empty() != options.index_path.empty()) {
    throw std::invalid_argument("--truth and --index must be given together");
  }
  auto outputs = GridOutputs(options.grid_path);
  outputs.insert(outputs.end(), {{"--out", options.out_path},
                                 {"--trajectory", options.trajectory_path},
                                 {"--json", options.json_path},
                                 {"--loops", options.loops_path}});
  CheckOutputs(command, outputs);
  const Config config = ResolveConfig(options.config);
  const ProcessingOrder order = ParseProcessingOrder(options.order);
  const LogInputs inputs = PrepareInputs(options.input, config);
  // Ground truth and relations are read before the long run, so that a bad file fails at once.
  std::optional<GroundTruth> truth;
  if (!options.truth_path.empty()) {
    truth = LoadGroundTruth(inputs.log, inputs.first_scan, inputs.file_scans, options.truth_path,
                            options.index_path);
  }
  std::optional<std::vector<Relation>> relations;
  if (!options.relations_path.empty()) relations = ReadRelations(options.relations_path);

  const SlamRun run = Run(inputs, config, order);
  std::string grid_note;
  const std::optional<OccupancyGrid> grid =
      SlamGrid(run, inputs, config, !options.grid_path.empty(), truth.has_value(), grid_note);
  if (!options.out_path.empty()) SaveMap(run.map, options.out_path);
  if (!options.trajectory_path.empty()) WriteTrajectory(options, run);
  const SlamEvaluation evaluation = EvaluateSlam(
      run, truth ? &*truth : nullptr, relations ? &*relations : nullptr, config.evaluation);
  if (!options.loops_path.empty()) WriteLoopsTsv(options.loops_path, run, evaluation.loops);

  const SlamReport report{options.input, DatasetName(options.input), run, evaluation, config};
  PrintSlamReport(report);
  if (!options.figures_dir.empty()) {
    DrawSlamFigures(options.figures_dir, report);
    fmt::print("figures written to {}\n", options.figures_dir);
  }
  if (!options.out_path.empty()) fmt::print("map written to {}\n", options.out_path);
  if (grid && !options.grid_path.empty()) WriteGrid(options.grid_path, *grid, config.grid);
  std::optional<GridAgreement> grid_agreement;
  if (truth) grid_agreement = CheckGrid(grid, inputs, *truth, evaluation, config, grid_note);
  if (!options.json_path.empty()) {
    nlohmann::json json = SlamJson(report, SecondsSince(start));
    if (grid_agreement) json["grid_agreement"] = GridAgreementJson(*grid_agreement);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterSlamCommand(CLI::App& app) {
  auto options = std::make_shared<SlamOptions>();
  CLI::App* command = app.add_subcommand(
      "slam",
      "Online SLAM on a raw log (paper Section 6.2.2): ICP odometry, submaps of stable keypoints, "
      "loop closure by place recognition, pose graph over submap origins (Ceres). Prints loop "
      "counts, loop precision by submap overlap, Table IX and, with --truth/--relations, "
      "ATE/RPE, the SLAM grid against the corrected-pose grid and relation errors. Tuning: --set "
      "slam.KEY=VALUE (e.g. "
      "slam.exclude_recent_submaps, slam.gate_base_m=0 for no gate, slam.loop_refinement.refine), "
      "--set mapping.KEY=VALUE, --set place.KEY=VALUE, --preset paper.");
  command
      ->add_option("input", options->input,
                   "raw CARMEN log (.log, .log.gz), ROS 1 bag or ROS 2 bag")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_option("--out", options->out_path, "write the SLAM map (.kpm)");
  command->add_option("--grid", options->grid_path,
                      "write an occupancy grid of the scans at the SLAM poses for ROS map_server "
                      "/ nav2 (FILE.yaml and FILE.pgm; settings: --set grid.KEY=VALUE)");
  command->add_option("--trajectory", options->trajectory_path,
                      "write every scan's optimised pose (TSV: scan_index, timestamp, x, y, theta, "
                      "submap, ICP pose; or TUM with --trajectory-format tum)");
  command
      ->add_option("--trajectory-format", options->trajectory_format,
                   "format of --trajectory: tsv (keyplace's columns) or tum (timestamp tx ty tz "
                   "qx qy qz qw, as evo reads it)")
      ->check(CLI::IsMember({"tsv", "tum"}))
      ->capture_default_str();
  command
      ->add_option("--truth", options->truth_path,
                   "corrected log for ATE / RPE and the grid check: the SLAM grid against the "
                   "grid at the corrected poses (needs --index)")
      ->check(CLI::ExistingFile);
  command->add_option("--index", options->index_path, "raw_index corrected_index TSV")
      ->check(CLI::ExistingFile);
  command->add_option("--relations", options->relations_path, "Kümmerle et al. relation file")
      ->check(CLI::ExistingFile);
  command->add_option("--json", options->json_path, "write the figures as JSON");
  command->add_option(
      "--loops", options->loops_path,
      "write one TSV row per detected loop (submaps, first scans, transform, "
      "consensus, gamma, overlap over all cells and over the common area, accepted, used, "
      "ground-truth check)");
  command->add_option("--figures", options->figures_dir,
                      "write trajectory, overlap histogram, RPE and ATE pictures (PNG) here");
  command->add_option("--order", options->order, "processing order: logger (default) or file")
      ->check(CLI::IsMember({"logger", "file"}));
  AddConfigOptions(command, options->config);
  command->callback([command, options] { RunSlam(*command, *options); });
}

}  // namespace keyplace::cli
