// keyplace localize: global localization against a map (paper Algorithm 4, Sections 5.2, 6.2.1
// and 6.3) through the library's evaluation (eval/global_localization.hpp): options, one call,
// the figures printed beside the paper's and written as JSON / TSV.

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/eval/distractor_map.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/map_localization.hpp"
#include "keyplace/store/map_file.hpp"
#include "localize_output.hpp"
#include "paper_tables.hpp"
#include "query_log.hpp"

namespace keyplace::cli {
namespace {

struct LocalizeOptions {
  QueryLogOptions query;
  std::string map_path;
  std::string json_path;
  std::string queries_path;
  std::string curve_path;
  std::string baseline;
  std::string rank_by;
  std::string reliability_path;
  ConfigOptions config;
  std::optional<int> mu;
  std::optional<double> gamma_min;
  std::optional<double> lambda;
  std::optional<double> min_confidence;
  std::string descriptor_index;
  std::vector<std::string> distractor_paths;
  std::size_t distractor_submaps = 0;
  int n_pos = 500;
  bool exclude_shared_scans = false;
};

// The everyday flags as configuration assignments (--gamma-min sets both thresholds).
std::vector<std::string> Aliases(const LocalizeOptions& o) {
  std::vector<std::string> aliases;
  if (o.mu) aliases.push_back(fmt::format("place.min_pairs={}", *o.mu));
  if (o.gamma_min) {
    aliases.push_back(fmt::format("place.min_gamma={}", *o.gamma_min));
    aliases.push_back(fmt::format("place.min_gamma_all_scans={}", *o.gamma_min));
  }
  if (o.lambda) aliases.push_back(fmt::format("place.double_match_m={}", *o.lambda));
  if (o.min_confidence)
    aliases.push_back(fmt::format("place.min_confidence={}", *o.min_confidence));
  if (!o.descriptor_index.empty()) {
    aliases.push_back(fmt::format("place.descriptor_index={}", o.descriptor_index));
  }
  return aliases;
}

// The map among copies of the distractor maps' submaps, far away (the scale benchmark).
GlobalMap WithDistractors(const GlobalMap& map, const std::vector<std::string>& paths,
                          std::size_t total_submaps, int first_scan) {
  if (total_submaps <= map.submaps.size()) {
    throw std::invalid_argument(
        fmt::format("--distractor-submaps {} must exceed the map's {} submaps", total_submaps,
                    map.submaps.size()));
  }
  std::vector<GlobalMap> sources;
  sources.reserve(paths.size());
  for (const std::string& path : paths) sources.push_back(LoadMap(path));
  DistractorOptions distractors;
  distractors.total_submaps = total_submaps;
  distractors.first_scan = first_scan;
  return EmbedAmongDistractors(map, sources, distractors);
}

void RunLocalize(const CLI::App& command, const LocalizeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(command, {{"--json", options.json_path},
                         {"--queries", options.queries_path},
                         {"--curve", options.curve_path},
                         {"--reliability", options.reliability_path}});
  const bool baseline = !options.baseline.empty();
  if (!baseline && options.map_path.empty()) {
    throw std::invalid_argument("--map is required (except with --baseline tip-flirt)");
  }
  const Config config = ResolveConfig(
      options.config,
      [&](Config& c) {
        // Tipaldi's protocol accepts on the RANSAC consensus alone; a gamma check between two
        // single scans at lambda = 0.05 m rejects most true neighbours (docs/PLACE.md).
        if (baseline) c.place.min_gamma = c.place.min_gamma_all_scans = 0.0;
      },
      Aliases(options));
  const RankBy rank_by = ParseRankBy(
      !options.rank_by.empty()
          ? options.rank_by
          : (baseline ? "consensus" : (options.config.preset == "paper" ? "gamma" : "confidence")));
  SelfMatchRule rule =
      options.exclude_shared_scans ? SelfMatchRule::kSharedScan : SelfMatchRule::kSameScans;

  const QueryLog query = ReadQueryLog(options.query, config);
  const LogInputs& inputs = query.inputs;
  const GroundTruth& truth = query.truth;
  const std::string map_log_path =
      options.query.truth_path.empty() ? options.query.log_path : options.query.truth_path;
  std::vector<LocalizationRecord> records;
  std::size_t places = 0;
  std::size_t requested_starts = 0;
  std::string map_description;
  bool truth_is_map_log = true;  // the TIP-FLIRT places are scans of the truth log
  double recognition_seconds = 0.0;
  if (!baseline) {
    GlobalMap map = LoadMap(options.map_path);
    truth_is_map_log = TruthIsMapLog(map, truth);
    WarnAboutMapSource(options.map_path, map, map_log_path, truth_is_map_log);
    if (!truth_is_map_log) {
      fmt::print(
          "self-match         none: the query log is another recording than the map's {} (no "
          "self-match exclusion)\n",
          map.source_log);
    }
    map_description = fmt::format("{} ({} submaps, {} keypoints)", options.map_path,
                                  map.submaps.size(), map.KeypointCount());
    if (!options.distractor_paths.empty()) {
      // Past every scan of the query and truth logs: with --scans the queries follow the map's
      // scans in the same file, and the self-match rule compares their indices.
      const auto logs_scans =
          std::max(inputs.file_scans, truth.truth_first_scan + truth.truth_poses.size());
      map = WithDistractors(map, options.distractor_paths, options.distractor_submaps,
                            static_cast<int>(logs_scans));
      map_description += fmt::format(" among distractors: {} submaps, {} keypoints",
                                     map.submaps.size(), map.KeypointCount());
    }
    MapLocalizationOptions localization;
    localization.n_pos = options.n_pos;
    localization.self_match = rule;
    localization.rank_by = rank_by;
    MapLocalization result = LocalizeLogAgainstMap(
        inputs, truth, map, config.place, config.evaluation, localization, StageProgressBar());
    requested_starts = result.starts.size();
    rule = result.self_match;
    places = result.places;
    records = std::move(result.records);
    recognition_seconds = result.seconds_recognition;
  } else {
    const std::vector<int> starts = QueryStarts(truth, options.n_pos);
    requested_starts = starts.size();
    LogInputOptions map_options = query.input_options;
    map_options.poses = PoseSource::kCorrected;
    // --scans cuts the query log; the places of a --truth log are all of its scans.
    map_options.first_scan = 0;
    map_options.end_scan = LogInputOptions{}.end_scan;
    const LogInputs map_log = options.query.truth_path.empty()
                                  ? inputs
                                  : PrepareLogInputs(options.query.truth_path, map_options);
    if (!options.query.truth_path.empty()) PrintInputsWarnings(map_log);
    std::vector<Place> scan_places = ScanPlaces(map_log);
    const std::vector<Submap> map_scans = ScanPlacesAsSubmaps(scan_places);
    places = scan_places.size();
    map_description = fmt::format("TIP-FLIRT: {} scans of {} as places", places, map_log_path);
    const std::vector<LocalizationQuery> queries = BuildScanQueries(inputs, truth, starts);
    const auto recognition_start = std::chrono::steady_clock::now();
    records = EvaluateLocalizationQueries(queries, std::move(scan_places), map_scans, config.place,
                                          rule, config.evaluation, StageProgressBar());
    recognition_seconds = SecondsSince(recognition_start);
  }
  if (requested_starts < static_cast<std::size_t>(options.n_pos)) {
    fmt::print(stderr,
               "keyplace: note: --n-pos {} capped to the {} query scans with a truth pose\n",
               options.n_pos, requested_starts);
  }
  const double preparation_seconds = SecondsSince(start) - recognition_seconds;

  LocalizeReport report;
  report.log_path = options.query.log_path;
  report.map_description = map_description;
  report.pose_source = inputs.pose_source;
  report.log_scans = inputs.log.scans.size();
  report.n_requested = options.n_pos;
  report.preset = options.config.preset;
  report.baseline = baseline;
  report.exclude_shared_scans = options.exclude_shared_scans;
  report.self_match = rule;
  report.truth_is_map_log = truth_is_map_log;
  report.first_scan = inputs.first_scan;
  report.file_scans = inputs.file_scans;
  report.skipped_lines = inputs.log.skipped_lines;
  report.evaluation = config.evaluation;
  report.place = config.place;
  report.summary = Summarize(records, rank_by);
  report.preparation_seconds = preparation_seconds;
  report.preparation_from_cache = inputs.poses_from_cache || inputs.keypoints_from_cache;
  PrintLocalizeReport(report);
  if (!options.queries_path.empty())
    WriteQueriesTsv(options.queries_path, records, inputs.first_scan);
  if (!options.curve_path.empty()) WriteCurveTsv(options.curve_path, report.summary.curve);
  if (!options.reliability_path.empty()) {
    WriteReliabilityTsv(options.reliability_path, report.summary.reliability);
  }
  if (!options.json_path.empty()) {
    nlohmann::json json = LocalizeJson(report, records);
    json["map"] = baseline ? "" : options.map_path;
    json["baseline"] = options.baseline;
    json["truth"] = options.query.truth_path;
    json["places"] = places;
    json["config"] = ConfigJson(config);
    json["seconds_total"] = SecondsSince(start);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterLocalizeCommand(CLI::App& app) {
  auto options = std::make_shared<LocalizeOptions>();
  CLI::App* command = app.add_subcommand(
      "localize",
      "Global localization against a map (paper Algorithm 4): query submaps from n_pos equally "
      "spaced starts, place recognition, precision/recall (also over the revisitable queries: "
      "a map scan within evaluation.revisit_radius_m / revisit_angle_deg), P_GL/P_CL, the "
      "confidence's reliability diagram, or the TIP-FLIRT single-scan baseline.");
  command->add_option("--map", options->map_path, "Map file (.kpm) built from the corrected log")
      ->check(CLI::ExistingFile);
  AddQueryLogOptions(command, options->query,
                     "Query poses: corrected (the log's), icp (scan matching on odometry) or "
                     "odometry");
  command->add_option("--mu", options->mu, "Alias of --set place.min_pairs=N (default 10)");
  command->add_option("--gamma-min", options->gamma_min,
                      "Sets place.min_gamma and place.min_gamma_all_scans (defaults 0.4 and 0.15; "
                      "0 with --baseline tip-flirt)");
  command->add_option("--lambda", options->lambda, "Alias of --set place.double_match_m=M");
  command->add_option("--min-confidence", options->min_confidence,
                      "Alias of --set place.min_confidence=C (0..1)");
  command
      ->add_option("--descriptor-index", options->descriptor_index,
                   "Alias of --set place.descriptor_index=X: dense (default), kdtree or none "
                   "(exhaustive; all find the same pairs)")
      ->check(CLI::IsMember({"dense", "kdtree", "none"}));
  CLI::Option* distractors =
      command
          ->add_option("--distractors", options->distractor_paths,
                       "Map files (.kpm, comma-separated) whose submaps are copied, moved far away "
                       "(one rigid transform per copy), among the map's: the scale benchmark "
                       "(docs/BENCHMARKS.md, \"Map size\")")
          ->check(CLI::ExistingFile)
          ->delimiter(',');
  command
      ->add_option("--distractor-submaps", options->distractor_submaps,
                   "Submaps of the map with its distractors, the map's own included")
      ->needs(distractors);
  distractors->needs("--distractor-submaps");
  AddConfigOptions(command, options->config);
  command->add_option("--n-pos", options->n_pos, "Number of queries")->capture_default_str();
  command->add_flag("--exclude-shared-scans", options->exclude_shared_scans,
                    "Skip every map submap sharing a scan with the query (default: only submaps "
                    "built from exactly the query's scans, the paper's rule). Either rule applies "
                    "only when the truth log is the map's own log (same file fingerprint); "
                    "queries from another recording exclude nothing");
  command
      ->add_option("--baseline", options->baseline,
                   "tip-flirt: every scan of the corrected log is a place, each query one scan, "
                   "accepted on the RANSAC consensus (no gamma check unless --gamma-min), ranked "
                   "by consensus")
      ->check(CLI::IsMember({"tip-flirt"}));
  command
      ->add_option("--rank-by", options->rank_by,
                   "Score ranking answers for the P/R curve: confidence (default preset), gamma "
                   "(paper preset), consensus (tip-flirt) or score")
      ->check(CLI::IsMember({"confidence", "gamma", "consensus", "score"}));
  command->add_option("--json", options->json_path, "Write the figures as JSON to FILE");
  command->add_option("--queries", options->queries_path, "Write one TSV row per query to FILE");
  command->add_option("--curve", options->curve_path, "Write the precision-recall curve (TSV)");
  command->add_option("--reliability", options->reliability_path,
                      "Write the reliability diagram (TSV): accepted answers in 10 confidence "
                      "bins, mean confidence and observed precision per bin");
  command->callback([command, options] {
    RunOnWorkerThreads(options->query.threads, [&] { RunLocalize(*command, *options); });
  });
}

}  // namespace keyplace::cli
