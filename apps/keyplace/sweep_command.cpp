// keyplace sweep mapping|place: parameter sweeps of the paper's Section 5 (Figures 8 and 9),
// in parallel, resumable, one result row per grid point written as soon as it finishes.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/file_fingerprint.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "keyplace/place/submap_query.hpp"
#include "sweep_grid.hpp"

namespace keyplace::cli {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct SweepOptions {
  std::string log_path;
  std::string poses;
  std::string out_dir;
  std::string scans;
  std::vector<std::string> mapping_assignments;
  std::vector<std::string> place_assignments;
  std::string s_min = "0.3";
  std::string l_g = "0.1";
  std::string mu = "10";
  std::string gamma_min = "0.4";
  std::string lambda = "0.05";
  std::string preset = "default";
  int n_pos = 500;
  int threads = 0;
  int stop_after = 0;
  bool overlap_only = false;
  bool exclude_shared_scans = false;
};

// The expensive inputs shared by every grid point: the log (cut to --scans), poses, keypoints.
struct SharedInputs {
  CarmenLog log;
  std::vector<Pose2> poses;
  std::vector<std::vector<Keypoint>> keypoints;
  PoseSource source = PoseSource::kCorrected;
  ScanRange range;
  double seconds = 0.0;
};

SharedInputs PrepareInputs(const SweepOptions& options, bool need_corrected) {
  const auto start = Clock::now();
  SharedInputs inputs;
  inputs.log = ReadLogWithScans(options.log_path);
  const std::size_t total = inputs.log.scans.size();
  inputs.range = options.scans.empty() ? ScanRange{0, total} : ParseScanRange(options.scans, total);
  if (inputs.range.end - inputs.range.begin < 2) {
    throw std::invalid_argument("--scans '" + options.scans + "': fewer than 2 scans");
  }
  auto& scans = inputs.log.scans;
  scans.erase(scans.begin() + static_cast<std::ptrdiff_t>(inputs.range.end), scans.end());
  scans.erase(scans.begin(), scans.begin() + static_cast<std::ptrdiff_t>(inputs.range.begin));
  inputs.source = options.poses.empty()
                      ? (inputs.log.corrected ? PoseSource::kCorrected : PoseSource::kIcp)
                      : ParsePoseSource(options.poses);
  if (need_corrected && (!inputs.log.corrected || inputs.source != PoseSource::kCorrected)) {
    throw std::invalid_argument(options.log_path +
                                ": sweep place needs a corrected log (VERTEX2/NEFF lines) and "
                                "corrected poses: they are the ground truth");
  }
  Progress pose_progress("poses (" + ToString(inputs.source) + ")", scans.size());
  inputs.poses = ScanPoses(inputs.log, inputs.source, {},
                           [&](std::size_t done, std::size_t) { pose_progress.Update(done); });
  pose_progress.Finish();
  const FlirtExtractor extractor;
  Progress keypoint_progress("keypoints", scans.size());
  inputs.keypoints = ExtractKeypoints(inputs.log, extractor, [&](std::size_t done, std::size_t) {
    keypoint_progress.Update(done);
  });
  keypoint_progress.Finish();
  inputs.seconds = Seconds(start);
  return inputs;
}

nlohmann::json BaseIdentity(const std::string& kind, const SweepOptions& options,
                            const SharedInputs& inputs) {
  nlohmann::json identity;
  identity["sweep"] = kind;
  identity["log"] = std::filesystem::path(options.log_path).filename().string();
  identity["log_fingerprint"] = FileFingerprint(options.log_path);
  identity["scans"] = fmt::format("{}:{}", inputs.range.begin, inputs.range.end);
  identity["poses"] = ToString(inputs.source);
  identity["mapping_set"] = options.mapping_assignments;
  return identity;
}

// Runs `evaluate` on every pending point in parallel, writing each row as it finishes.
template <typename Evaluate>
void RunPoints(const std::vector<std::vector<double>>& pending, SweepResults& results,
               const std::vector<std::string>& parameter_columns,
               const std::vector<std::string>& value_columns, int stop_after,
               const Evaluate& evaluate) {
  std::mutex print_mutex;
  std::atomic<int> started{0};
  std::atomic<std::size_t> finished{0};
  Progress progress("sweep", pending.size());
  tbb::parallel_for(std::size_t{0}, pending.size(), [&](std::size_t i) {
    if (stop_after > 0 && started.fetch_add(1) >= stop_after) return;
    const auto start = Clock::now();
    const std::vector<double> values = evaluate(pending[i]);
    results.Add(pending[i], values);
    const std::size_t done = finished.fetch_add(1) + 1;
    std::lock_guard<std::mutex> lock(print_mutex);
    std::string text;
    for (std::size_t k = 0; k < parameter_columns.size(); ++k) {
      text += fmt::format("{}{}={}", k > 0 ? " " : "", parameter_columns[k], pending[i][k]);
    }
    text += ":";
    for (std::size_t k = 0; k < value_columns.size(); ++k) {
      text += fmt::format(" {} {:.4g}", value_columns[k], values[k]);
    }
    fmt::print("[{}/{}] {} ({:.1f} s)\n", done, pending.size(), text, Seconds(start));
    std::fflush(stdout);
    progress.Update(done);
  });
  progress.Finish();
}

std::vector<std::vector<double>> Pending(const std::vector<std::vector<double>>& grid,
                                         const SweepResults& results) {
  std::vector<std::vector<double>> pending;
  for (const auto& point : grid) {
    if (!results.Has(point)) pending.push_back(point);
  }
  return pending;
}

void PrintSummary(const SweepResults& results, std::size_t grid_size, std::size_t pending_before,
                  const std::string& out_dir) {
  const std::size_t done = results.size();
  fmt::print("{} rows in {}/results.csv and results.json ({} grid points, {} computed now)\n", done,
             out_dir, grid_size, pending_before);
}

MappingConfig BaseMappingConfig(const SweepOptions& options) {
  MappingConfig config;
  if (options.overlap_only) {
    config.use_distribution = false;
    config.min_stable_keypoints = 0;
  }
  ApplyKeyValues(ParseAssignments(options.mapping_assignments), config);
  return config;
}

MappingConfig MappingConfigAt(MappingConfig config, double s_min, double l_g) {
  config.min_stability = s_min;
  config.cell_size_m = l_g;
  Validate(config);
  return config;
}

double MeanOf(const std::vector<double>& values) {
  return values.empty() ? 0.0
                        : std::accumulate(values.begin(), values.end(), 0.0) /
                              static_cast<double>(values.size());
}

// ---------------------------------------------------------------- sweep mapping

void RunSweepMapping(const SweepOptions& options) {
  const std::vector<GridAxis> axes{{"s_min", ParseValueList(options.s_min, "--s-min")},
                                   {"l_g", ParseValueList(options.l_g, "--lg")}};
  const std::vector<std::vector<double>> grid = ExpandGrid(axes);
  const MappingConfig base = BaseMappingConfig(options);
  for (const auto& point : grid) MappingConfigAt(base, point[0], point[1]);  // fail early

  tbb::global_control control(tbb::global_control::max_allowed_parallelism,
                              options.threads > 0 ? static_cast<std::size_t>(options.threads)
                                                  : tbb::this_task_arena::max_concurrency());
  const SharedInputs inputs = PrepareInputs(options, false);
  nlohmann::json identity = BaseIdentity("mapping", options, inputs);
  identity["overlap_only"] = options.overlap_only;
  const std::vector<std::string> parameter_columns{"s_min", "l_g"};
  const std::vector<std::string> value_columns{
      "submaps",      "forced_submaps",       "compression",      "scans_per_submap",
      "distribution", "keypoints_per_submap", "stable_keypoints", "seconds_per_submap"};
  SweepResults results(options.out_dir, identity, parameter_columns, value_columns);
  const auto pending = Pending(grid, results);
  fmt::print("sweep mapping: {} ({} scans, {} poses), {} points, {} done before, inputs {:.1f} s\n",
             options.log_path, inputs.log.scans.size(), ToString(inputs.source), grid.size(),
             grid.size() - pending.size(), inputs.seconds);
  const ScanSequence sequence{inputs.log.scans, inputs.poses, inputs.keypoints};
  RunPoints(pending, results, parameter_columns, value_columns, options.stop_after,
            [&](const std::vector<double>& point) {
              const MappingConfig config = MappingConfigAt(base, point[0], point[1]);
              GlobalMappingTimings timings;
              const GlobalMap map = BuildGlobalMap(sequence, config, &timings);
              const MappingStats stats = ComputeStats(map);
              return std::vector<double>{static_cast<double>(stats.submaps),
                                         static_cast<double>(stats.forced_submaps),
                                         stats.compression,
                                         stats.scans_per_submap,
                                         stats.distribution,
                                         stats.keypoints_per_submap,
                                         static_cast<double>(stats.stable_keypoints),
                                         MeanOf(timings.submap_seconds)};
            });
  PrintSummary(results, grid.size(), pending.size(), options.out_dir);
}

// ---------------------------------------------------------------- sweep place

// One query of Algorithm 4 on a corrected log (the log is its own ground truth): the same
// procedure as keyplace localize without --truth/--index.
struct Query {
  PlaceQuery query;
  std::vector<int> scans;  // sorted scan indices (self-match rule)
  Pose2 truth;
  int scan_count = 0;
};

// A map and its query submaps for one mapping setting.
struct Prepared {
  std::vector<Place> places;
  std::vector<Query> queries;
  std::size_t submaps = 0;
};

Prepared PrepareMapping(const SharedInputs& inputs, const MappingConfig& config, int n_pos,
                        PlaceRecognitionConfig::QueryKeypoints query_keypoints) {
  const ScanSequence sequence{inputs.log.scans, inputs.poses, inputs.keypoints};
  Prepared prepared;
  const GlobalMap map = BuildGlobalMap(sequence, config);
  prepared.submaps = map.submaps.size();
  prepared.places = PlacesFromMap(map);
  LocalMapper mapper(config);
  const std::size_t eligible = inputs.log.scans.size();
  for (int i = 0; i < n_pos; ++i) {
    const std::size_t start_scan = static_cast<std::size_t>(i) * eligible / n_pos;
    const std::optional<Submap> submap = BuildSubmap(sequence, start_scan, mapper);
    if (!submap) break;  // Algorithm 4: the log ends before the submap is complete
    const int evaluated = submap->scan_indices.back();
    Query query;
    query.scan_count = static_cast<int>(submap->scan_indices.size());
    query.query = MakeSubmapQuery(*submap, sequence, evaluated, query_keypoints);
    query.scans = submap->scan_indices;
    std::sort(query.scans.begin(), query.scans.end());
    query.truth = *inputs.log.scans[evaluated].corrected_pose;
    prepared.queries.push_back(std::move(query));
  }
  return prepared;
}

double RankScore(const std::string& rank_by, const PlaceMatch& match) {
  return rank_by == "gamma" ? match.gamma : match.confidence;
}

void RunSweepPlace(const SweepOptions& options) {
  if (options.n_pos < 1) throw std::invalid_argument("--n-pos must be >= 1");
  const std::vector<GridAxis> mapping_axes{{"s_min", ParseValueList(options.s_min, "--s-min")},
                                           {"l_g", ParseValueList(options.l_g, "--lg")}};
  std::vector<GridAxis> axes = mapping_axes;
  axes.push_back({"mu", ParseValueList(options.mu, "--mu")});
  axes.push_back({"gamma_min", ParseValueList(options.gamma_min, "--gamma-min")});
  axes.push_back({"lambda", ParseValueList(options.lambda, "--lambda")});
  for (double mu : axes[2].values) {
    if (mu != static_cast<double>(static_cast<int>(mu))) {
      throw std::invalid_argument(fmt::format("--mu: {} is not an integer", mu));
    }
  }
  const std::vector<std::vector<double>> grid = ExpandGrid(axes);
  const MappingConfig base_mapping = BaseMappingConfig(options);
  PlaceRecognitionConfig base_place = PlacePreset(options.preset);
  ApplyKeyValues(ParseAssignments(options.place_assignments), base_place);
  auto place_config_at = [&](const std::vector<double>& point) {
    PlaceRecognitionConfig config = base_place;
    config.min_pairs = static_cast<int>(point[2]);
    config.min_gamma = point[3];  // the threshold in force, as localize's --gamma-min
    config.min_gamma_all_scans = point[3];
    config.double_match_m = point[4];
    Validate(config);
    return config;
  };
  for (const auto& point : grid) {  // fail early
    MappingConfigAt(base_mapping, point[0], point[1]);
    place_config_at(point);
  }
  const std::string rank_by = options.preset == "paper" ? "gamma" : "confidence";
  const SelfMatchRule rule =
      options.exclude_shared_scans ? SelfMatchRule::kSharedScan : SelfMatchRule::kSameScans;

  tbb::global_control control(tbb::global_control::max_allowed_parallelism,
                              options.threads > 0 ? static_cast<std::size_t>(options.threads)
                                                  : tbb::this_task_arena::max_concurrency());
  const SharedInputs inputs = PrepareInputs(options, true);
  nlohmann::json identity = BaseIdentity("place", options, inputs);
  identity["preset"] = options.preset;
  identity["place_set"] = options.place_assignments;
  identity["n_pos"] = options.n_pos;
  identity["self_match"] = options.exclude_shared_scans ? "shared_scan" : "same_scans";
  const std::vector<std::string> parameter_columns{"s_min", "l_g", "mu", "gamma_min", "lambda"};
  const std::vector<std::string> value_columns{
      "n_pos",      "n_acc", "n_cor", "precision", "recall",
      "scans_mean", "p_gl",  "p_cl",  "submaps",   "seconds_per_query"};
  SweepResults results(options.out_dir, identity, parameter_columns, value_columns);
  const auto pending = Pending(grid, results);
  fmt::print("sweep place: {} ({} scans), {} points, {} done before, inputs {:.1f} s\n",
             options.log_path, inputs.log.scans.size(), grid.size(), grid.size() - pending.size(),
             inputs.seconds);

  // The map and the query submaps once per mapping setting that still has pending points.
  std::vector<std::vector<double>> settings;
  for (const auto& point : pending) {
    const std::vector<double> setting{point[0], point[1]};
    if (std::find(settings.begin(), settings.end(), setting) == settings.end()) {
      settings.push_back(setting);
    }
  }
  std::vector<Prepared> prepared(settings.size());
  const auto map_start = Clock::now();
  Progress map_progress("maps and queries", settings.size());
  std::mutex map_progress_mutex;
  std::size_t maps_done = 0;
  tbb::parallel_for(std::size_t{0}, settings.size(), [&](std::size_t i) {
    prepared[i] =
        PrepareMapping(inputs, MappingConfigAt(base_mapping, settings[i][0], settings[i][1]),
                       options.n_pos, base_place.query_keypoints);
    const std::lock_guard<std::mutex> lock(map_progress_mutex);
    map_progress.Update(++maps_done);
  });
  map_progress.Finish();
  if (!settings.empty()) {
    fmt::print("maps and query submaps for {} mapping settings in {:.1f} s\n", settings.size(),
               Seconds(map_start));
  }

  RunPoints(pending, results, parameter_columns, value_columns, options.stop_after,
            [&](const std::vector<double>& point) {
              const std::size_t s =
                  static_cast<std::size_t>(std::find(settings.begin(), settings.end(),
                                                     std::vector<double>{point[0], point[1]}) -
                                           settings.begin());
              const Prepared& data = prepared[s];
              const PlaceRecognizer recognizer(data.places, place_config_at(point));
              std::size_t n_acc = 0;
              std::size_t n_cor = 0;
              double scans_correct = 0.0;
              double seconds = 0.0;
              std::vector<RankedAnswer> answers;
              for (const Query& q : data.queries) {
                const PlaceMatch match = recognizer.Recognize(q.query, [&](const Place& place) {
                  return IsSelfMatch(rule, q.scans, place.scan_indices);
                });
                const bool verified_correct =
                    match.verified && IsCorrectPose(match.estimated_pose, q.truth);
                seconds += match.seconds;
                if (match.found) ++n_acc;
                if (match.found && verified_correct) {
                  ++n_cor;
                  scans_correct += q.scan_count;
                }
                answers.push_back({match.verified, verified_correct, RankScore(rank_by, match)});
              }
              const std::size_t n_pos = data.queries.size();
              const std::vector<PrPoint> curve = PrecisionRecallCurve(answers, n_pos);
              return std::vector<double>{
                  static_cast<double>(n_pos),
                  static_cast<double>(n_acc),
                  static_cast<double>(n_cor),
                  n_acc > 0 ? static_cast<double>(n_cor) / static_cast<double>(n_acc) : 0.0,
                  n_pos > 0 ? static_cast<double>(n_cor) / static_cast<double>(n_pos) : 0.0,
                  n_cor > 0 ? scans_correct / static_cast<double>(n_cor) : 0.0,
                  PrecisionAtMaxRecall(curve),
                  RecallAtPrecision(curve, 0.95),
                  static_cast<double>(data.submaps),
                  n_pos > 0 ? seconds / static_cast<double>(n_pos) : 0.0};
            });
  PrintSummary(results, grid.size(), pending.size(), options.out_dir);
}

void AddCommonOptions(CLI::App* command, SweepOptions& options) {
  command
      ->add_option("--out", options.out_dir,
                   "Directory of the results: sweep.json, results.csv, results.json; an "
                   "interrupted sweep in it is resumed")
      ->required();
  command->add_option("--scans", options.scans, "Use only the scans A:B of the log");
  command->add_option("--s-min", options.s_min, "s_min values: A:B:STEP or V1,V2,...")
      ->capture_default_str();
  command->add_option("--lg", options.l_g, "l_g values in m: A:B:STEP or V1,V2,...")
      ->capture_default_str();
  command->add_option("--set", options.mapping_assignments,
                      "Fixed mapping parameter, KEY=VALUE (repeatable; see keyplace map)");
  command->add_option("--threads", options.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  command
      ->add_option("--stop-after", options.stop_after,
                   "Test hook: start no new grid point once N have started in this run")
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
  mapping_command->add_option("--log", mapping->log_path, "CARMEN log (.log or .log.gz)")
      ->required()
      ->check(CLI::ExistingFile);
  mapping_command
      ->add_option("--poses", mapping->poses,
                   "corrected, odometry or icp (default: corrected when the log has them)")
      ->check(CLI::IsMember({"corrected", "odometry", "icp"}));
  mapping_command->add_flag("--overlap-only", mapping->overlap_only,
                            "Complete submaps on the overlap criterion alone (as keyplace map)");
  AddCommonOptions(mapping_command, *mapping);
  mapping_command->callback([mapping] { RunSweepMapping(*mapping); });

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
  place_command->add_option("--preset", place->preset, "default or paper (as keyplace localize)")
      ->check(CLI::IsMember({"default", "paper"}))
      ->capture_default_str();
  place_command->add_option("--place-set", place->place_assignments,
                            "Fixed PlaceRecognitionConfig field, KEY=VALUE (repeatable)");
  place_command->add_option("--n-pos", place->n_pos, "Queries per point")->capture_default_str();
  place_command->add_flag("--exclude-shared-scans", place->exclude_shared_scans,
                          "Skip every map submap sharing a scan with the query");
  AddCommonOptions(place_command, *place);
  place_command->callback([place] { RunSweepPlace(*place); });
}

}  // namespace keyplace::cli
