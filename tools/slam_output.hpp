#pragma once
// The outputs of `keyplace slam`: the printed summary beside the paper's figures, the JSON of
// figures, the loops and trajectory TSVs and the pictures (slam_figures.hpp).

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "keyplace/config/config.hpp"
#include "keyplace/eval/slam_evaluation.hpp"

namespace keyplace::cli {

/// What a SLAM run's outputs show.
struct SlamReport {
  std::string log_path;
  std::optional<std::string> dataset;  // DatasetName of the log
  const SlamRun& run;
  const SlamEvaluation& evaluation;
  const Config& config;
};

/// The loops, the map beside paper Table IX, ATE / RPE and relation errors, on stdout.
void PrintSlamReport(const SlamReport& report);

/// The figures as JSON; `total_seconds` of the whole command.
nlohmann::json SlamJson(const SlamReport& report, double total_seconds);

/// One row per scan (processing order): scan_index, timestamp, SLAM pose, submap, ICP pose.
void WriteTrajectoryTsv(const std::string& path, const SlamRun& run);

/// One row per detected loop under a header naming the columns; written atomically.
void WriteLoopsTsv(const std::string& path, const SlamRun& run, const LoopEvaluation& evaluation);

/// trajectory.png, overlap_histogram*.png and, with ground truth, rpe.png and ate.png in `dir`.
void DrawSlamFigures(const std::string& dir, const SlamReport& report);

}  // namespace keyplace::cli
