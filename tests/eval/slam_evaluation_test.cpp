// A whole SLAM run and its evaluation on the simulated square-loop world (tests/support), with the
// simulation's true poses as ground truth and relations made from them.

#include "keyplace/eval/slam_evaluation.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "support/square_loop_run.hpp"

namespace keyplace {
namespace {

TEST(ProcessingOrder, ParsesAndSortsStablyByLoggerTime) {
  EXPECT_EQ(ParseProcessingOrder("logger"), ProcessingOrder::kLogger);
  EXPECT_EQ(ParseProcessingOrder("file"), ProcessingOrder::kFile);
  EXPECT_EQ(ToString(ProcessingOrder::kLogger), "logger");
  EXPECT_EQ(ToString(ProcessingOrder::kFile), "file");
  EXPECT_THROW(ParseProcessingOrder("time"), std::invalid_argument);
  std::vector<LogScan> scans(5);
  const double stamps[] = {3.0, 1.0, 1.0, 2.0, 0.0};
  for (std::size_t i = 0; i < scans.size(); ++i) scans[i].logger_timestamp_s = stamps[i];
  EXPECT_EQ(ProcessingSequence(scans, ProcessingOrder::kLogger),
            (std::vector<std::size_t>{4, 1, 2, 3, 0}));
  EXPECT_EQ(ProcessingSequence(scans, ProcessingOrder::kFile),
            (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

LogInputs InputsOf(const testing::SimulatedRun& run) {
  LogInputs inputs;
  inputs.log.path = "square.log";
  inputs.log.scans = run.scans;
  inputs.source_log = "square.log";
  inputs.source_hash = "crc32:0:0";
  inputs.file_scans = run.scans.size();
  const FlirtExtractor extractor;
  for (const LogScan& scan : run.scans) inputs.keypoints.push_back(extractor.Extract(scan));
  inputs.seconds_keypoints = 1.0;
  return inputs;
}

GroundTruth TruthOf(const testing::SimulatedRun& run) {
  GroundTruth truth;
  truth.truth_poses = run.truth;
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    truth.truth_index_of_scan.push_back(static_cast<int>(i));
    truth.pairs.push_back({i, i});
  }
  return truth;
}

// Relations from the true poses: scans 20 apart (2 s), 40 apart (4 s), and from scan 0 to every
// 50th scan from scan 100 on (10 s and more).
struct SimulatedRelations {
  std::vector<Relation> relations;
  std::size_t within_2_s = 0;
};

SimulatedRelations RelationsOf(const testing::SimulatedRun& run) {
  SimulatedRelations r;
  auto add = [&](std::size_t a, std::size_t b) {
    r.relations.push_back({run.scans[a].timestamp_s, run.scans[b].timestamp_s,
                           Between(run.truth[a], run.truth[b]), r.relations.size() + 1});
  };
  for (std::size_t i = 0; i + 40 < run.truth.size(); i += 40) {
    add(i, i + 20);
    ++r.within_2_s;
    add(i, i + 40);
  }
  for (std::size_t i = 100; i < run.truth.size(); i += 50) add(0, i);
  return r;
}

TEST(SlamEvaluation, SquareLoopRunAgainstItsTruth) {
  const testing::SimulatedRun sim = testing::Simulate(1.4);
  const LogInputs inputs = InputsOf(sim);
  const SlamRun run =
      RunSlamOnLog(inputs, testing::SimulationConfig(), FlirtConfig{}, ProcessingOrder::kLogger);
  ASSERT_NE(run.slam, nullptr);
  EXPECT_EQ(run.scans, sim.scans.size());
  EXPECT_EQ(run.trajectory.size(), sim.scans.size());
  EXPECT_EQ(run.map.pose_source, "slam");
  EXPECT_EQ(run.map.source_log, "square.log");
  EXPECT_EQ(run.map.source_scans, sim.scans.size());
  EXPECT_EQ(run.map.submaps.size(), run.slam->map().submaps.size());
  EXPECT_DOUBLE_EQ(run.seconds_keypoints, 1.0);

  const GroundTruth truth = TruthOf(sim);
  const SimulatedRelations simulated = RelationsOf(sim);
  const std::vector<Relation>& relations = simulated.relations;
  EvaluationConfig config;
  config.truth_max_gap_scans = 7;
  config.local_relation_max_dt_s = 3.0;  // the 4 s relations count as loop relations
  const SlamEvaluation ev = EvaluateSlam(run, &truth, &relations, config);
  const std::size_t loops = run.slam->loops().size();
  ASSERT_GE(loops, 1u);
  // Every scan has truth: every loop is checked (gap 0) and correct.
  EXPECT_TRUE(ev.has_truth);
  EXPECT_EQ(ev.truth_max_gap_scans, 7);
  EXPECT_EQ(ev.loops.truth_evaluated, loops);
  EXPECT_EQ(ev.loops.truth_correct, loops);
  EXPECT_DOUBLE_EQ(ev.loops.truth_mean_gap_scans, 0.0);
  // Aggregates of the per-loop overlaps.
  EXPECT_DOUBLE_EQ(ev.precision.overlap_30, LoopPrecision(ev.loops.overlap, 0.3));
  EXPECT_DOUBLE_EQ(ev.precision.common_area_10, LoopPrecision(ev.loops.overlap_common, 0.1));
  EXPECT_DOUBLE_EQ(ev.precision.cells_0_2m_30, LoopPrecision(ev.loops.overlap_coarse, 0.3));
  EXPECT_EQ(ev.histogram.total, loops);
  EXPECT_EQ(ev.histogram_common.total, loops);
  EXPECT_EQ(ev.mapping.submaps, run.map.submaps.size());
  EXPECT_DOUBLE_EQ(ev.seconds_per_submap,
                   (1.0 + run.seconds_slam) / static_cast<double>(ev.mapping.submaps));
  // The loops remove the drift: SLAM beats its odometry against the truth and the relations.
  ASSERT_TRUE(ev.accuracy);
  EXPECT_EQ(ev.accuracy->truth_pairs, sim.scans.size());
  EXPECT_LT(ev.accuracy->ate.translation_rmse_m, 0.5);
  EXPECT_LT(ev.accuracy->ate.translation_rmse_m, ev.accuracy->ate_icp.translation_rmse_m / 2);
  EXPECT_EQ(ev.accuracy->rpe.size(), SlamRpeDeltas().size());
  ASSERT_TRUE(ev.relations && ev.relations_icp);
  EXPECT_EQ(ev.relations->matched, relations.size());
  EXPECT_EQ(ev.relations->local.count, simulated.within_2_s);
  EXPECT_EQ(ev.relations->loop.count, relations.size() - simulated.within_2_s);
  EXPECT_LT(ev.relations->loop.translation_mean_m, ev.relations_icp->loop.translation_mean_m / 2);
  // The figure: every scan aligned onto the truth, one point per used loop.
  EXPECT_EQ(ev.figure.estimated.size(), sim.scans.size());
  EXPECT_EQ(ev.figure.truth.size(), sim.scans.size());
  EXPECT_EQ(ev.figure.loops_used.size(), ev.loops.used_count);
  double worst = 0.0;
  for (std::size_t i = 0; i < sim.scans.size(); ++i) {
    worst = std::max(worst, (ev.figure.estimated[i] - ev.figure.truth[i]).norm());
  }
  EXPECT_LT(worst, 1.0);

  // Without truth and relations: the loops' overlaps only, the figure in the SLAM frame.
  const SlamEvaluation bare = EvaluateSlam(run, nullptr, nullptr);
  EXPECT_FALSE(bare.has_truth);
  EXPECT_FALSE(bare.accuracy);
  EXPECT_FALSE(bare.relations);
  EXPECT_EQ(bare.loops.truth_evaluated, 0u);
  EXPECT_EQ(bare.loops.overlap, ev.loops.overlap);
  EXPECT_TRUE(bare.figure.truth.empty());
  ASSERT_EQ(bare.figure.estimated.size(), sim.scans.size());
  EXPECT_EQ(bare.figure.estimated.front(), run.trajectory.front().T_world_robot.translation());
  EXPECT_EQ(bare.figure.loops_used.size(), ev.loops.used_count);

  // Ground truth of another log is misuse.
  GroundTruth short_truth = truth;
  short_truth.truth_index_of_scan.pop_back();
  EXPECT_THROW(EvaluateSlam(run, &short_truth, nullptr), std::invalid_argument);
}

TEST(SlamEvaluation, RunFollowsTheProcessingOrder) {
  testing::SimulatedRun sim = testing::Simulate(0.2);
  sim.scans.resize(30);
  // The logger stamps put scans 10..19 first.
  for (std::size_t i = 0; i < sim.scans.size(); ++i) {
    sim.scans[i].logger_timestamp_s = i >= 10 && i < 20 ? static_cast<double>(i) - 100.0 : i;
  }
  const LogInputs inputs = InputsOf(sim);
  for (ProcessingOrder order : {ProcessingOrder::kLogger, ProcessingOrder::kFile}) {
    const SlamRun run = RunSlamOnLog(inputs, testing::SimulationConfig(), FlirtConfig{}, order);
    const std::vector<std::size_t> sequence = ProcessingSequence(inputs.log.scans, order);
    ASSERT_EQ(run.trajectory.size(), sequence.size());
    for (std::size_t k = 0; k < sequence.size(); ++k) {
      EXPECT_EQ(static_cast<std::size_t>(run.trajectory[k].scan_index), sequence[k]) << k;
    }
    EXPECT_EQ(run.order, order);
    EXPECT_EQ(run.trajectory.front().scan_index, order == ProcessingOrder::kLogger ? 10 : 0);
  }
  // Progress after every scan; keypoints for other scans than the inputs' are misuse.
  std::vector<std::size_t> done;
  RunSlamOnLog(inputs, testing::SimulationConfig(), FlirtConfig{}, ProcessingOrder::kFile,
               [&](std::size_t d, std::size_t total) {
                 EXPECT_EQ(total, 30u);
                 done.push_back(d);
               });
  ASSERT_EQ(done.size(), 30u);
  EXPECT_EQ(done.back(), 30u);
  LogInputs too_few_keypoints = inputs;
  too_few_keypoints.keypoints.pop_back();
  EXPECT_THROW(RunSlamOnLog(too_few_keypoints, testing::SimulationConfig(), FlirtConfig{},
                            ProcessingOrder::kFile),
               std::invalid_argument);
}

// Without keypoints in the inputs they are extracted beside SLAM, in its order: the run is the
// one with the same keypoints given, pose for pose and loop for loop.
TEST(SlamEvaluation, KeypointsExtractedBesideSlamGiveTheSameRun) {
  testing::SimulatedRun sim = testing::Simulate(1.4);
  // Logger order differs from file order (the first 40 scans come last).
  for (std::size_t i = 0; i < sim.scans.size(); ++i) {
    sim.scans[i].logger_timestamp_s = static_cast<double>(i < 40 ? i + 10000 : i);
  }
  LogInputs given = InputsOf(sim);
  given.keypoints = ExtractKeypoints(given.log, FlirtExtractor(), {});
  LogInputs beside = given;
  beside.keypoints.clear();
  const SlamRun a =
      RunSlamOnLog(given, testing::SimulationConfig(), FlirtConfig{}, ProcessingOrder::kLogger);
  const SlamRun b =
      RunSlamOnLog(beside, testing::SimulationConfig(), FlirtConfig{}, ProcessingOrder::kLogger);
  EXPECT_FALSE(a.keypoints_beside_slam);
  EXPECT_TRUE(b.keypoints_beside_slam);
  EXPECT_GT(b.seconds_keypoints, 0.0);
  EXPECT_LE(b.seconds_keypoints, b.seconds_slam);
  ASSERT_GE(a.slam->loops().size(), 1u);
  ASSERT_EQ(b.slam->loops().size(), a.slam->loops().size());
  ASSERT_EQ(b.trajectory.size(), a.trajectory.size());
  for (std::size_t k = 0; k < a.trajectory.size(); ++k) {
    EXPECT_EQ(b.trajectory[k].scan_index, a.trajectory[k].scan_index) << k;
    EXPECT_EQ(b.trajectory[k].T_world_robot.x, a.trajectory[k].T_world_robot.x) << k;
    EXPECT_EQ(b.trajectory[k].T_world_robot.theta, a.trajectory[k].T_world_robot.theta) << k;
  }
  // A scan whose keypoints cannot be extracted fails the run with the extraction's error.
  beside.log.scans[50].ranges_m.pop_back();
  try {
    RunSlamOnLog(beside, testing::SimulationConfig(), FlirtConfig{}, ProcessingOrder::kFile);
    ADD_FAILURE() << "a scan whose keypoints cannot be extracted was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("LaserScan.angles_rad has"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace keyplace
