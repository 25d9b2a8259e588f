// keyplace merge A.kpm B.kpm --out C.kpm: where map B (another session, its own frame) lies in
// map A, found by place recognition of B's submaps, and the two joined in A's frame.

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/store/map_file.hpp"

namespace keyplace::cli {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

struct MergeCommandOptions {
  std::string map_a;
  std::string map_b;
  std::string out_path;
  std::string json_path;
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

nlohmann::json MergeJson(const MergeCommandOptions& options, const MergeResult& result) {
  nlohmann::json json;
  json["map_a"] = options.map_a;
  json["map_b"] = options.map_b;
  json["T_a_b"] = {
      {"x_m", result.T_a_b.x}, {"y_m", result.T_a_b.y}, {"theta_rad", result.T_a_b.theta}};
  json["submaps_queried"] = result.queried;
  json["recognised"] = result.recognitions.size();
  json["agreeing"] = result.agreeing;
  json["submaps_merged"] = result.merged.submaps.size();
  nlohmann::json recognitions = nlohmann::json::array();
  for (const SubmapRecognition& r : result.recognitions) {
    recognitions.push_back({{"submap_b", r.submap_b},
                            {"submap_a", r.submap_a},
                            {"confidence", r.confidence},
                            {"agrees", r.agrees},
                            {"x_m", r.T_a_b.x},
                            {"y_m", r.T_a_b.y},
                            {"theta_rad", r.T_a_b.theta}});
  }
  json["recognitions"] = recognitions;
  return json;
}

void RunMerge(const MergeCommandOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckOutputs({{"--out", options.out_path}, {"--json", options.json_path}},
               {options.map_a, options.map_b});
  const Config config = ResolveConfig(options.config);
  const GlobalMap a = LoadMap(options.map_a);
  const GlobalMap b = LoadMap(options.map_b);
  // The library names the maps by their logs; the user gave these files.
  const MergeResult result = [&] {
    try {
      // A progress line on stderr (a terminal, or KEYPLACE_PROGRESS=1): recognising B's submaps
      // in A is the long part.
      return MergeMaps(a, b, config.place, config.merge,
                       [bar = StageProgressBar()](std::size_t done, std::size_t total) {
                         bar("submaps of B", done, total);
                       });
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(options.map_b + " into " + options.map_a + ": " + error.what());
    }
  }();
  SaveMap(result.merged, options.out_path);
  PrintMerge(options, result);
  if (!options.json_path.empty()) {
    nlohmann::json json = MergeJson(options, result);
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
      "otherwise. A progress line with ETA on stderr when it is a terminal or KEYPLACE_PROGRESS=1 "
      "(docs/MERGE.md).");
  command->add_option("a", options->map_a, "Map A (.kpm): the frame of the result")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("b", options->map_b, "Map B (.kpm), made with the same mapping settings")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out_path, "Write the merged map to this file (.kpm)")
      ->required();
  command->add_option("--json", options->json_path,
                      "Write the transform and every recognition as JSON to FILE");
  // Joining maps acts on the answer as a robot would: the strict preset (see relocalize).
  options->config.preset = "strict";
  AddConfigOptions(command, options->config);
  command->callback([options] { RunMerge(*options); });
}

}  // namespace keyplace::cli
