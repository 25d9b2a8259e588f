// keyplace sweep mapping|place: parameter sweeps of the paper's Section 5 (Figures 8 and 9),
// in parallel, resumable, one result row per grid point written as soon as it finishes. The
// place sweep evaluates Algorithm 4 through the same library calls as keyplace localize.

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "sweep_grid.hpp"
#include "sweep_points.hpp"
#include "sweep_runner.hpp"

namespace keyplace::cli {
namespace {

struct SweepOptions {
  std::string log_path;
  std::string poses;
  std::string out_dir;
  std::string json_path;
  std::string scans;
  ConfigOptions config;
  std::string s_min = "0.3";
  std::string l_g = "0.1";
  std::string mu = "10";
  std::string gamma_min = "0.4";
  std::string lambda = "0.05";
  int n_pos = 500;
  int threads = 0;
  int stop_after = 0;
  bool overlap_only = false;
  bool exclude_shared_scans = false;
};

// The expensive inputs shared by every grid point: the log (cut to --scans), poses, keypoints.
LogInputs PrepareInputs(const SweepOptions& options, const Config& config, bool need_corrected) {
  LogInputOptions input_options = LogInputOptionsFor(config);
  if (!options.poses.empty()) input_options.poses = ParsePoseSource(options.poses);
  ApplyScanRange(options.scans, input_options);
  LogInputs inputs = PrepareLogInputs(options.log_path, input_options, StageProgressBar());
  if (inputs.log.scans.size() < 2) {
    throw std::invalid_argument("--scans '" + options.scans + "': fewer than 2 scans");
  }
  if (need_corrected && (!inputs.log.corrected || inputs.pose_source != PoseSource::kCorrected)) {
    throw std::invalid_argument(options.log_path +
                                ": sweep place needs a corrected log (VERTEX2/NEFF lines) and "
                                "corrected poses: they are the ground truth");
  }
  return inputs;
}

nlohmann::json Identity(const std::string& kind, const SweepOptions& options,
                        const LogInputs& inputs, const Config& config) {
  nlohmann::json identity;
  identity["sweep"] = kind;
  identity["log"] = inputs.source_log;
  identity["log_fingerprint"] = inputs.source_hash;
  identity["scans"] =
      fmt::format("{}:{}", inputs.first_scan, inputs.first_scan + inputs.log.scans.size());
  identity["poses"] = ToString(inputs.pose_source);
  identity["config"] = ConfigJson(config);
  if (kind == "place") {
    identity["n_pos"] = options.n_pos;
    identity["self_match"] = options.exclude_shared_scans ? "shared_scan" : "same_scans";
  }
  return identity;
}

MappingConfig MappingConfigAt(MappingConfig config, double s_min, double l_g) {
  config.min_stability = s_min;
  config.cell_size_m = l_g;
  Validate(config);
  return config;
}

PlaceRecognitionConfig PlaceConfigAt(PlaceRecognitionConfig config,
                                     const std::vector<double>& point) {
  config.min_pairs = static_cast<int>(point[2]);
  config.min_gamma = point[3];  // the threshold in force, as localize's --gamma-min
  config.min_gamma_all_scans = point[3];
  config.double_match_m = point[4];
  Validate(config);
  return config;
}

Config ResolveSweepConfig(const SweepOptions& options) {
  return ResolveConfig(options.config, [&](Config& c) {
    if (options.overlap_only) {
      c.mapping.use_distribution = false;
      c.mapping.min_stable_keypoints = 0;
    }
  });
}

// The JSON must not be the log, nor one of the files the sweep keeps in --out (its resume
// identity and results), which it would replace.
void CheckSweepOutputs(const CLI::App& command, const SweepOptions& options) {
  CheckOutputs(command, {{"--json", options.json_path}});
  const std::string dir = options.out_dir;
  CheckNotReserved("--json", options.json_path,
                   {dir + "/sweep.json", dir + "/results.csv", dir + "/results.json"},
                   "the sweep's own file");
}

void RunSweepMapping(const CLI::App& command, const SweepOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckSweepOutputs(command, options);
  const std::vector<GridAxis> axes{{"s_min", ParseValueList(options.s_min, "--s-min")},
                                   {"l_g", ParseValueList(options.l_g, "--lg")}};
  const std::vector<std::vector<double>> grid = ExpandGrid(axes);
  const Config config = ResolveSweepConfig(options);
  for (const auto& point : grid) MappingConfigAt(config.mapping, point[0], point[1]);
  const LogInputs inputs = PrepareInputs(options, config, false);
  nlohmann::json identity = Identity("mapping", options, inputs, config);
  identity["overlap_only"] = options.overlap_only;
  const std::vector<std::string> parameters{"s_min", "l_g"};
  const std::vector<std::string> values{
      "submaps",      "forced_submaps",       "compression",      "scans_per_submap",
      "distribution", "keypoints_per_submap", "stable_keypoints", "seconds_per_submap"};
  SweepResults results(options.out_dir, identity, parameters, values);
  const auto pending = PendingPoints(grid, results);
  fmt::print("sweep mapping: {} ({} scans, {} poses), {} points, {} done before, inputs {:.1f} s\n",
             options.log_path, inputs.log.scans.size(), ToString(inputs.pose_source), grid.size(),
             grid.size() - pending.size(),
             inputs.seconds_read + inputs.seconds_poses + inputs.seconds_keypoints);
  const std::size_t computed = RunSweepGroups(
      GroupPoints(pending, {0, 1}), results, parameters, values, options.stop_after,
      [&](const std::vector<std::vector<double>>& points, const std::function<void(double)>&) {
        std::vector<std::vector<double>> rows;
        rows.reserve(points.size());
        for (const auto& point : points) {
          rows.push_back(
              MappingSweepRow(inputs, MappingConfigAt(config.mapping, point[0], point[1])));
        }
        return rows;
      });
  PrintSweepSummary(results, grid.size(), computed, options.out_dir);
  WriteSweepJson(options.json_path, results, grid.size(), computed, options.out_dir,
                 SecondsSince(start));
}

void RunSweepPlace(const CLI::App& command, const SweepOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckSweepOutputs(command, options);
  if (options.n_pos < 1) throw std::invalid_argument("--n-pos must be >= 1");
  std::vector<GridAxis> axes{{"s_min", ParseValueList(options.s_min, "--s-min")},
                             {"l_g", ParseValueList(options.l_g, "--lg")},
                             {"mu", ParseValueList(options.mu, "--mu")},
                             {"gamma_min", ParseValueList(options.gamma_min, "--gamma-min")},
                             {"lambda", ParseValueList(options.lambda, "--lambda")}};
  for (double mu : axes[2].values) {
    if (mu != static_cast<double>(static_cast<int>(mu))) {
      throw std::invalid_argument(fmt::format("--mu: {} is not an integer", mu));
    }
  }
  const std::vector<std::vector<double>> grid = ExpandGrid(axes);
  const Config config = ResolveSweepConfig(options);
  for (const auto& point : grid) {  // fail early
    MappingConfigAt(config.mapping, point[0], point[1]);
    PlaceConfigAt(config.place, point);
  }
  const RankBy rank_by = options.config.preset == "paper" ? RankBy::kGamma : RankBy::kConfidence;
  const SelfMatchRule rule =
      options.exclude_shared_scans ? SelfMatchRule::kSharedScan : SelfMatchRule::kSameScans;
  const LogInputs inputs = PrepareInputs(options, config, true);
  const std::vector<std::string> parameters{"s_min", "l_g", "mu", "gamma_min", "lambda"};
  const std::vector<std::string> values{
      "n_pos",      "n_acc", "n_cor", "precision", "recall",
      "scans_mean", "p_gl",  "p_cl",  "submaps",   "seconds_per_query"};
  SweepResults results(options.out_dir, Identity("place", options, inputs, config), parameters,
                       values);
  const auto pending = PendingPoints(grid, results);
  fmt::print("sweep place: {} ({} scans), {} points, {} done before, inputs {:.1f} s\n",
             options.log_path, inputs.log.scans.size(), grid.size(), grid.size() - pending.size(),
             inputs.seconds_read + inputs.seconds_poses + inputs.seconds_keypoints);

  // The map and the query submaps once per mapping setting that still has pending points.
  const std::map<std::vector<double>, PlaceSweepSetting> prepared = PreparePlaceSweepSettings(
      inputs, pending,
      [&](double s_min, double l_g) { return MappingConfigAt(config.mapping, s_min, l_g); },
      options.n_pos, config.place.query_keypoints);
  // The points of one mapping setting and lambda share their recognitions (PlaceSweepRows).
  const std::size_t computed = RunSweepGroups(
      GroupPoints(pending, {0, 1, 4}), results, parameters, values, options.stop_after,
      [&](const std::vector<std::vector<double>>& points,
          const std::function<void(double)>& fraction_done) {
        std::vector<RecognitionThresholds> thresholds;
        for (const auto& point : points) {
          const PlaceRecognitionConfig at = PlaceConfigAt(config.place, point);
          thresholds.push_back({at.min_pairs, at.min_gamma, at.min_gamma_all_scans});
        }
        return PlaceSweepRows(prepared.at({points[0][0], points[0][1]}),
                              PlaceConfigAt(config.place, points[0]), thresholds, rule, rank_by,
                              fraction_done);
      });
  PrintSweepSummary(results, grid.size(), computed, options.out_dir);
  WriteSweepJson(options.json_path, results, grid.size(), computed, options.out_dir,
                 SecondsSince(start));
}

void AddCommonOptions(CLI::App* command, SweepOptions& options) {
  command
      ->add_option("--out", options.out_dir,
                   "Directory of the results: sweep.json, results.csv, results.json; an "
                   "interrupted sweep in it is resumed")
      ->required();
  command->add_option("--json", options.json_path,
                      "Also write the results (as DIR/results.json, with the grid size and the "
                      "points computed by this run) to FILE");
  command->add_option("--scans", options.scans, "Use only the scans A:B of the log");
  command->add_option("--s-min", options.s_min, "s_min values: A:B:STEP or V1,V2,...")
      ->capture_default_str();
  command->add_option("--lg", options.l_g, "l_g values in m: A:B:STEP or V1,V2,...")
      ->capture_default_str();
  AddConfigOptions(command, options.config);
  command->add_option("--threads", options.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  command
      ->add_option("--stop-after", options.stop_after,
                   "Test hook: start no new group of grid points once N points have started "
                   "in this run")
      ->group("");
}

}  // namespace

void RegisterSweepCommand(CLI::App& app) {
  CLI::App* sweep = app.add_subcommand(
      "sweep",
      "Parameter sweeps of the paper's Section 5 (Figures 8 and 9): parallel, resumable, one "
      "CSV/JSON row per grid point.");
  sweep->require_subcommand(1);

  auto mapping = std::make_shared<SweepOptions>();
  CLI::App* mapping_command = sweep->add_subcommand(
      "mapping",
      "Mapping criteria of Section 5.1 (compression, #scans, #keypoints, distribution, "
      "#submaps, time) over a grid of s_min and l_g (Figure 8).");
  mapping_command
      ->add_option("--log", mapping->log_path, "CARMEN log (.log, .log.gz), ROS 1 bag or ROS 2 bag")
      ->required()
      ->check(CLI::ExistingPath);
  mapping_command
      ->add_option("--poses", mapping->poses,
                   "corrected, odometry or icp (default: corrected when the log has them)")
      ->check(CLI::IsMember({"corrected", "odometry", "icp"}));
  mapping_command->add_flag("--overlap-only", mapping->overlap_only,
                            "Complete submaps on the overlap criterion alone (as keyplace map)");
  AddCommonOptions(mapping_command, *mapping);
  mapping_command->callback([mapping_command, mapping] {
    RunOnWorkerThreads(mapping->threads, [&] { RunSweepMapping(*mapping_command, *mapping); });
  });

  auto place = std::make_shared<SweepOptions>();
  CLI::App* place_command = sweep->add_subcommand(
      "place",
      "Global localization (precision, recall, #scans, time, P_GL, P_CL) over a grid of "
      "mu, gamma_min and lambda (Figure 9), for each mapping setting s_min x l_g.");
  place_command
      ->add_option("--map-log", place->log_path,
                   "Corrected CARMEN log: map, queries and ground truth (as keyplace localize "
                   "with a map built from the same log)")
      ->required()
      ->check(CLI::ExistingFile);
  place_command->add_option("--mu", place->mu, "mu values (integers)")->capture_default_str();
  place_command->add_option("--gamma-min", place->gamma_min, "gamma_min values")
      ->capture_default_str();
  place_command->add_option("--lambda", place->lambda, "lambda values in m")->capture_default_str();
  place_command->add_option("--n-pos", place->n_pos, "Queries per point")->capture_default_str();
  place_command->add_flag("--exclude-shared-scans", place->exclude_shared_scans,
                          "Skip every map submap sharing a scan with the query");
  AddCommonOptions(place_command, *place);
  place_command->callback([place_command, place] {
    RunOnWorkerThreads(place->threads, [&] { RunSweepPlace(*place_command, *place); });
  });
}

}  // namespace keyplace::cli
