#pragma once
// Whether a log's timestamps can order its scans: zero stamps, repeated ones (too coarse, e.g.
// kept to 6 significant digits), stamps running backwards and 32-bit wraps are counted, so that
// `info` can warn and the commands that order scans by time can refuse instead of computing a
// meaningless order (`--order file` processes the scans as the file lists them).

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

struct TimestampCheck {
  std::size_t stamps = 0;
  std::size_t zero = 0;  // exactly 0
  // Of them, after a nonzero stamp (a leading 0 sorts first anyway: FR079's raw log starts with
  // one).
  std::size_t zero_after_nonzero = 0;
  std::size_t repeated = 0;    // equal to the previous stamp
  std::size_t backwards = 0;   // earlier than the previous stamp (a wrap not counted)
  std::size_t wraps = 0;       // earlier by more than 2^31 s: a 32-bit counter that wrapped
  double resolution_s = 0.0;   // smallest positive step between consecutive stamps (0: none)
  double median_step_s = 0.0;  // median positive step
  // One sentence per problem, for people ("12 of 120 timestamps are 0").
  std::vector<std::string> warnings;

  /// Sorting by these stamps gives the order the scans were taken in: no zero after a nonzero
  /// stamp, no wrap,
  /// and at most 1 % repeated stamps (a stable sort keeps those in file order).
  bool CanOrder() const;
};

/// `stamps` in file order.
TimestampCheck CheckTimestamps(const std::vector<double>& stamps);

/// The same for one kind of stamp of a log's scans.
enum class TimestampSource { kLogger, kIpc };
TimestampCheck CheckTimestamps(const std::vector<LogScan>& scans, TimestampSource source);

/// Throws std::invalid_argument naming `what` (e.g. "LOG: logger timestamps") and every problem
/// when `check` cannot order the scans, suggesting `--order file`.
void RequireTimeOrder(const TimestampCheck& check, const std::string& what);

}  // namespace keyplace
