// LogPathLengthM and FlaserSpacingRule on logs built in memory.

#include "keyplace/io/log_summary.hpp"

#include <gtest/gtest.h>

namespace keyplace {
namespace {

LogScan ScanAt(double x, double y, bool corrected) {
  LogScan scan;
  (corrected ? scan.corrected_pose : scan.odometry_pose) = Pose2(x, y, 0.0);
  return scan;
}

TEST(LogSummary, PathLengthFollowsThePosesOfTheLogsKindAndSkipsScansWithoutOne) {
  CarmenLog log;
  log.scans = {ScanAt(0, 0, false), ScanAt(3, 4, false), LogScan{}, ScanAt(3, 0, false)};
  EXPECT_DOUBLE_EQ(LogPathLengthM(log), 9.0);  // 5 m, then 4 m past the scan without a pose
  log.corrected = true;                        // the odometry poses no longer count
  EXPECT_DOUBLE_EQ(LogPathLengthM(log), 0.0);
  log.scans.push_back(ScanAt(1, 1, true));
  log.scans.push_back(ScanAt(1, 3, true));
  EXPECT_DOUBLE_EQ(LogPathLengthM(log), 2.0);
}

TEST(LogSummary, FlaserSpacingRuleNamesOneRuleMixedOrNone) {
  CarmenLog log;
  EXPECT_EQ(FlaserSpacingRule(log), "");
  log.flaser_scans_fov_over_beams = 3;
  EXPECT_EQ(FlaserSpacingRule(log), ToString(FlaserSpacing::kFovOverBeams));
  log.flaser_scans_fov_over_beams_minus_one = 1;
  EXPECT_EQ(FlaserSpacingRule(log), "mixed");
  log.flaser_scans_fov_over_beams = 0;
  EXPECT_EQ(FlaserSpacingRule(log), ToString(FlaserSpacing::kFovOverBeamsMinusOne));
}

TEST(LogSummary, FlaserSpacingTextSaysTheRuleOrBothWithTheirCounts) {
  EXPECT_EQ(FlaserSpacingText(5, 0),
            "step fov/n from -fov/2 (even beam count, FLIRTLib's convention)");
  EXPECT_EQ(FlaserSpacingText(0, 5),
            "step fov/(n-1), first and last beam at -fov/2 and +fov/2 (odd beam count)");
  EXPECT_EQ(FlaserSpacingText(2, 3).rfind("2 FLASER scans step fov/n from -fov/2", 0), 0U);
  EXPECT_NE(FlaserSpacingText(2, 3).find("; 3 step fov/(n-1)"), std::string::npos);
}

}  // namespace
}  // namespace keyplace
