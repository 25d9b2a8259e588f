#include "keyplace/io/timestamps.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace keyplace {
namespace {

constexpr double kWrapJumpS = 2147483648.0;  // 2^31 s backwards: a 32-bit counter wrapped

}  // namespace

bool TimestampCheck::CanOrder() const {
  return zero_after_nonzero == 0 && wraps == 0 && repeated * 100 <= stamps;
}

TimestampCheck CheckTimestamps(const std::vector<double>& stamps) {
  TimestampCheck check;
  check.stamps = stamps.size();
  std::vector<double> steps;
  bool nonzero_seen = false;
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    if (stamps[i] == 0.0) {
      ++check.zero;
      if (nonzero_seen) ++check.zero_after_nonzero;
    } else {
      nonzero_seen = true;
    }
    if (i == 0) continue;
    const double step = stamps[i] - stamps[i - 1];
    if (step == 0.0) {
      ++check.repeated;
    } else if (step < -kWrapJumpS) {
      ++check.wraps;
    } else if (step < 0.0) {
      ++check.backwards;
    } else {
      steps.push_back(step);
    }
  }
  if (!steps.empty()) {
    check.resolution_s = *std::min_element(steps.begin(), steps.end());
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                     steps.end());
    check.median_step_s = steps[steps.size() / 2];
  }
  const std::string of = " of " + std::to_string(check.stamps);
  if (check.zero > 0) check.warnings.push_back(std::to_string(check.zero) + of + " are 0");
  if (check.repeated > 0) {
    std::ostringstream resolution;
    resolution << check.resolution_s;
    check.warnings.push_back(std::to_string(check.repeated) + of +
                             " repeat the previous one (resolution " + resolution.str() +
                             " s: too coarse?)");
  }
  if (check.backwards > 0) {
    check.warnings.push_back(std::to_string(check.backwards) + of +
                             " run backwards (the file is not in time order)");
  }
  if (check.wraps > 0) {
    check.warnings.push_back(std::to_string(check.wraps) + of +
                             " jump back by more than 2^31 s (a 32-bit counter wrapped)");
  }
  return check;
}

TimestampCheck CheckTimestamps(const std::vector<LogScan>& scans, TimestampSource source) {
  std::vector<double> stamps;
  stamps.reserve(scans.size());
  for (const LogScan& scan : scans) {
    stamps.push_back(source == TimestampSource::kLogger ? scan.logger_timestamp_s
                                                        : scan.timestamp_s);
  }
  return CheckTimestamps(stamps);
}

void RequireTimeOrder(const TimestampCheck& check, const std::string& what) {
  if (check.CanOrder()) return;
  std::string message = what + " cannot order the scans:";
  for (const std::string& warning : check.warnings) message += " " + warning + ";";
  message += " give --order file to process the scans as the file lists them";
  throw std::invalid_argument(message);
}

}  // namespace keyplace
