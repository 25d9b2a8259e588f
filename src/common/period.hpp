#pragma once
// Internal: when a robot node sends something again (its status, map -> odom, /map).

#include <optional>

namespace keyplace {

/// True when nothing was sent yet, `period_s` has passed since `last_s`, or the clock went back
/// by more than a period (a bag started again): then it is due now. Odometry, scans and the clock
/// interleave their stamps, so a time a little before `last_s` is not a new start.
inline bool PeriodElapsed(const std::optional<double>& last_s, double now_s, double period_s) {
  return !last_s || now_s - *last_s >= period_s || now_s < *last_s - period_s;
}

}  // namespace keyplace
