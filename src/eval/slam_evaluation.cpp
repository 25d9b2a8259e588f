#include "keyplace/eval/slam_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "common/seconds_since.hpp"
#include "keyplace/io/timestamps.hpp"
#include "mapping/keypoint_stream.hpp"

namespace keyplace {
namespace {

LoopPrecisions Precisions(const LoopEvaluation& e) {
  LoopPrecisions p;
  p.overlap_10 = LoopPrecision(e.overlap, 0.1);
  p.overlap_30 = LoopPrecision(e.overlap, 0.3);
  p.used_overlap_30 = LoopPrecision(e.overlap_used, 0.3);
  p.cells_0_2m_10 = LoopPrecision(e.overlap_coarse, 0.1);
  p.cells_0_2m_30 = LoopPrecision(e.overlap_coarse, 0.3);
  p.common_area_10 = LoopPrecision(e.overlap_common, 0.1);
  p.common_area_30 = LoopPrecision(e.overlap_common, 0.3);
  p.matched_ransac_30 = LoopPrecision(e.overlap_matched_ransac, 0.3);
  return p;
}

// The SLAM and ICP poses of every scan, indexed by scan index (identity for a scan SLAM did not
// see).
struct PosesByScan {
  std::vector<Pose2> slam, icp;
};

PosesByScan ByScan(const SlamRun& run) {
  PosesByScan poses{std::vector<Pose2>(run.scans), std::vector<Pose2>(run.scans)};
  for (const OnlineSlam::ScanPose& pose : run.trajectory) {
    poses.slam.at(static_cast<std::size_t>(pose.scan_index)) = pose.T_world_robot;
    poses.icp.at(static_cast<std::size_t>(pose.scan_index)) = pose.T_world_robot_icp;
  }
  return poses;
}

// ATE and RPE against the truth, and the figure's points in the truth frame.
SlamAccuracy Accuracy(const SlamRun& run, const GroundTruth& truth, const LoopEvaluation& loops,
                      SlamFigurePoints& figure) {
  const PosesByScan poses = ByScan(run);
  const PairedTrajectory paired = PairTrajectory(poses.slam, truth.truth_poses, truth.pairs);
  SlamAccuracy accuracy;
  accuracy.truth_pairs = paired.estimated.size();
  accuracy.rpe = RelativePoseErrorCurve(paired, SlamRpeDeltas());
  accuracy.ate = AbsoluteTrajectoryErrors(paired);
  accuracy.ate_icp =
      AbsoluteTrajectoryErrors(PairTrajectory(poses.icp, truth.truth_poses, truth.pairs));
  const Pose2& alignment = accuracy.ate.alignment;
  for (std::size_t i = 0; i < paired.estimated.size(); ++i) {
    figure.estimated.push_back((alignment * paired.estimated[i]).translation());
    figure.truth.push_back(paired.truth[i].translation());
  }
  const std::vector<LoopClosure>& closures = run.slam->loops();
  for (std::size_t k = 0; k < closures.size(); ++k) {
    if (!loops.used[k]) continue;
    const int first = run.map.submaps[closures[k].query_submap].first_scan();
    figure.loops_used.push_back((alignment * poses.slam[first]).translation());
  }
  return accuracy;
}

// The figure's points in the SLAM frame (no truth).
SlamFigurePoints FigureWithoutTruth(const SlamRun& run, const LoopEvaluation& loops) {
  SlamFigurePoints figure;
  for (const OnlineSlam::ScanPose& pose : run.trajectory) {
    figure.estimated.push_back(pose.T_world_robot.translation());
  }
  const std::vector<LoopClosure>& closures = run.slam->loops();
  for (std::size_t k = 0; k < closures.size(); ++k) {
    if (!loops.used[k]) continue;
    figure.loops_used.push_back(run.map.submaps[closures[k].query_submap].origin().translation());
  }
  return figure;
}

void EvaluateRelationsOf(const SlamRun& run, const std::vector<Relation>& relations,
                         const EvaluationConfig& config, SlamEvaluation& ev) {
  std::vector<TimedPose> slam_timed, icp_timed;
  for (const OnlineSlam::ScanPose& pose : run.trajectory) {
    slam_timed.push_back({pose.timestamp_s, pose.T_world_robot});
    icp_timed.push_back({pose.timestamp_s, pose.T_world_robot_icp});
  }
  const RelationErrorConfig relation_config = RelationConfigFrom(config);
  ev.relations = EvaluateRelations(slam_timed, relations, relation_config);
  ev.relations_icp = EvaluateRelations(icp_timed, relations, relation_config);
}

}  // namespace

ProcessingOrder ParseProcessingOrder(const std::string& text) {
  if (text == "logger") return ProcessingOrder::kLogger;
  if (text == "file") return ProcessingOrder::kFile;
  throw std::invalid_argument("--order '" + text + "': expected logger or file");
}

std::string ToString(ProcessingOrder order) {
  return order == ProcessingOrder::kLogger ? "logger" : "file";
}

std::vector<std::size_t> ProcessingSequence(const std::vector<LogScan>& scans,
                                            ProcessingOrder order) {
  std::vector<std::size_t> sequence(scans.size());
  std::iota(sequence.begin(), sequence.end(), std::size_t{0});
  if (order == ProcessingOrder::kLogger) {
    std::stable_sort(sequence.begin(), sequence.end(), [&](std::size_t a, std::size_t b) {
      return scans[a].logger_timestamp_s < scans[b].logger_timestamp_s;
    });
  }
  return sequence;
}

std::vector<std::size_t> SlamRpeDeltas() {
  return {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000};
}

SlamRun RunSlamOnLog(const LogInputs& inputs, const SlamConfig& config, const FlirtConfig& features,
                     ProcessingOrder order, const ProgressCallback& progress) {
  const std::vector<LogScan>& scans = inputs.log.scans;
  if (!inputs.keypoints.empty() && inputs.keypoints.size() != scans.size()) {
    throw std::invalid_argument("RunSlamOnLog: " + std::to_string(inputs.keypoints.size()) +
                                " keypoint lists for the " + std::to_string(scans.size()) +
                                " scans of " + inputs.log.path);
  }
  if (order == ProcessingOrder::kLogger) {
    RequireTimeOrder(CheckTimestamps(scans, TimestampSource::kLogger),
                     inputs.log.path + ": the logger timestamps");
  }
  SlamRun run;
  run.slam = std::make_unique<OnlineSlam>(config);
  run.order = order;
  run.scans = scans.size();
  run.seconds_keypoints = inputs.seconds_keypoints;
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::size_t> sequence = ProcessingSequence(scans, order);
  std::optional<KeypointStream> stream;
  if (inputs.keypoints.empty()) stream.emplace(inputs.log, sequence, features);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    const std::size_t i = sequence[k];
    run.slam->AddScan(static_cast<int>(i), scans[i], scans[i].odometry_pose,
                      stream ? stream->Wait(k) : inputs.keypoints[i]);
    if (progress) progress(k + 1, sequence.size());
  }
  run.slam->Finish();
  run.seconds_slam = SecondsSince(start);
  if (stream) {
    run.seconds_keypoints = stream->seconds();
    run.keypoints_beside_slam = true;
  }
  run.map = run.slam->map();
  run.map.source_log = inputs.source_log;
  run.map.source_hash = inputs.source_hash;
  run.map.pose_source = "slam";
  run.map.source_scans = scans.size();
  run.trajectory = run.slam->Trajectory();
  return run;
}

OccupancyGrid SlamOccupancyGrid(const SlamRun& run, const LogInputs& inputs,
                                const OccupancyGridConfig& config) {
  std::vector<const LaserScan*> scans;
  std::vector<Pose2> T_world_robot;
  scans.reserve(run.trajectory.size());
  T_world_robot.reserve(run.trajectory.size());
  for (const OnlineSlam::ScanPose& pose : run.trajectory) {
    scans.push_back(&inputs.log.scans.at(static_cast<std::size_t>(pose.scan_index)));
    T_world_robot.push_back(pose.T_world_robot);
  }
  return BuildOccupancyGrid(scans, T_world_robot, config);
}

SlamEvaluation EvaluateSlam(const SlamRun& run, const GroundTruth* truth,
                            const std::vector<Relation>* relations,
                            const EvaluationConfig& config) {
  Validate(config);
  if (truth != nullptr && truth->truth_index_of_scan.size() != run.scans) {
    throw std::invalid_argument("EvaluateSlam: ground truth for " +
                                std::to_string(truth->truth_index_of_scan.size()) +
                                " scans, the run has " + std::to_string(run.scans));
  }
  SlamEvaluation ev;
  ev.has_truth = truth != nullptr;
  ev.truth_max_gap_scans = config.truth_max_gap_scans;
  const std::vector<std::optional<PropagatedTruth>> truth_of_scan =
      truth == nullptr ? std::vector<std::optional<PropagatedTruth>>()
                       : TruthOfEveryScan(run.trajectory, truth->truth_index_of_scan,
                                          truth->truth_poses, config.truth_max_gap_scans);
  ev.loops = EvaluateLoops(*run.slam, run.map, truth_of_scan);
  ev.precision = Precisions(ev.loops);
  ev.histogram = HistogramOfOverlaps(ev.loops.overlap);
  ev.histogram_common = HistogramOfOverlaps(ev.loops.overlap_common);
  ev.loops_below_1_percent = static_cast<std::size_t>(std::count_if(
      ev.loops.overlap.begin(), ev.loops.overlap.end(), [](double o) { return o < 0.01; }));
  ev.mapping = ComputeStats(run.map);
  // Keypoints extracted beside SLAM took their time within seconds_slam.
  const double seconds =
      run.seconds_slam + (run.keypoints_beside_slam ? 0.0 : run.seconds_keypoints);
  ev.seconds_per_submap =
      ev.mapping.submaps > 0 ? seconds / static_cast<double>(ev.mapping.submaps) : 0.0;
  if (truth != nullptr) {
    ev.accuracy = Accuracy(run, *truth, ev.loops, ev.figure);
  } else {
    ev.figure = FigureWithoutTruth(run, ev.loops);
  }
  if (relations != nullptr) EvaluateRelationsOf(run, *relations, config, ev);
  return ev;
}

GridAgreement EvaluateSlamGrid(const OccupancyGrid& slam_grid, const LogInputs& inputs,
                               const GroundTruth& truth, const SlamAccuracy& accuracy,
                               const OccupancyGridConfig& config, double tolerance_m) {
  std::vector<const LaserScan*> scans;
  std::vector<Pose2> T_world_robot;
  for (std::size_t i = 0; i < inputs.log.scans.size(); ++i) {
    if (!truth.Has(i)) continue;
    scans.push_back(&inputs.log.scans[i]);
    T_world_robot.push_back(truth.Pose(i));
  }
  const OccupancyGrid reference = BuildOccupancyGrid(scans, T_world_robot, config);
  return CompareOccupancyGrids(slam_grid, reference, accuracy.ate.alignment, config, tolerance_m);
}

}  // namespace keyplace
