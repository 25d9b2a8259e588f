// keyplace odometry LOG: scan-matching odometry (point-to-line ICP against a local map,
// initialised by odometry) and its accuracy against the Kümmerle et al. (2009) relations and
// against corrected poses. The evaluation is eval/odometry_evaluation; this file reads the
// options and writes the results (odometry_output).

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "eval_json.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/odometry_evaluation.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/io/trajectory_file.hpp"
#include "odometry_output.hpp"

namespace keyplace::cli {
namespace {

struct OdometryOptions {
  std::string input;
  std::string out_path;
  std::string trajectory_format = "tsv";
  std::string relations_path;
  std::string relation_errors_path;
  std::string steps_path;
  std::string json_path;
  std::string corrected_path;
  std::string index_path;
  std::string scans;
  std::string order = "logger";
  std::string local_dt;  // alias of --set evaluation.local_relation_max_dt_s=...
  ConfigOptions config;
};

void RunOdometry(const CLI::App& command, const OdometryOptions& options) {
  CheckOutputs(command, {{"--out", options.out_path},
                         {"--relation-errors", options.relation_errors_path},
                         {"--steps", options.steps_path},
                         {"--json", options.json_path}});
  std::vector<std::string> aliases;
  if (!options.local_dt.empty()) {
    aliases.push_back("evaluation.local_relation_max_dt_s=" + options.local_dt);
  }
  const Config config = ResolveConfig(options.config, {}, aliases);
  if (options.corrected_path.empty() != options.index_path.empty()) {
    throw std::invalid_argument("--corrected and --raw-to-corrected must be given together");
  }

  const CarmenLog log = ReadLogWithScans(options.input, ReadingOptions(config));
  OdometryRunOptions run_options;
  run_options.order = ParseScanOrder(options.order);
  run_options.source = log.path;
  ScanRange range{0, log.scans.size()};
  if (!options.scans.empty()) range = ParseScanRange(options.scans, log.scans.size());
  run_options.begin = range.begin;
  run_options.end = range.end;
  Progress progress("odometry", range.end - range.begin);
  const OdometryRun run = RunScanOdometry(
      log.scans, config.odometry, run_options,
      [&progress](std::size_t done, std::size_t /*total*/) { progress.Update(done); });
  progress.Finish();

  nlohmann::json json = OdometryRunJson(run);
  json["log"] = options.input;
  json["config"] = ConfigJson(config);
  PrintOdometryRun(run);
  const std::vector<OdometryStep> steps = OdometrySteps(run);
  const OdometryStepDisagreement disagreement = SummarizeStepDisagreement(steps);
  PrintStepDisagreement(disagreement);
  json["step_disagreement"] = StepDisagreementJson(disagreement);

  if (!options.relations_path.empty()) {
    const std::vector<Relation> relations = ReadRelations(options.relations_path);
    const OdometryRelationErrors errors =
        EvaluateOdometryRelations(run, relations, config.evaluation);
    PrintOdometryRelations(errors);
    json["relations_file"] = options.relations_path;
    json["local_max_dt_s"] = config.evaluation.local_relation_max_dt_s;
    json["icp"] = RelationJson(errors.icp);
    json["odometry"] = RelationJson(errors.odometry);
    if (!options.relation_errors_path.empty()) {
      WriteRelationErrorsTsv(options.relation_errors_path, relations, errors);
    }
  }

  if (!options.corrected_path.empty()) {
    const GroundTruth truth =
        TruthFromIndex(log, 0, log.scans.size(), options.corrected_path, options.index_path);
    const OdometryDrift drift = EvaluateOdometryDrift(run, truth);
    PrintOdometryDrift(drift);
    json["drift"] = {{"corrected_log", options.corrected_path},
                     {"index_file", options.index_path},
                     {"icp", DriftJson(drift.icp)},
                     {"odometry", DriftJson(drift.odometry)}};
  }

  if (!options.out_path.empty()) {
    if (ParseTrajectoryFormat(options.trajectory_format) == TrajectoryFormat::kTum) {
      std::vector<TrajectoryPose> poses;
      for (const TimedPose& pose : run.icp_trajectory)
        poses.push_back({pose.timestamp_s, pose.pose});
      WriteTumTrajectory(options.out_path, poses);
    } else {
      WriteTrajectoryTsv(options.out_path, run.icp_trajectory);
    }
  }
  if (!options.steps_path.empty()) WriteStepsTsv(options.steps_path, steps);
  if (!options.json_path.empty()) WriteJson(options.json_path, json);
}

}  // namespace

void RegisterOdometryCommand(CLI::App& app) {
  auto options = std::make_shared<OdometryOptions>();
  CLI::App* command = app.add_subcommand(
      "odometry",
      "Scan-matching odometry on a raw log: every scan is registered with point-to-line ICP "
      "against a local map of the last key scans, initialised by the odometry increment; when "
      "ICP fails from there, it is retried from the best pose of a correlative search around the "
      "prediction (counted as recovered; so is a result beyond the correction bound that the "
      "previous step repeated confirms against a glitching odometry), and if that fails too the "
      "odometry increment is used and the scan is counted as a fallback (so is a match on far "
      "fewer points than the recent ones whose step the odometry contradicts far beyond their "
      "recent agreement: something next to the laser hiding the room). A scan that becomes a key "
      "scan has its pose refined on an occupancy probability grid of the last 90 key scans, and "
      "a recovered pose is taken only where that grid supports it better than the pose it "
      "replaces (odometry.grid_refinement). Prints "
      "the run statistics and, with --relations, the relation error of Kümmerle et al. (2009) "
      "for the ICP trajectory and for raw odometry: mean ± std of the translational (m) and "
      "rotational (deg) error of the relative poses, over all relations and split into local "
      "(|t_b - t_a| < evaluation.local_relation_max_dt_s) and loop relations. The trajectory is "
      "the robot pose, in the odometry frame of the first scan. ICP settings: --set "
      "odometry.KEY=VALUE and odometry.icp.KEY=VALUE (keyplace dump-config lists them).");
  command
      ->add_option("input", options->input,
                   "raw CARMEN log with odometry (.log, .log.gz), ROS 1 bag or ROS 2 bag")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_option("--out", options->out_path,
                      "write the ICP trajectory as TSV: ipc timestamp (s), x (m), y (m), theta "
                      "(rad), one row per scan in processing order (or TUM: --trajectory-format)");
  command
      ->add_option("--trajectory-format", options->trajectory_format,
                   "format of --out: tsv or tum (timestamp tx ty tz qx qy qz qw, as evo reads it)")
      ->check(CLI::IsMember({"tsv", "tum"}))
      ->capture_default_str();
  command
      ->add_option("--relations", options->relations_path,
                   "Kümmerle relation file (t_a t_b dx dy dz droll dpitch dyaw; times are "
                   "ipc timestamps of the raw log, each matched to the scan with the nearest "
                   "stamp within evaluation.relation_stamp_tolerance_s, default 0.1 ms)")
      ->check(CLI::ExistingFile);
  command->add_option("--relation-errors", options->relation_errors_path,
                      "with --relations: write the error of every matched relation as TSV");
  command->add_option("--steps", options->steps_path,
                      "write one TSV row per scan: ICP status, inlier ratio, "
                      "residual, the step as ICP estimated it and as the odometry measured it "
                      "(earlier robot frame) and how far they part, to find where scan matching "
                      "and odometry disagree");
  command
      ->add_option("--corrected", options->corrected_path,
                   "corrected log (ROBOTLASER1 + VERTEX2) for drift: consecutive relative error "
                   "and ATE after SE(2) alignment; needs --raw-to-corrected")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--raw-to-corrected", options->index_path,
                   "raw_index corrected_index TSV pairing raw scans with corrected scans")
      ->check(CLI::ExistingFile);
  command->add_option("--json", options->json_path,
                      "also write all figures (run statistics, relation errors, drift, config) as "
                      "JSON to FILE");
  command->add_option("--scans", options->scans,
                      "process only scans A:B of the processing order (half-open, e.g. 0:500)");
  command
      ->add_option("--order", options->order,
                   "processing order: logger (by logger_timestamp; needed for Intel raw, whose "
                   "ipc stamps are not monotonic), ipc, or file")
      ->check(CLI::IsMember({"logger", "ipc", "file"}))
      ->capture_default_str();
  command->add_option("--local-dt", options->local_dt,
                      "relations with |t_b - t_a| below this (s) are local, the others loop; "
                      "short for --set evaluation.local_relation_max_dt_s=SECONDS (default 5)");
  AddConfigOptions(command, options->config);
  command->callback([command, options] { RunOdometry(*command, *options); });
}

}  // namespace keyplace::cli
