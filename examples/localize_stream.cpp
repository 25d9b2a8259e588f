// Streams a log through keyplace::GlobalLocalizer, scan by scan, as a robot would, and prints
// every fix with its confidence.
//
//   localize_stream MAP.kpm LOG [--truth]
//
// MAP.kpm comes from `keyplace map`; LOG is a CARMEN log. The localizer is fed each scan with the
// robot's odometry pose (a raw log's odometry, or a corrected log's poses standing in for it);
// with --truth (corrected logs) each fix is also compared with the log's corrected pose.

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "keyplace/eval/localization.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/localization/global_localizer.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s MAP.kpm LOG [--truth]\n", argv[0]);
    return 2;
  }
  try {
    const bool check_truth = argc > 3 && std::string(argv[3]) == "--truth";
    keyplace::GlobalLocalizer localizer = keyplace::GlobalLocalizer::FromFile(argv[1]);
    const keyplace::CarmenLog log = keyplace::ReadCarmenLogWithScans(argv[2]);
    int fixes = 0;
    int correct = 0;
    for (std::size_t k = 0; k < log.scans.size(); ++k) {
      const keyplace::LogScan& scan = log.scans[k];
      const auto& odometry = scan.odometry_pose ? scan.odometry_pose : scan.corrected_pose;
      if (!odometry) continue;  // no pose to feed this scan with
      const std::optional<keyplace::LocalizationResult> result = localizer.AddScan(scan, *odometry);
      if (!result || !result->found) continue;
      ++fixes;
      const keyplace::Pose2& pose = result->T_world_robot;
      std::printf("scan %5zu  x %8.3f m  y %8.3f m  theta %7.2f deg  confidence %.2f  submap %d", k,
                  pose.x, pose.y, pose.theta * 180.0 / M_PI, result->confidence, result->submap_id);
      if (check_truth && scan.corrected_pose) {
        const bool ok = keyplace::IsCorrectPose(pose, *scan.corrected_pose);
        correct += ok ? 1 : 0;
        std::printf("  %s", ok ? "correct" : "WRONG");
      }
      std::printf("\n");
    }
    std::printf("%d fixes", fixes);
    if (check_truth) std::printf(", %d correct", correct);
    std::printf("\n");
  } catch (const std::exception& error) {
    std::fprintf(stderr, "localize_stream: %s\n", error.what());
    return 1;
  }
  return 0;
}
