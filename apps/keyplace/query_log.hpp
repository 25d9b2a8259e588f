#pragma once
// The query log of the localization commands (localize, relocalize): its options (--log, --poses,
// --truth, --index, --scans, --skip-bad-lines, and --threads for the work on it) and reading it
// with its ground truth.

#include <string>

#include <CLI/CLI.hpp>

#include "keyplace/config/config.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {

struct QueryLogOptions {
  std::string log_path;
  std::string poses = "corrected";
  std::string truth_path;
  std::string index_path;
  std::string scans;
  bool skip_bad_lines = false;
  std::string cache_dir;  // --cache (LogInputOptions::cache_dir)
  int threads = 0;        // worker threads for keypoints and queries (WorkerThreads: 0 = all cores)
};

/// Registers the options; `poses_help` says what the poses are used for.
void AddQueryLogOptions(CLI::App* command, QueryLogOptions& options, const std::string& poses_help);

struct QueryLog {
  LogInputOptions input_options;  // as the log was read (for more logs read alike)
  LogInputs inputs;
  bool has_truth = false;  // false: no --truth and the log has no corrected poses
  GroundTruth truth;       // when has_truth
};

/// Reads the log (poses, keypoints, the --scans cut) with progress, prints its warnings and loads
/// its ground truth (its own corrected poses, or --truth through --index). An empty
/// options.poses takes the log's corrected poses if it has them, else ICP. Without truth the
/// error asks for --truth, unless `truth_optional` (then has_truth is false).
QueryLog ReadQueryLog(const QueryLogOptions& options, const Config& config,
                      bool truth_optional = false);

}  // namespace keyplace::cli
