#include "keyplace/eval/odometry_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "registration/synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::DegToRad;

// A robot drives part of a circle in the irregular room. Scan i (drive order) has logger stamp
// 1000 + 0.1 i and an ipc stamp out of that order (IpcStamp); the file holds the scans with
// neighbours swapped (1, 0, 3, 2, ...), so file order and processing order differ. Odometry =
// T_odom_world * truth, with a 5 % scale error per step when `drifting`.
struct Drive {
  std::vector<Pose2> truth_by_file;  // true robot pose of each file scan
  std::vector<std::size_t> drive_step_of_file;
  std::vector<LogScan> scans;  // file order
};

const Pose2 kOdomFromWorld(3.0, -2.0, 0.7);

// Every third step is stamped 0.25 s late by ipc, as Intel raw's ipc stamps are not monotonic.
double IpcStamp(int step) { return 50.0 + 0.1 * step + (step % 3 == 0 ? 0.25 : 0.0); }

Drive MakeDrive(int steps, bool drifting) {
  const auto world = testing::IrregularRoom();
  testing::ScanOptions options = testing::FrontLaser(180, 0.005);
  std::mt19937 rng(11);
  const Pose2 step(0.1, 0.0, DegToRad(4.5));
  std::vector<Pose2> truth;
  std::vector<LogScan> in_drive_order;
  Pose2 pose(0.5, -1.1, 0.0);
  Pose2 odometry = kOdomFromWorld * pose;
  for (int i = 0; i < steps; ++i) {
    if (i > 0) {
      pose = pose * step;
      odometry = drifting ? odometry * Pose2(step.x * 1.05, step.y, step.theta + DegToRad(0.5))
                          : kOdomFromWorld * pose;
    }
    LogScan scan;
    static_cast<LaserScan&>(scan) = testing::CastScan(world, pose, options, &rng);
    scan.odometry_pose = odometry;
    scan.logger_timestamp_s = 1000.0 + 0.1 * i;
    scan.timestamp_s = IpcStamp(i);
    truth.push_back(pose);
    in_drive_order.push_back(std::move(scan));
  }
  Drive drive;
  for (int f = 0; f < steps; ++f) {
    const int i = (f % 2 == 0 && f + 1 < steps) ? f + 1 : (f % 2 == 1 ? f - 1 : f);
    drive.truth_by_file.push_back(truth[i]);
    drive.drive_step_of_file.push_back(static_cast<std::size_t>(i));
    drive.scans.push_back(in_drive_order[i]);
  }
  return drive;
}

LogScan StampedScan(double logger_s, double ipc_s) {
  LogScan scan;
  scan.logger_timestamp_s = logger_s;
  scan.timestamp_s = ipc_s;
  return scan;
}

TEST(OdometryEvaluationTest, ProcessingOrderSortsStablyByTheChosenStamp) {
  // logger: 3, 1, 1, 0 -> positions 3, 1, 2, 0 (the tie keeps file order);
  // ipc: 5, 7, 6, 6 -> 0, 2, 3, 1.
  const std::vector<LogScan> scans = {StampedScan(3.0, 5.0), StampedScan(1.0, 7.0),
                                      StampedScan(1.0, 6.0), StampedScan(0.0, 6.0)};
  EXPECT_EQ(ProcessingSequence(scans, ScanOrder::kLogger), (std::vector<std::size_t>{3, 1, 2, 0}));
  EXPECT_EQ(ProcessingSequence(scans, ScanOrder::kIpc), (std::vector<std::size_t>{0, 2, 3, 1}));
  EXPECT_EQ(ProcessingSequence(scans, ScanOrder::kFile), (std::vector<std::size_t>{0, 1, 2, 3}));
  for (const char* name : {"logger", "ipc", "file"}) {
    EXPECT_EQ(ToString(ParseScanOrder(name)), name);
  }
  EXPECT_THROW(ParseScanOrder("time"), std::invalid_argument);
}

TEST(OdometryEvaluationTest, SummaryCountsEachStatusAndAveragesIterationsOverRegistered) {
  const auto result = [](ScanOdometryStatus status, int iterations, double seconds, bool keyframe,
                         bool degenerate) {
    ScanOdometryResult r;
    r.status = status;
    r.iterations = iterations;
    r.seconds = seconds;
    r.keyframe = keyframe;
    r.degenerate = degenerate;
    return r;
  };
  using S = ScanOdometryStatus;
  const std::vector<ScanOdometryResult> results = {
      result(S::kFirstScan, 0, 0.001, true, false),
      result(S::kRegistered, 4, 0.002, false, true),
      result(S::kRegistered, 8, 0.006, true, false),
      result(S::kFallbackNotConverged, 30, 0.004, false, true),
      result(S::kFallbackCorrectionTooLarge, 12, 0.002, false, false),
      result(S::kFallbackTooFewPoints, 0, 0.001, false, false),
      result(S::kFallbackNotConverged, 30, 0.005, false, false),
      result(S::kRegistered, 6, 0.003, true, true),
      result(S::kRecovered, 9, 0.002, false, false),
      result(S::kFallbackWeakMatch, 14, 0.003, false, false)};
  const OdometryRunStats s = SummarizeOdometryRun(results);
  EXPECT_EQ(s.scans, 10u);
  EXPECT_EQ(s.registered, 3u);
  EXPECT_EQ(s.recovered, 1u);
  EXPECT_EQ(s.not_converged, 2u);
  EXPECT_EQ(s.fallback_correction_too_large, 1u);
  EXPECT_EQ(s.fallback_too_few_points, 1u);
  EXPECT_EQ(s.fallback_weak_match, 1u);
  EXPECT_EQ(s.keyframes, 3u);
  EXPECT_EQ(s.degenerate, 3u);
  EXPECT_DOUBLE_EQ(s.iterations_mean, 6.0);  // (4 + 8 + 6) / 3: only the registered scans'
  EXPECT_DOUBLE_EQ(s.seconds_per_scan_mean, 0.029 / 10);
  EXPECT_DOUBLE_EQ(s.seconds_per_scan_max, 0.006);

  const OdometryRunStats empty = SummarizeOdometryRun({});
  EXPECT_EQ(empty.scans, 0u);
  EXPECT_EQ(empty.seconds_per_scan_mean, 0.0);
  EXPECT_EQ(empty.iterations_mean, 0.0);
}

TEST(OdometryEvaluationTest, RunRegistersInLoggerOrderAsAPlainScanOdometryLoopWould) {
  Drive drive = MakeDrive(30, /*drifting=*/true);
  // Scan 7 (file) is blind, scan 12 (file) has no odometry.
  std::fill(drive.scans[7].valid.begin(), drive.scans[7].valid.end(), std::uint8_t{0});
  drive.scans[12].odometry_pose.reset();
  const ScanOdometryConfig config;
  std::size_t reported = 0;
  const OdometryRun run =
      RunScanOdometry(drive.scans, config, {}, [&](std::size_t done, std::size_t total) {
        EXPECT_EQ(done, reported + 1);
        EXPECT_EQ(total, 30u);
        reported = done;
      });
  EXPECT_EQ(reported, 30u);
  EXPECT_EQ(run.order, ScanOrder::kLogger);
  EXPECT_EQ(run.log_scans, 30u);
  ASSERT_EQ(run.results.size(), 30u);
  ASSERT_EQ(run.scan_index.size(), 30u);

  // Oracle: ScanOdometry over the scans sorted by hand into drive order.
  std::vector<std::size_t> file_of_step(30);
  for (std::size_t f = 0; f < 30; ++f) file_of_step[drive.drive_step_of_file[f]] = f;
  ScanOdometry oracle(config);
  OdometryRunStats counted;
  for (std::size_t k = 0; k < 30; ++k) {
    const LogScan& scan = drive.scans[file_of_step[k]];
    const ScanOdometryResult expected = oracle.Add(scan, scan.odometry_pose);
    EXPECT_EQ(run.scan_index[k], file_of_step[k]);
    EXPECT_EQ(run.results[k].status, expected.status) << k;
    EXPECT_EQ(run.results[k].T_world_robot.x, expected.T_world_robot.x) << k;
    EXPECT_EQ(run.results[k].T_world_robot.theta, expected.T_world_robot.theta) << k;
    EXPECT_EQ(run.icp_trajectory[k].timestamp_s, scan.timestamp_s);
    EXPECT_EQ(run.icp_trajectory[k].pose.y, expected.T_world_robot.y);
    ASSERT_TRUE(run.icp_by_scan[file_of_step[k]].has_value());
    EXPECT_EQ(run.icp_by_scan[file_of_step[k]]->x, expected.T_world_robot.x);
    counted.keyframes += expected.keyframe ? 1 : 0;
    counted.registered += expected.status == ScanOdometryStatus::kRegistered ? 1 : 0;
  }
  // The blind scan falls back; the one without odometry is counted and left out of the odometry
  // trajectory, which stays in processing order.
  EXPECT_EQ(run.stats.scans, 30u);
  EXPECT_EQ(run.stats.fallback_too_few_points, 1u);
  EXPECT_EQ(run.stats.missing_odometry, 1u);
  EXPECT_EQ(run.stats.registered, counted.registered);
  EXPECT_GE(run.stats.registered, 27u);
  EXPECT_EQ(run.stats.keyframes, counted.keyframes);
  EXPECT_GT(run.stats.seconds_total, 0.0);
  EXPECT_GT(run.stats.iterations_mean, 0.0);
  ASSERT_EQ(run.odometry_trajectory.size(), 29u);
  for (std::size_t k = 0, j = 0; k < 30; ++k) {
    if (file_of_step[k] == 12) continue;
    EXPECT_EQ(run.odometry_trajectory[j].timestamp_s, IpcStamp(static_cast<int>(k)));
    EXPECT_EQ(run.odometry_trajectory[j].pose.x, drive.scans[file_of_step[k]].odometry_pose->x);
    ++j;
  }
  EXPECT_FALSE(run.odometry_by_scan[12].has_value());
  ASSERT_TRUE(run.odometry_by_scan[13].has_value());
  EXPECT_EQ(run.odometry_by_scan[13]->x, drive.scans[13].odometry_pose->x);

  // ICP corrects the drifting odometry: the last pose (step 29, file 28) is near the truth
  // expressed in the odometry frame.
  const Pose2 error = Between(kOdomFromWorld * drive.truth_by_file[28], *run.icp_by_scan[28]);
  EXPECT_LT(TranslationNorm(error), 0.05);
  EXPECT_GT(TranslationNorm(
                Between(kOdomFromWorld * drive.truth_by_file[28], *drive.scans[28].odometry_pose)),
            0.1);
}

TEST(OdometryEvaluationTest, StepsSetTheIcpStepBesideTheOdometryStepItCorrected) {
  // The odometry overstates every 0.1 m step by 5 % and every turn by 0.5 deg; ICP measures the
  // true step, so a converged step parts from the odometry by about 5 mm and 0.5 deg.
  Drive drive = MakeDrive(30, /*drifting=*/true);
  drive.scans[12].odometry_pose.reset();
  // ICP alone: the grid refinement moves key scans by up to half a cell, which would hide the
  // 5 mm this checks.
  ScanOdometryConfig icp_only;
  icp_only.grid_refinement = false;
  const OdometryRun run = RunScanOdometry(drive.scans, icp_only);
  const std::vector<OdometryStep> all_steps = OdometrySteps(run);
  ASSERT_EQ(all_steps.size(), 30u);
  EXPECT_EQ(all_steps[0].status, ScanOdometryStatus::kFirstScan);
  EXPECT_EQ(all_steps[0].scan_index, run.scan_index[0]);
  EXPECT_EQ(TranslationNorm(all_steps[0].T_previous_current_icp), 0.0);
  EXPECT_FALSE(all_steps[0].T_previous_current_odometry.has_value());
  const std::vector<OdometryStep> steps(all_steps.begin() + 1, all_steps.end());
  std::size_t with_odometry = 0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const OdometryStep& step = steps[k];
    const std::size_t before = run.scan_index[k];
    EXPECT_EQ(step.scan_index, run.scan_index[k + 1]);
    EXPECT_EQ(step.timestamp_s, run.results[k + 1].timestamp_s);
    EXPECT_EQ(step.status, run.results[k + 1].status);
    const Pose2 icp = Between(run.results[k].T_world_robot, run.results[k + 1].T_world_robot);
    EXPECT_NEAR(step.T_previous_current_icp.x, icp.x, 1e-12);
    EXPECT_NEAR(step.T_previous_current_icp.y, icp.y, 1e-12);
    EXPECT_NEAR(step.T_previous_current_icp.theta, icp.theta, 1e-12);
    if (before == 12 || step.scan_index == 12) {
      EXPECT_FALSE(step.T_previous_current_odometry.has_value()) << k;
      continue;
    }
    ASSERT_TRUE(step.T_previous_current_odometry.has_value()) << k;
    ++with_odometry;
    EXPECT_NEAR(step.T_previous_current_odometry->x, 0.105, 1e-9) << k;
    EXPECT_NEAR(step.T_previous_current_odometry->theta, DegToRad(5.0), 1e-9) << k;
    if (step.status == ScanOdometryStatus::kRegistered) {
      EXPECT_NEAR(step.disagreement_rad, DegToRad(0.5), DegToRad(0.3)) << k;
      EXPECT_NEAR(step.disagreement_m, 0.005, 0.004) << k;
    }
  }
  EXPECT_EQ(with_odometry, 27u);
  const OdometryStepDisagreement summary = SummarizeStepDisagreement(all_steps);
  EXPECT_GE(summary.steps, 25u);
  EXPECT_LE(summary.steps, 27u);
  EXPECT_NEAR(summary.median_rad, DegToRad(0.5), DegToRad(0.2));
  EXPECT_NEAR(summary.median_m, 0.005, 0.003);
  // The 99th percentile of ~27 values lies between the two largest counted disagreements.
  std::vector<double> counted_rad;
  for (const OdometryStep& step : steps) {
    if (IsIcpPose(step.status) && step.T_previous_current_odometry) {
      counted_rad.push_back(step.disagreement_rad);
    }
  }
  ASSERT_EQ(counted_rad.size(), summary.steps);
  std::sort(counted_rad.begin(), counted_rad.end());
  EXPECT_GE(summary.p99_rad, counted_rad[counted_rad.size() - 2]);
  EXPECT_LE(summary.p99_rad, counted_rad.back());

  // Exact odometry: nothing to correct, the steps agree.
  const OdometryRun exact = RunScanOdometry(MakeDrive(30, /*drifting=*/false).scans, {});
  const OdometryStepDisagreement agreed = SummarizeStepDisagreement(OdometrySteps(exact));
  EXPECT_GE(agreed.steps, 27u);
  EXPECT_LT(agreed.median_rad, DegToRad(0.1));
  EXPECT_LT(agreed.median_m, 0.002);
}

TEST(OdometryEvaluationTest, StepsWithoutOdometryGiveNoDisagreementFigure) {
  Drive drive = MakeDrive(6, /*drifting=*/false);
  for (LogScan& scan : drive.scans) scan.odometry_pose.reset();
  const OdometryRun run = RunScanOdometry(drive.scans, ScanOdometryConfig{});
  const std::vector<OdometryStep> steps = OdometrySteps(run);
  ASSERT_EQ(steps.size(), 6u);
  for (const OdometryStep& step : steps) EXPECT_FALSE(step.T_previous_current_odometry);
  const OdometryStepDisagreement summary = SummarizeStepDisagreement(steps);
  EXPECT_EQ(summary.steps, 0u);
  EXPECT_EQ(summary.median_m, 0.0);
  EXPECT_TRUE(OdometrySteps(RunScanOdometry({}, ScanOdometryConfig{})).empty());
}

TEST(OdometryEvaluationTest, RangeCutsTheProcessingOrderNotTheFileOrder) {
  const Drive drive = MakeDrive(12, /*drifting=*/false);
  OdometryRunOptions options;
  options.begin = 3;
  options.end = 8;
  const OdometryRun run = RunScanOdometry(drive.scans, {}, options);
  EXPECT_EQ(run.stats.scans, 5u);
  EXPECT_EQ(run.log_scans, 12u);
  EXPECT_EQ(run.results.front().status, ScanOdometryStatus::kFirstScan);
  // Steps 3..7 lie in files 2, 5, 4, 7, 6.
  EXPECT_EQ(run.scan_index, (std::vector<std::size_t>{2, 5, 4, 7, 6}));
  for (std::size_t f = 0; f < 12; ++f) {
    const bool registered = f == 2 || (f >= 4 && f <= 7);
    EXPECT_EQ(run.icp_by_scan[f].has_value(), registered) << f;
    EXPECT_EQ(run.odometry_by_scan[f].has_value(), registered) << f;
  }
  options.begin = 20;  // clamped: nothing to do
  options.end = 40;
  EXPECT_EQ(RunScanOdometry(drive.scans, {}, options).stats.scans, 0u);
}

// Truth for every third file scan, stored in a truth log in reverse order.
GroundTruth EveryThirdScan(const Drive& drive) {
  GroundTruth truth;
  truth.truth_index_of_scan.assign(drive.scans.size(), -1);
  std::vector<std::size_t> files;
  for (std::size_t f = 0; f < drive.scans.size(); f += 3) files.push_back(f);
  for (std::size_t j = 0; j < files.size(); ++j) {
    const std::size_t f = files[files.size() - 1 - j];
    truth.truth_poses.push_back(drive.truth_by_file[f]);
    truth.truth_index_of_scan[f] = static_cast<int>(j);
    truth.pairs.push_back({f, j});
  }
  return truth;
}

TEST(OdometryEvaluationTest, DriftOfAPerfectTrajectoryIsZeroInAnyFrame) {
  const Drive drive = MakeDrive(30, /*drifting=*/false);
  const GroundTruth truth = EveryThirdScan(drive);
  const OdometryRun run = RunScanOdometry(drive.scans, {}, {});
  const OdometryDrift drift = EvaluateOdometryDrift(run, truth);
  // The odometry is the truth in another frame: no drift at all.
  EXPECT_EQ(drift.odometry.pairs, 10u);
  EXPECT_EQ(drift.odometry.consecutive.count, 9u);
  EXPECT_NEAR(drift.odometry.consecutive.translation_max_m, 0.0, 1e-9);
  EXPECT_NEAR(drift.odometry.consecutive.rotation_max_deg, 0.0, 1e-7);
  EXPECT_NEAR(drift.odometry.ate_max_m, 0.0, 1e-9);
  EXPECT_NEAR(drift.odometry.ate_rotation_rmse_deg, 0.0, 1e-7);
  // The alignment found is the frame change.
  const Pose2 frame = kOdomFromWorld.inverse();
  EXPECT_NEAR(drift.odometry.T_corrected_estimate.x, frame.x, 1e-9);
  EXPECT_NEAR(drift.odometry.T_corrected_estimate.theta, frame.theta, 1e-9);
  // ICP from perfect odometry in a noisy room stays within millimetres.
  EXPECT_EQ(drift.icp.pairs, 10u);
  EXPECT_LT(drift.icp.ate_max_m, 0.01);
  EXPECT_LT(drift.icp.consecutive.translation_max_m, 0.01);
}

TEST(OdometryEvaluationTest, DriftUsesOnlyScansWithATruthPoseAndAnEstimate) {
  Drive drive = MakeDrive(30, /*drifting=*/false);
  drive.scans[9].odometry_pose.reset();  // file 9 has truth but no odometry
  const GroundTruth truth = EveryThirdScan(drive);
  OdometryRunOptions options;
  options.end = 20;  // steps 0..19 = files 0..19 (swapped pairs stay inside)
  const OdometryRun run = RunScanOdometry(drive.scans, {}, options);
  const OdometryDrift drift = EvaluateOdometryDrift(run, truth);
  EXPECT_EQ(drift.icp.pairs, 7u);       // files 0, 3, ..., 18
  EXPECT_EQ(drift.odometry.pairs, 6u);  // without file 9
  // Still exactly zero: scan 9 was skipped, not taken at the identity pose.
  EXPECT_NEAR(drift.odometry.ate_max_m, 0.0, 1e-9);

  GroundTruth wrong = truth;
  wrong.truth_index_of_scan.pop_back();
  EXPECT_THROW(EvaluateOdometryDrift(run, wrong), std::invalid_argument);
}

TEST(OdometryEvaluationTest, RelationsOfBothTrajectoriesSplitByTheEvaluationDt) {
  const Drive drive = MakeDrive(30, /*drifting=*/false);
  const OdometryRun run = RunScanOdometry(drive.scans, {}, {});
  // Relations between drive steps: 0-1, 0-10, 5-25, 3-29.
  std::vector<Pose2> truth_by_step(30);
  for (std::size_t f = 0; f < 30; ++f)
    truth_by_step[drive.drive_step_of_file[f]] = drive.truth_by_file[f];
  std::vector<Relation> relations;
  for (const auto& [a, b] : std::vector<std::pair<int, int>>{{0, 1}, {0, 10}, {5, 25}, {3, 29}}) {
    relations.push_back({IpcStamp(a), IpcStamp(b), Between(truth_by_step[a], truth_by_step[b]), 0});
  }
  EvaluationConfig config;
  config.local_relation_max_dt_s = 1.5;  // 0.15, 0.75 s are local; 2.0, 2.35 s loop
  const OdometryRelationErrors errors = EvaluateOdometryRelations(run, relations, config);
  EXPECT_EQ(errors.icp.matched, 4u);
  EXPECT_EQ(errors.icp.local.count, 2u);
  EXPECT_EQ(errors.icp.loop.count, 2u);
  EXPECT_EQ(errors.odometry.matched, 4u);
  EXPECT_NEAR(errors.odometry.all.translation_max_m, 0.0, 1e-9);
  EXPECT_LT(errors.icp.all.translation_max_m, 0.03);
  config.local_relation_max_dt_s = 5.0;
  EXPECT_EQ(EvaluateOdometryRelations(run, relations, config).icp.local.count, 4u);
}

}  // namespace
}  // namespace keyplace
