#include "keyplace/eval/odometry_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <stdexcept>

#include "common/quantile.hpp"
#include "keyplace/io/timestamps.hpp"

namespace keyplace {

ScanOrder ParseScanOrder(const std::string& text) {
  if (text == "logger") return ScanOrder::kLogger;
  if (text == "ipc") return ScanOrder::kIpc;
  if (text == "file") return ScanOrder::kFile;
  throw std::invalid_argument("scan order '" + text + "': expected logger, ipc or file");
}

std::string ToString(ScanOrder order) {
  switch (order) {
    case ScanOrder::kLogger:
      return "logger";
    case ScanOrder::kIpc:
      return "ipc";
    case ScanOrder::kFile:
      return "file";
  }
  return "?";
}

std::vector<std::size_t> ProcessingSequence(const std::vector<LogScan>& scans, ScanOrder order) {
  std::vector<std::size_t> indices(scans.size());
  std::iota(indices.begin(), indices.end(), std::size_t{0});
  if (order == ScanOrder::kLogger) {
    std::stable_sort(indices.begin(), indices.end(), [&](std::size_t a, std::size_t b) {
      return scans[a].logger_timestamp_s < scans[b].logger_timestamp_s;
    });
  } else if (order == ScanOrder::kIpc) {
    std::stable_sort(indices.begin(), indices.end(), [&](std::size_t a, std::size_t b) {
      return scans[a].timestamp_s < scans[b].timestamp_s;
    });
  }
  return indices;
}

OdometryRunStats SummarizeOdometryRun(const std::vector<ScanOdometryResult>& results) {
  OdometryRunStats stats;
  stats.scans = results.size();
  double seconds_sum = 0.0;
  double iterations_sum = 0.0;
  for (const ScanOdometryResult& r : results) {
    seconds_sum += r.seconds;
    stats.seconds_per_scan_max = std::max(stats.seconds_per_scan_max, r.seconds);
    stats.keyframes += r.keyframe ? 1 : 0;
    stats.degenerate += r.degenerate ? 1 : 0;
    switch (r.status) {
      case ScanOdometryStatus::kRegistered:
        ++stats.registered;
        iterations_sum += r.iterations;
        break;
      case ScanOdometryStatus::kRecovered:
        ++stats.recovered;
        break;
      case ScanOdometryStatus::kFallbackNotConverged:
        ++stats.not_converged;
        break;
      case ScanOdometryStatus::kFallbackCorrectionTooLarge:
        ++stats.fallback_correction_too_large;
        break;
      case ScanOdometryStatus::kFallbackTooFewPoints:
        ++stats.fallback_too_few_points;
        break;
      case ScanOdometryStatus::kFallbackWeakMatch:
        ++stats.fallback_weak_match;
        break;
      case ScanOdometryStatus::kFirstScan:
        break;
    }
  }
  stats.seconds_per_scan_mean =
      seconds_sum / std::max<double>(1.0, static_cast<double>(results.size()));
  stats.iterations_mean =
      stats.registered > 0 ? iterations_sum / static_cast<double>(stats.registered) : 0.0;
  return stats;
}

OdometryRun RunScanOdometry(const std::vector<LogScan>& scans, const ScanOdometryConfig& config,
                            const OdometryRunOptions& options, const OdometryProgress& progress) {
  ValidateScanOdometryConfig(config);
  if (options.order != ScanOrder::kFile) {
    const bool logger = options.order == ScanOrder::kLogger;
    RequireTimeOrder(
        CheckTimestamps(scans, logger ? TimestampSource::kLogger : TimestampSource::kIpc),
        (options.source.empty() ? "" : options.source + ": ") +
            (logger ? "the logger timestamps" : "the ipc timestamps"));
  }
  const std::vector<std::size_t> order = ProcessingSequence(scans, options.order);
  const std::size_t end = std::min(options.end, order.size());
  const std::size_t begin = std::min(options.begin, end);

  OdometryRun run;
  run.order = options.order;
  run.log_scans = scans.size();
  run.icp_by_scan.resize(scans.size());
  run.odometry_by_scan.resize(scans.size());
  run.scan_index.reserve(end - begin);
  run.results.reserve(end - begin);
  std::size_t missing_odometry = 0;
  ScanOdometry odometry(config);
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = begin; k < end; ++k) {
    const std::size_t index = order[k];
    const LogScan& scan = scans[index];
    const ScanOdometryResult result = odometry.Add(scan, scan.odometry_pose);
    run.icp_trajectory.push_back({scan.timestamp_s, result.T_world_robot});
    run.icp_by_scan[index] = result.T_world_robot;
    if (scan.odometry_pose) {
      run.odometry_trajectory.push_back({scan.timestamp_s, *scan.odometry_pose});
      run.odometry_by_scan[index] = *scan.odometry_pose;
    } else {
      ++missing_odometry;
    }
    run.scan_index.push_back(index);
    run.results.push_back(result);
    if (progress) progress(k + 1 - begin, end - begin);
  }
  const double seconds_total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.stats = SummarizeOdometryRun(run.results);
  run.stats.missing_odometry = missing_odometry;
  run.stats.seconds_total = seconds_total;
  return run;
}

std::vector<OdometryStep> OdometrySteps(const OdometryRun& run) {
  std::vector<OdometryStep> steps;
  steps.reserve(run.results.size());
  for (std::size_t k = 0; k < run.results.size(); ++k) {
    const ScanOdometryResult& current = run.results[k];
    OdometryStep step;
    step.scan_index = run.scan_index[k];
    step.timestamp_s = current.timestamp_s;
    step.status = current.status;
    step.inlier_ratio = current.inlier_ratio;
    step.residual_rms_m = current.residual_rms_m;
    step.iterations = current.iterations;
    step.degenerate = current.degenerate;
    if (k > 0) {
      const ScanOdometryResult& previous = run.results[k - 1];
      step.T_previous_current_icp = Between(previous.T_world_robot, current.T_world_robot);
      const std::optional<Pose2>& odometry_before = run.odometry_by_scan[run.scan_index[k - 1]];
      const std::optional<Pose2>& odometry_now = run.odometry_by_scan[step.scan_index];
      if (odometry_before && odometry_now) {
        step.T_previous_current_odometry = Between(*odometry_before, *odometry_now);
        const Pose2 disagreement =
            Between(*step.T_previous_current_odometry, step.T_previous_current_icp);
        step.disagreement_m = std::hypot(disagreement.x, disagreement.y);
        step.disagreement_rad = std::abs(disagreement.theta);
      }
    }
    steps.push_back(step);
  }
  return steps;
}

OdometryStepDisagreement SummarizeStepDisagreement(const std::vector<OdometryStep>& steps) {
  std::vector<double> translation_m;
  std::vector<double> rotation_rad;
  for (const OdometryStep& step : steps) {
    if (!IsIcpPose(step.status) || !step.T_previous_current_odometry) continue;
    translation_m.push_back(step.disagreement_m);
    rotation_rad.push_back(step.disagreement_rad);
  }
  OdometryStepDisagreement summary;
  summary.steps = translation_m.size();
  if (translation_m.empty()) return summary;
  summary.median_m = Quantile(translation_m, 0.5);
  summary.p99_m = Quantile(translation_m, 0.99);
  summary.median_rad = Quantile(rotation_rad, 0.5);
  summary.p99_rad = Quantile(rotation_rad, 0.99);
  return summary;
}

OdometryRelationErrors EvaluateOdometryRelations(const OdometryRun& run,
                                                 const std::vector<Relation>& relations,
                                                 const EvaluationConfig& config) {
  const RelationErrorConfig relation_config = RelationConfigFrom(config);
  return {EvaluateRelations(run.icp_trajectory, relations, relation_config),
          EvaluateRelations(run.odometry_trajectory, relations, relation_config)};
}

namespace {

// EvaluateDrift over the scans with a truth pose and an estimate.
DriftReport DriftOf(const std::vector<std::optional<Pose2>>& estimate_by_scan,
                    const GroundTruth& truth) {
  std::vector<Pose2> estimates(estimate_by_scan.size());
  std::vector<IndexPair> pairs;
  for (const IndexPair& pair : truth.pairs) {
    const std::optional<Pose2>& estimate = estimate_by_scan[pair.raw_index];
    if (!estimate) continue;
    estimates[pair.raw_index] = *estimate;
    pairs.push_back(pair);
  }
  return EvaluateDrift(estimates, truth.truth_poses, pairs);
}

}  // namespace

OdometryDrift EvaluateOdometryDrift(const OdometryRun& run, const GroundTruth& truth) {
  if (truth.truth_index_of_scan.size() != run.log_scans) {
    throw std::invalid_argument("EvaluateOdometryDrift: the ground truth covers " +
                                std::to_string(truth.truth_index_of_scan.size()) +
                                " scans, the run's log has " + std::to_string(run.log_scans));
  }
  for (const IndexPair& pair : truth.pairs) {
    if (pair.raw_index >= run.log_scans) {
      throw std::invalid_argument("EvaluateOdometryDrift: ground-truth pair for scan " +
                                  std::to_string(pair.raw_index) + " of a log of " +
                                  std::to_string(run.log_scans) + " scans");
    }
  }
  return {DriftOf(run.icp_by_scan, truth), DriftOf(run.odometry_by_scan, truth)};
}

}  // namespace keyplace
