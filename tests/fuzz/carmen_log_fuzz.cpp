// libFuzzer harness of the CARMEN log reader (ReadCarmenLog): plain and gzip text, every message
// type. Correct rejection is std::invalid_argument (malformed line) or std::runtime_error
// (compressed data cut off) naming the file; anything else, and a log that breaks the reader's
// documented guarantees, is a finding.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace {

using keyplace::fuzz::Finding;

bool Finite(const keyplace::Pose2& pose) {
  return std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta);
}

// What every log the reader accepts guarantees (carmen_log.hpp, laser_scan.hpp,
// docs/RELIABILITY.md): beams within the cap with one angle and one validity flag each, finite
// angles and poses, valid beams with usable ranges.
void CheckLog(const keyplace::CarmenLog& log) {
  for (const keyplace::LogScan& scan : log.scans) {
    const std::string where = "scan of line " + std::to_string(scan.line);
    if (scan.size() > keyplace::kMaxScanBeams) Finding(where + ": more beams than kMaxScanBeams");
    if (scan.angles_rad.size() != scan.size() || scan.valid.size() != scan.size()) {
      Finding(where + ": ranges, angles and valid flags differ in length");
    }
    for (std::size_t i = 0; i < scan.size(); ++i) {
      if (!std::isfinite(scan.angles_rad[i])) Finding(where + ": a beam angle is not finite");
      const double range = scan.ranges_m[i];
      if (scan.valid[i] != 0 &&
          !(std::isfinite(range) && range >= 0.0 && range < scan.max_range_m)) {
        Finding(where + ": a beam marked valid has an unusable range");
      }
    }
    if (!Finite(scan.logged_laser_pose) || !Finite(scan.T_robot_laser) ||
        (scan.odometry_pose && !Finite(*scan.odometry_pose)) ||
        (scan.corrected_pose && !Finite(*scan.corrected_pose))) {
      Finding(where + ": a pose is not finite");
    }
  }
  for (const keyplace::OdometryMessage& odometry : log.odometry) {
    if (!Finite(odometry.pose)) Finding("an ODOM pose is not finite");
  }
  if (log.skipped_line_numbers.size() > keyplace::CarmenLog::kMaxListedSkippedLines) {
    Finding("more skipped line numbers listed than kMaxListedSkippedLines");
  }
}

// Reads the file; true when it was rejected with a documented error.
bool Read(const std::string& path, const keyplace::CarmenReadOptions& options) {
  try {
    CheckLog(keyplace::ReadCarmenLog(path, options));
    return false;
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  } catch (const std::runtime_error& error) {
    keyplace::fuzz::ExpectNamedError("std::runtime_error", error.what(), path);
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("carmen-log");
  const std::string& path = file.Write(data, size);
  if (Read(path, {})) {
    // The same input again, skipping malformed lines: the other path through the reader.
    keyplace::CarmenReadOptions skipping;
    skipping.skip_bad_lines = true;
    Read(path, skipping);
  }
  return 0;
}
