#pragma once
// Internal: when a robot node sends something again (its status, map -> odom, /map).

#include <optional>

namespace keyplace {

/// True when nothing was sent yet, `period_s` has passed since `last_s`, or the clock went back
/// (a bag started again): then it is due now.
inline bool PeriodElapsed(const std::optional<double>& last_s, double now_s, double period_s) {
  return !last_s || now_s < *last_s || now_s - *last_s >= period_s;
}

}  // namespace keyplace
