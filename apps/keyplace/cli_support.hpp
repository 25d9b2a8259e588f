#pragma once
// Helpers shared by the subcommands: option help, threads, scan ranges, output checks (with
// command_output.hpp and progress.hpp from tools/).

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "command_output.hpp"
#include "common/seconds_since.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "progress.hpp"

namespace keyplace::cli {

/// ReadCarmenLogWithScans: a file without laser scans is an error naming it.
inline CarmenLog ReadLogWithScans(const std::string& path, const CarmenReadOptions& options = {}) {
  return ReadCarmenLogWithScans(path, options);
}

/// Help text of --skip-bad-lines (CarmenReadOptions::skip_bad_lines).
inline constexpr const char* kSkipBadLinesHelp =
    "Skip malformed log lines (counted and reported) instead of stopping at the first one";

/// Help text of --cache (LogInputOptions::cache_dir).
inline constexpr const char* kCacheHelp =
    "Directory keeping the log's ICP poses and FLIRT keypoints between runs (created if "
    "missing): a later run over the same log with the same settings reads them instead of "
    "computing them; the results are the same bit for bit. Entries are keyed by the log's "
    "content, the settings and the code that computes them";

/// The worker threads of --threads N: N, or every core when N is 0. Throws
/// std::invalid_argument for N < 0.
std::size_t WorkerThreads(int threads);

/// Runs `work` with its parallel loops on exactly WorkerThreads(threads) threads, also when that
/// is more than the cores (--threads 8 on two cores runs eight), so that a result's independence
/// of the thread count can be checked on any machine.
void RunOnWorkerThreads(int threads, const std::function<void()>& work);

/// A half-open scan range "A:B" (either side may be empty: ":100", "50:"), clamped to `count`.
struct ScanRange {
  std::size_t begin = 0;
  std::size_t end = 0;
};
ScanRange ParseScanRange(const std::string& text, std::size_t count);

/// The one check every command that writes runs before any work: CheckOutputPath on every given
/// output (option name, path; empty paths are skipped) against the inputs, and no two outputs the
/// same file; throws std::invalid_argument naming the option. The inputs are every value given
/// on the command line to `command` (positionals included) except to the outputs' own options,
/// so that no input can be forgotten, plus `more_inputs` (files named elsewhere).
void CheckOutputs(const CLI::App& command,
                  const std::vector<std::pair<std::string, std::string>>& outputs,
                  const std::vector<std::string>& more_inputs = {});

/// Refuses `path` (given to `option`) when it names one of `reserved`, the files a command keeps
/// in its own output directory (a sweep's resume identity, a report's page), whether they exist
/// yet or not: writing the JSON there would replace them.
void CheckNotReserved(const std::string& option, const std::string& path,
                      const std::vector<std::string>& reserved, const std::string& owner);

/// The outputs of --grid FILE.yaml: the YAML and its image (MapServerImagePath), for CheckOutputs;
/// none when `yaml_path` is empty.
std::vector<std::pair<std::string, std::string>> GridOutputs(const std::string& yaml_path);

/// --scans A:B as the scans [A, B) of the file that PrepareLogInputs keeps (clamped to the log
/// there); nothing when `text` is empty.
void ApplyScanRange(const std::string& text, LogInputOptions& options);

}  // namespace keyplace::cli
