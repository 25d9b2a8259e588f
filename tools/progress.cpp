#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <utility>

#include <fmt/core.h>

namespace keyplace::cli {

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)),
      total_(total),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {
  const char* env = std::getenv("KEYPLACE_PROGRESS");
  const std::string setting = env != nullptr ? env : "";
  if (setting == "0") {
    mode_ = Mode::kOff;
  } else if (setting == "1") {
    mode_ = Mode::kBar;
  } else if (setting == "lines") {
    mode_ = Mode::kLines;
  } else {
    mode_ = isatty(fileno(stderr)) != 0 ? Mode::kBar : Mode::kLines;
  }
}

void Progress::Update(std::size_t done) {
  if (mode_ == Mode::kOff || total_ == 0) return;
  const auto now = std::chrono::steady_clock::now();
  const auto interval = mode_ == Mode::kBar ? std::chrono::duration<double>(0.25)
                                            : std::chrono::duration<double>(kProgressLineSeconds);
  if (started_ && now - last_print_ < interval && done < total_) return;
  if (mode_ == Mode::kLines && done == total_) return;  // Finish says it
  started_ = true;
  last_print_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  const std::string eta = fraction > 0.0
                              ? fmt::format("ETA {:.0f} s", elapsed_s * (1.0 - fraction) / fraction)
                              : std::string("started");
  if (mode_ == Mode::kBar) {
    fmt::print(stderr, "\r{}  {}/{}  {:3.0f} %  {}   ", label_, done, total_, 100.0 * fraction,
               eta);
  } else {
    fmt::print(stderr, "keyplace: {}  {}/{}  {:.0f} %  {}\n", label_, done, total_,
               100.0 * fraction, eta);
  }
  std::fflush(stderr);
}

void Progress::Finish() {
  if (mode_ == Mode::kOff || total_ == 0) return;
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (mode_ == Mode::kBar) {
    fmt::print(stderr, "\r{}  {}/{}  done in {:.1f} s          \n", label_, total_, total_,
               elapsed_s);
  } else {
    fmt::print(stderr, "keyplace: {}  {}/{}  done in {:.1f} s\n", label_, total_, total_,
               elapsed_s);
  }
}

StageProgress StageProgressBar() {
  auto current = std::make_shared<std::unique_ptr<Progress>>();
  auto stage_name = std::make_shared<std::string>();
  return [current, stage_name](const std::string& stage, std::size_t done, std::size_t total) {
    if (*current == nullptr || *stage_name != stage) {
      *current = std::make_unique<Progress>(stage, total);
      *stage_name = stage;
    }
    (*current)->Update(done);
    if (done == total) (*current)->Finish();
  };
}
}  // namespace keyplace::cli
