#pragma once
// Evaluation of scan odometry on a log (`keyplace odometry`): ScanOdometry over the scans in a
// processing order, the run statistics, the relation error of Kümmerle et al. (2009) and the drift
// against corrected poses, each for the ICP trajectory and for the raw odometry.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relation_error.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/registration/scan_odometry.hpp"

namespace keyplace {

/// The order in which the scans of a log are registered: by logger_timestamp (the monotonic one
/// for Intel raw, whose ipc stamps are not), by ipc timestamp, or as they stand in the file.
/// Sorting is stable, so equal stamps keep their file order.
enum class ScanOrder { kLogger, kIpc, kFile };

/// "logger" | "ipc" | "file"; throws std::invalid_argument naming the accepted values.
ScanOrder ParseScanOrder(const std::string& text);
std::string ToString(ScanOrder order);

/// Indices into `scans` (file order) in processing order.
std::vector<std::size_t> ProcessingSequence(const std::vector<LogScan>& scans, ScanOrder order);

struct OdometryRunOptions {
  ScanOrder order = ScanOrder::kLogger;
  // Register only the positions [begin, end) of the processing order (clamped to the log).
  std::size_t begin = 0;
  std::size_t end = static_cast<std::size_t>(-1);
  // The log the scans come from, named in errors (the refusal of timestamps that cannot order).
  std::string source;
};

/// Counts and times of a run, over the registered scans.
struct OdometryRunStats {
  std::size_t scans = 0;          // scans registered (the range of the processing order)
  std::size_t registered = 0;     // ScanOdometryStatus::kRegistered
  std::size_t recovered = 0;      // kRecovered (searched pose, or odometry glitch)
  std::size_t not_converged = 0;  // kFallbackNotConverged
  std::size_t fallback_correction_too_large = 0;  // kFallbackCorrectionTooLarge
  std::size_t fallback_too_few_points = 0;        // kFallbackTooFewPoints
  std::size_t fallback_weak_match = 0;            // kFallbackWeakMatch
  std::size_t degenerate = 0;                     // ICP held a weak direction at the guess
  std::size_t keyframes = 0;                      // scans added to the local map
  std::size_t missing_odometry = 0;               // scans without an odometry pose
  double seconds_per_scan_mean = 0.0;             // ScanOdometryResult::seconds (0 without scans)
  double seconds_per_scan_max = 0.0;
  double seconds_total = 0.0;    // wall time of the whole run
  double iterations_mean = 0.0;  // ICP iterations per registered scan (0 without any)
};

/// The counts and per-scan times of `results`; seconds_total and missing_odometry are left 0.
OdometryRunStats SummarizeOdometryRun(const std::vector<ScanOdometryResult>& results);

/// A run of ScanOdometry over a log.
struct OdometryRun {
  ScanOrder order = ScanOrder::kLogger;
  std::size_t log_scans = 0;  // scans in the log (file order)
  // Per registered scan, in processing order: its index in the log (file order) and the result.
  std::vector<std::size_t> scan_index;
  std::vector<ScanOdometryResult> results;
  // The robot poses keyed by the scans' ipc timestamps, in processing order: the ICP estimate of
  // every registered scan, and the raw odometry of those that have one.
  std::vector<TimedPose> icp_trajectory;
  std::vector<TimedPose> odometry_trajectory;
  // The same by index in the log (file order); nullopt for scans not registered (outside the
  // range) or, for odometry, without an odometry pose.
  std::vector<std::optional<Pose2>> icp_by_scan;
  std::vector<std::optional<Pose2>> odometry_by_scan;
  OdometryRunStats stats;
};

/// (done, total) after each scan.
using OdometryProgress = std::function<void(std::size_t, std::size_t)>;

/// Registers the scans [options.begin, options.end) of the processing order with one
/// ScanOdometry(config), each initialised by its odometry pose. Throws std::invalid_argument for
/// an invalid config.
OdometryRun RunScanOdometry(const std::vector<LogScan>& scans, const ScanOdometryConfig& config,
                            const OdometryRunOptions& options = {},
                            const OdometryProgress& progress = {});

/// One step of a run: a registered scan against the scan before it in processing order, as ICP
/// estimated it and as the wheel odometry measured it, so that the places where the two part can
/// be found (keyplace odometry --steps; docs/notes/slam-hospital-bag.md). The run's first scan
/// is a step of zero from nowhere (identity, no odometry step).
struct OdometryStep {
  std::size_t scan_index = 0;  // the later scan, file order
  double timestamp_s = 0.0;    // its ipc stamp
  ScanOdometryStatus status = ScanOdometryStatus::kRegistered;
  double inlier_ratio = 0.0;
  double residual_rms_m = 0.0;
  int iterations = 0;
  bool degenerate = false;
  Pose2 T_previous_current_icp;  // the step in the earlier scan's robot frame, as estimated
  // The step as the wheel odometry measured it, when both scans have an odometry pose.
  std::optional<Pose2> T_previous_current_odometry;
  // T_previous_current_odometry^-1 * T_previous_current_icp: how far the estimate leaves the
  // odometry in this step (translation norm and |angle|); 0 for a scan that fell back.
  double disagreement_m = 0.0;
  double disagreement_rad = 0.0;
};

/// The steps of a run, one per registered scan (run.results order).
std::vector<OdometryStep> OdometrySteps(const OdometryRun& run);

/// How far ICP and odometry part per step, over the steps with odometry where ICP converged
/// (registered or recovered; a fallback is the odometry itself and would only add zeros).
struct OdometryStepDisagreement {
  std::size_t steps = 0;  // steps counted
  double median_m = 0.0;
  double p99_m = 0.0;
  double median_rad = 0.0;
  double p99_rad = 0.0;
};
/// Quantiles interpolated between order statistics; all zero when no step qualifies.
OdometryStepDisagreement SummarizeStepDisagreement(const std::vector<OdometryStep>& steps);

/// The relation error of both trajectories of a run.
struct OdometryRelationErrors {
  RelationErrorReport icp;
  RelationErrorReport odometry;
};

/// EvaluateRelations for the ICP and the odometry trajectory; relations shorter than
/// config.local_relation_max_dt_s are local.
OdometryRelationErrors EvaluateOdometryRelations(const OdometryRun& run,
                                                 const std::vector<Relation>& relations,
                                                 const EvaluationConfig& config = {});

/// The drift of both trajectories of a run.
struct OdometryDrift {
  DriftReport icp;
  DriftReport odometry;
};

/// EvaluateDrift of each trajectory against `truth`, whose scans are the run's log (file order,
/// first_scan 0: LoadGroundTruth(log, 0, log.scans.size(), ...)), over the scans that have a
/// truth pose and an estimate (for the odometry: an odometry pose). Throws
/// std::invalid_argument when `truth` covers another number of scans than the run's log.
OdometryDrift EvaluateOdometryDrift(const OdometryRun& run, const GroundTruth& truth);

}  // namespace keyplace
