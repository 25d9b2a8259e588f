#pragma once
// Internal: the wall time of a step, for the seconds_* fields of results and statistics.

#include <chrono>

namespace keyplace {

/// Seconds elapsed on the steady clock since `start`.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace keyplace
