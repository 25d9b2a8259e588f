// keyplace merge A.kpm B.kpm --out C.kpm: where map B (another session, its own frame) lies in
// map A, found by place recognition of B's submaps, and the two joined in A's frame.

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "eval_json.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/merge_evaluation.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/store/map_file.hpp"
#include "result_json.hpp"

namespace keyplace::cli {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

struct MergeCommandOptions {
  std::string map_a;
  std::string map_b;
  std::string out_path;
  std::string json_path;
  std::string log_path;    // the log both maps were made from: evaluate against its truth
  std::string truth_path;  // a raw --log's corrected log, paired by --index
  std::string index_path;
  ConfigOptions config;
};

void PrintMerge(const MergeCommandOptions& options, const MergeResult& result) {
  fmt::print("B in A               x {:.3f} m, y {:.3f} m, heading {:.2f} deg\n", result.T_a_b.x,
             result.T_a_b.y, result.T_a_b.theta * kDegPerRad);
  fmt::print("recognitions         {} of {} submaps of B recognised in A, {} agreeing\n",
             result.recognitions.size(), result.queried, result.agreeing);
  fmt::print("merged map           {} submaps written to {}\n", result.merged.submaps.size(),
             options.out_path);
}

void PrintEvaluation(const MergeEvaluation& evaluation) {
  const MergePlacementError& origins = evaluation.at_origins;
  fmt::print(
      "error at the origins  {:.3f} m, {:.3f} deg (B's scan {} seen from A's scan {}: the frames, "
      "with both sessions' drift)\n",
      origins.error.translation_m, origins.error.rotation_deg, origins.scan_b, origins.scan_a);
  const ErrorStats& stats = evaluation.at_recognitions_stats;
  if (stats.count == 0) {  // an empty mean is not a perfect merge
    fmt::print("error where they meet none: no agreeing recognition has truth poses ({} without)\n",
               evaluation.recognitions_without_truth);
    return;
  }
  fmt::print(
      "error where they meet {:.3f} m, {:.3f} deg mean, {:.3f} m, {:.3f} deg max over {} agreeing "
      "recognitions with truth poses ({} without)\n",
      stats.translation_mean_m, stats.rotation_mean_deg, stats.translation_max_m,
      stats.rotation_max_deg, stats.count, evaluation.recognitions_without_truth);
  const ErrorStats& alone = evaluation.recognitions_alone_stats;
  fmt::print(
      "each recognition alone {:.3f} m, {:.3f} deg mean, {:.3f} m, {:.3f} deg max (its own "
      "transform)\n",
      alone.translation_mean_m, alone.rotation_mean_deg, alone.translation_max_m,
      alone.rotation_max_deg);
}

// StatsJson (eval_json.hpp) with every figure null when there is none: an empty mean is not a
// perfect merge.
nlohmann::json ErrorsJson(const ErrorStats& stats) {
  nlohmann::json json = StatsJson(stats);
  if (stats.count == 0) {
    for (auto& [key, value] : json.items()) {
      if (key != "count") value = nullptr;
    }
  }
  return json;
}

nlohmann::json PlacementJson(const MergePlacementError& placement) {
  return {{"scan_a", placement.scan_a},
          {"scan_b", placement.scan_b},
          {"submap_a", placement.submap_a},
          {"submap_b", placement.submap_b},
          {"true_T_a_scan_b",
           {{"x_m", placement.true_T_a_scan_b.x},
            {"y_m", placement.true_T_a_scan_b.y},
            {"theta_rad", placement.true_T_a_scan_b.theta}}},
          {"translation_error_m", placement.error.translation_m},
          {"rotation_error_deg", placement.error.rotation_deg},
          {"recognition_translation_error_m", placement.recognition_error.translation_m},
          {"recognition_rotation_error_deg", placement.recognition_error.rotation_deg}};
}

nlohmann::json EvaluationJson(const MergeCommandOptions& options,
                              const MergeEvaluation& evaluation) {
  nlohmann::json json;
  json["log"] = options.log_path;
  json["truth"] = options.truth_path;
  json["index"] = options.index_path;
  json["at_origins"] = PlacementJson(evaluation.at_origins);
  const ErrorStats& stats = evaluation.at_recognitions_stats;
  json["at_recognitions"] = ErrorsJson(stats);
  json["at_recognitions"]["without_truth"] = evaluation.recognitions_without_truth;
  json["recognitions_alone"] = ErrorsJson(evaluation.recognitions_alone_stats);
  nlohmann::json items = nlohmann::json::array();
  for (const MergePlacementError& placement : evaluation.at_recognitions) {
    items.push_back(PlacementJson(placement));
  }
  json["at_recognitions"]["items"] = items;
  return json;
}

nlohmann::json MergeJson(const MergeCommandOptions& options, const MergeResult& result) {
  nlohmann::json json;
  json["map_a"] = options.map_a;
  json["map_b"] = options.map_b;
  json["T_a_b"] = {
      {"x_m", result.T_a_b.x}, {"y_m", result.T_a_b.y}, {"theta_rad", result.T_a_b.theta}};
  AddResultFields(result, MergeResultFields(), json);
  nlohmann::json recognitions = nlohmann::json::array();
  for (const SubmapRecognition& r : result.recognitions) {
    nlohmann::json recognition = {
        {"x_m", r.T_a_b.x}, {"y_m", r.T_a_b.y}, {"theta_rad", r.T_a_b.theta}};
    AddResultFields(r, SubmapRecognitionFields(), recognition);
    recognitions.push_back(recognition);
  }
  json["recognitions"] = recognitions;
  return json;
}

void RunMerge(const CLI::App& command, const MergeCommandOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs(command, {{"--out", options.out_path}, {"--json", options.json_path}});
  if (options.log_path.empty() && !(options.truth_path.empty() && options.index_path.empty())) {
    throw std::invalid_argument("--truth and --index need --log (the log the maps were made from)");
  }
  std::error_code same_error;
  if (std::filesystem::equivalent(options.map_a, options.map_b, same_error)) {
    throw std::invalid_argument(options.map_b + ": is the same file as " + options.map_a +
                                "; merging a map with itself adds nothing");
  }
  const Config config = ResolveConfig(options.config);
  const GlobalMap a = LoadMap(options.map_a);
  const GlobalMap b = LoadMap(options.map_b);
  // The truth is read before the long part, so that a wrong file fails at once.
  std::optional<CarmenLog> log;
  std::optional<GroundTruth> truth;
  if (!options.log_path.empty()) {
    log = ReadLogWithScans(options.log_path, ReadingOptions(config));
    truth = LoadGroundTruth(*log, 0, log->scans.size(), options.truth_path, options.index_path,
                            log->fingerprint);
    CheckMergeTruthSource(a, b, log->fingerprint);
  }
  // The library names the maps by their logs; the user gave these files.
  const MergeResult result = [&] {
    try {
      // Progress on stderr (Progress: a bar on a terminal, lines otherwise): recognising B's
      // submaps in A is the long part.
      return MergeMaps(a, b, config.place, config.merge,
                       [bar = StageProgressBar()](std::size_t done, std::size_t total) {
                         bar("submaps of B", done, total);
                       });
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(options.map_b + " into " + options.map_a + ": " + error.what());
    }
  }();
  std::optional<MergeEvaluation> evaluation;
  if (truth) evaluation = EvaluateMerge(a, b, result, *truth, log->fingerprint);
  SaveMap(result.merged, options.out_path);
  PrintMerge(options, result);
  if (evaluation) PrintEvaluation(*evaluation);
  if (!options.json_path.empty()) {
    nlohmann::json json = MergeJson(options, result);
    if (evaluation) json["evaluation"] = EvaluationJson(options, *evaluation);
    json["seconds_total"] = SecondsSince(start);
    json["config"] = ConfigJson(config);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterMergeCommand(CLI::App& app) {
  auto options = std::make_shared<MergeCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "merge",
      "Join map B (another session, in its own frame) to map A: every submap of B is recognised "
      "in A, the largest group of recognitions that agree on where B lies gives the transform "
      "(at least merge.min_agreeing), B is moved into A's frame and appended. Refuses, saying "
      "why, when no reliable overlap exists. Uses the strict preset unless --preset says "
      "otherwise. Progress with ETA on stderr: a bar on a terminal, a line every 5 s otherwise "
      "(KEYPLACE_PROGRESS=0 off, =1 the bar, =lines the lines; docs/MERGE.md).");
  command->add_option("a", options->map_a, "Map A (.kpm): the frame of the result")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("b", options->map_b, "Map B (.kpm), made with the same mapping settings")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out_path, "Write the merged map to this file (.kpm)")
      ->required();
  command->add_option("--json", options->json_path,
                      "Write the transform and every recognition (and the evaluation, with "
                      "--log) as JSON to FILE");
  command
      ->add_option("--log", options->log_path,
                   "The log both maps were made from (e.g. its two halves): print the error of "
                   "the transform against its corrected poses, at the maps' first scans and "
                   "where the maps meet (docs/MERGE.md)")
      ->check(CLI::ExistingPath);
  command
      ->add_option("--truth", options->truth_path,
                   "Corrected log giving the ground truth of a raw --log")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--index", options->index_path,
                   "raw_index<TAB>corrected_index file relating --log to --truth")
      ->check(CLI::ExistingFile);
  // Joining maps acts on the answer as a robot would: the strict preset (see relocalize).
  options->config.preset = "strict";
  AddConfigOptions(command, options->config);
  command->callback([command, options] { RunMerge(*command, *options); });
}

}  // namespace keyplace::cli
