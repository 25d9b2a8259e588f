#pragma once
// Helpers shared by the subcommands: output files, JSON, progress, argument parsing.

#include <chrono>
#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "keyplace/io/carmen_log.hpp"

namespace keyplace::cli {

/// Reads a CARMEN log and throws std::invalid_argument when it holds no laser scans (so that a
/// wrong file is reported instead of giving empty results).
CarmenLog ReadLogWithScans(const std::string& path);

/// Writes `json` (pretty-printed) to `path` atomically.
void WriteJson(const std::string& path, const nlohmann::json& json);

/// A half-open scan range "A:B" (either side may be empty: ":100", "50:"), clamped to `count`.
struct ScanRange {
  std::size_t begin = 0;
  std::size_t end = 0;
};
ScanRange ParseScanRange(const std::string& text, std::size_t count);

/// A progress line on stderr ("label  123/456  27 %  ETA 12 s"), at most a few times a second,
/// and only when stderr is a terminal or KEYPLACE_PROGRESS=1.
class Progress {
 public:
  Progress(std::string label, std::size_t total);
  void Update(std::size_t done);
  void Finish();

 private:
  std::string label_;
  std::size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
};

}  // namespace keyplace::cli
