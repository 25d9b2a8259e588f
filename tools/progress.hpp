#pragma once
// Progress of long runs on stderr, for the commands and the library's stage callbacks.

#include <chrono>
#include <cstddef>
#include <string>

#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {

/// Progress on stderr. On a terminal a bar that rewrites itself ("label  123/456  27 %  ETA 12 s"),
/// at most a few times a second. Elsewhere (a log file, CI) whole lines: one when the work starts,
/// one every kProgressLineSeconds and one when it ends ("keyplace: label  456/456  done in 80.1
/// s"). KEYPLACE_PROGRESS=0 prints nothing, =1 the bar, =lines the lines, wherever stderr goes.
class Progress {
 public:
  Progress(std::string label, std::size_t total);
  void Update(std::size_t done);
  void Finish();

 private:
  enum class Mode { kOff, kBar, kLines };
  std::string label_;
  std::size_t total_;
  Mode mode_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
  bool started_ = false;
};

/// Seconds between two progress lines when stderr is not a terminal.
constexpr double kProgressLineSeconds = 5.0;

/// Progress lines for the stages of PrepareLogInputs (one Progress per stage).
StageProgress StageProgressBar();

}  // namespace keyplace::cli
