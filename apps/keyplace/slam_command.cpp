// keyplace slam LOG: online SLAM with loop closure by place recognition (paper Section 6.2.2):
// ICP odometry -> submaps -> each completed submap matched against the map so far -> loop edges
// -> pose graph over submap origins (Ceres). Evaluates loops by submap overlap (Figure 10), the
// map (Table IX), RPE / ATE against corrected poses (Figures 11-12) and Kümmerle relations.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "eval_json.hpp"
#include "keyplace/eval/loop_overlap.hpp"
#include "keyplace/eval/relation_error.hpp"
#include "keyplace/eval/trajectory_error.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "io/file_fingerprint.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/slam/online_slam.hpp"
#include "keyplace/store/map_file.hpp"
#include "paper_tables.hpp"
#include "slam_figures.hpp"
#include "slam_loop_evaluation.hpp"

namespace keyplace::cli {
namespace {

// How far (in scans, processing order) a submap origin may be from a scan with a corrected pose
// for its loops to be checked against ground truth; FR101 has one corrected scan per 16 raw ones.
constexpr int kTruthMaxGapScans = 50;

struct SlamOptions {
  std::string input;
  std::string out_path;
  std::string trajectory_path;
  std::string truth_path;
  std::string index_path;
  std::string relations_path;
  std::string json_path;
  std::string loops_path;
  std::string figures_dir;
  std::string order = "logger";
  std::string place_preset = "default";
  std::vector<std::string> mapping_assignments;
  std::vector<std::string> place_assignments;
  SlamConfig config;
  bool no_gate = false;
  bool no_loop_refine = false;
};

std::map<std::string, std::string> ParseAssignments(const std::vector<std::string>& items) {
  std::map<std::string, std::string> values;
  for (const auto& item : items) {
    const auto equals = item.find('=');
    if (equals == std::string::npos) throw std::invalid_argument("--set '" + item + "'");
    values[item.substr(0, equals)] = item.substr(equals + 1);
  }
  return values;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunSlam(SlamOptions options) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (options.truth_path.empty() != options.index_path.empty()) {
    throw std::invalid_argument("--truth and --index must be given together");
  }
  SlamConfig config = options.config;
  ApplyKeyValues(ParseAssignments(options.mapping_assignments), config.mapping);
  config.place = PlacePreset(options.place_preset);
  ApplyKeyValues(ParseAssignments(options.place_assignments), config.place);
  if (options.no_gate) config.gate_base_m = 0.0;
  if (options.no_loop_refine) config.loop_refinement.refine = false;
  Validate(config);

  const CarmenLog log = ReadLogWithScans(options.input);
  std::vector<std::size_t> order(log.scans.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (options.order == "logger") {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return log.scans[a].logger_timestamp_s < log.scans[b].logger_timestamp_s;
    });
  } else if (options.order != "file") {
    throw std::invalid_argument("--order '" + options.order + "': expected logger or file");
  }

  // --- ground truth (optional): corrected pose of each raw scan that has one; read before the
  // long run so that a bad file fails at once
  std::vector<Pose2> corrected_poses;
  std::vector<IndexPair> pairs;
  std::vector<int> corrected_of(log.scans.size(), -1);
  if (!options.truth_path.empty()) {
    const CarmenLog corrected = ReadLogWithScans(options.truth_path);
    for (const LogScan& scan : corrected.scans) {
      if (!scan.corrected_pose) {
        throw std::invalid_argument(options.truth_path + ":" + std::to_string(scan.line) +
                                    ": scan has no corrected pose");
      }
      corrected_poses.push_back(*scan.corrected_pose);
    }
    pairs = ReadIndexPairs(options.index_path);
    for (const IndexPair& pair : pairs) {
      if (pair.raw_index < corrected_of.size() && pair.corrected_index < corrected_poses.size()) {
        corrected_of[pair.raw_index] = static_cast<int>(pair.corrected_index);
      }
    }
  }

  std::vector<Relation> relations;
  if (!options.relations_path.empty()) relations = ReadRelations(options.relations_path);

  const auto keypoint_start = Clock::now();
  const FlirtExtractor extractor;
  Progress keypoint_progress("keypoints", log.scans.size());
  const std::vector<std::vector<Keypoint>> keypoints = ExtractKeypoints(
      log, extractor, [&](std::size_t done, std::size_t) { keypoint_progress.Update(done); });
  keypoint_progress.Finish();
  const double keypoint_seconds = Seconds(keypoint_start);

  OnlineSlam slam(config);
  Progress progress("slam", order.size());
  const auto slam_start = Clock::now();
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    slam.AddScan(static_cast<int>(i), log.scans[i], log.scans[i].odometry_pose, keypoints[i]);
    progress.Update(k + 1);
  }
  slam.Finish();
  progress.Finish();
  const double slam_seconds = Seconds(slam_start);

  GlobalMap map = slam.map();
  map.source_log = std::filesystem::path(options.input).filename().string();
  map.source_hash = FileFingerprint(options.input);
  map.pose_source = "slam";
  map.source_scans = log.scans.size();
  if (!options.out_path.empty()) SaveMap(map, options.out_path);
  const MappingStats stats = ComputeStats(map);
  const SlamStats& s = slam.stats();
  // Per submap: everything (keypoints, ICP, mapping, recognition, optimisation) / submaps.
  const double seconds_per_submap =
      stats.submaps > 0 ? (keypoint_seconds + slam_seconds) / stats.submaps : 0.0;

  // --- trajectory
  const std::vector<OnlineSlam::ScanPose> trajectory = slam.Trajectory();
  std::vector<Pose2> slam_by_raw(log.scans.size()), icp_by_raw(log.scans.size());
  std::vector<TimedPose> slam_timed, icp_timed;
  for (const OnlineSlam::ScanPose& pose : trajectory) {
    slam_by_raw[pose.scan_index] = pose.T_world_robot;
    icp_by_raw[pose.scan_index] = pose.T_world_robot_icp;
    slam_timed.push_back({pose.timestamp_s, pose.T_world_robot});
    icp_timed.push_back({pose.timestamp_s, pose.T_world_robot_icp});
  }
  if (!options.trajectory_path.empty()) {
    WriteFileAtomically(options.trajectory_path, [&](std::ostream& out) {
      out << "scan_index\ttimestamp_s\tx_m\ty_m\ttheta_rad\tsubmap\ticp_x_m\ticp_y_m\t"
             "icp_theta_rad\n";
      for (const OnlineSlam::ScanPose& pose : trajectory) {
        out << fmt::format("{}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\n",
                           pose.scan_index, pose.timestamp_s, pose.T_world_robot.x,
                           pose.T_world_robot.y, pose.T_world_robot.theta, pose.submap,
                           pose.T_world_robot_icp.x, pose.T_world_robot_icp.y,
                           pose.T_world_robot_icp.theta);
      }
    });
  }

  // --- loops: overlap rates and the ground-truth check of each detected loop
  const std::vector<LoopClosure>& loops = slam.loops();
  const LoopEvaluation ev = EvaluateLoops(
      slam, map, TruthOfEveryScan(trajectory, corrected_of, corrected_poses, kTruthMaxGapScans));
  if (!options.loops_path.empty()) WriteLoopsTsv(options.loops_path, slam, map, ev);
  const OverlapHistogram histogram = HistogramOfOverlaps(ev.overlap);
  const OverlapHistogram histogram_common = HistogramOfOverlaps(ev.overlap_common);
  const double precision_10 = LoopPrecision(ev.overlap, 0.1);
  const double precision_30 = LoopPrecision(ev.overlap, 0.3);
  const double precision_used_30 = LoopPrecision(ev.overlap_used, 0.3);
  const double precision_coarse_30 = LoopPrecision(ev.overlap_coarse, 0.3);
  // The paper rejects matches of pairs with no overlap (minimal overlap 0.01): count them too.
  const std::size_t no_overlap = static_cast<std::size_t>(
      std::count_if(ev.overlap.begin(), ev.overlap.end(), [](double o) { return o < 0.01; }));

  const auto dataset = DatasetName(options.input);
  fmt::print("log                {} ({} scans, {} order)\n", options.input, log.scans.size(),
             options.order);
  fmt::print("submaps            {} ({} queried)\n", s.submaps, s.queries);
  fmt::print("loops              {} detected, {} accepted by the gate, {} used in the graph\n",
             loops.size(), s.loops_accepted, ev.used);
  fmt::print(
      "loop refinement    {} refined by ICP, {} with a neighbour of the matched submap as "
      "partner; precision at 30 % before refinement and partner choice {:.3f}\n",
      s.loops_refined, s.loops_partner_changed, LoopPrecision(ev.overlap_matched_ransac, 0.3));
  if (config.loop_refinement.min_point_overlap > 0.0) {
    fmt::print("                   {} matches dropped by --loop-min-point-overlap {:.2f}\n",
               s.loops_rejected_by_point_overlap, config.loop_refinement.min_point_overlap);
  }
  fmt::print("optimisations      {} ({} Ceres solves, {:.2f} s)\n", s.optimizations, s.solves,
             s.seconds_optimization);
  fmt::print("loop precision     {:.3f} at 10 % overlap, {:.3f} at 30 % ({:.3f} of the used)\n",
             precision_10, precision_30, precision_used_30);
  fmt::print("                   {:.3f} at 30 % with 0.2 m cells (sensitivity of the measure)\n",
             precision_coarse_30);
  fmt::print(
      "                   {:.3f} at 10 %, {:.3f} at 30 % counting only the area both submaps "
      "observed\n",
      LoopPrecision(ev.overlap_common, 0.1), LoopPrecision(ev.overlap_common, 0.3));
  if (!corrected_poses.empty()) {
    fmt::print(
        "                   {:.3f} against ground truth (0.5 m, 10 deg): {} of {} loops whose "
        "submap origins are at most {} scans from a corrected scan (mean {:.1f})\n",
        ev.precision_truth(), ev.truth_correct, ev.truth_evaluated, kTruthMaxGapScans,
        ev.truth_mean_gap_scans);
    fmt::print(
        "                   loop transform error against ground truth, mean over {} loops: "
        "{:.3f} m / {:.2f} deg (place recognition's RANSAC estimate: {:.3f} m / {:.2f} deg)\n",
        ev.paired_loops, ev.paired_final_m, ev.paired_final_deg, ev.paired_ransac_m,
        ev.paired_ransac_deg);
  }
  if (ev.truth_evaluated > 0) {
    fmt::print("overlap as a correctness test, loops passing of the {} correct / {} wrong ones:\n",
               ev.truth_correct, ev.truth_wrong);
    for (const OverlapTest& t : ev.overlap_tests) {
      if (t.threshold < 0.25 || t.threshold > 0.45) continue;
      fmt::print("                   at {:.0f} %: all cells {} / {}, common area {} / {}\n",
                 100.0 * t.threshold, t.all_cells_correct, t.all_cells_wrong, t.common_correct,
                 t.common_wrong);
    }
  }
  fmt::print(
      "overlap histogram  [0,10) {}  [10,20) {}  [20,30) {}  [30,40) {}  [40,100] {}"
      "  ({} below 1 %)\n",
      histogram.counts[0], histogram.counts[1], histogram.counts[2], histogram.counts[3],
      histogram.counts[4], no_overlap);
  fmt::print("  in common area    [0,10) {}  [10,20) {}  [20,30) {}  [30,40) {}  [40,100] {}\n",
             histogram_common.counts[0], histogram_common.counts[1], histogram_common.counts[2],
             histogram_common.counts[3], histogram_common.counts[4]);
  fmt::print(
      "time               keypoints {:.1f} s, slam {:.1f} s (odometry {:.1f}, mapping "
      "{:.1f}, recognition {:.1f} of which loop refinement {:.1f}, optimisation {:.1f})\n",
      keypoint_seconds, slam_seconds, s.seconds_odometry, s.seconds_mapping, s.seconds_recognition,
      s.seconds_loop_refinement, s.seconds_optimization);
  const PaperSlamRow* paper = dataset ? PaperSlam(*dataset) : nullptr;
  fmt::print("\nTable IX ({})   {:>8} {:>8} {:>10} {:>8} {:>8} {:>9}\n", dataset ? *dataset : "?",
             "Compress", "#Scans", "#Keypoints", "Distrib", "#Submaps", "Time (s)");
  if (paper) {
    fmt::print("  paper          {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               paper->compression, paper->scans_per_submap, paper->keypoints_per_submap,
               paper->distribution, paper->submaps, paper->seconds_per_submap);
  }
  fmt::print("  keyplace       {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n", stats.compression,
             stats.scans_per_submap, stats.keypoints_per_submap, stats.distribution,
             static_cast<int>(stats.submaps), seconds_per_submap);
  if (paper) {
    fmt::print(
        "Section 6.2.2: paper {} loops detected, {} used, precision {:.2f} at 30 %, "
        "{:.2f} at 10 %\n",
        paper->loops_detected, paper->loops_used, paper->precision_overlap_30,
        paper->precision_overlap_10);
  }

  nlohmann::json json;
  json["log"] = options.input;
  json["dataset"] = dataset ? *dataset : "";
  json["order"] = options.order;
  json["scans"] = log.scans.size();
  json["submaps"] = stats.submaps;
  json["queries"] = s.queries;
  json["loops_detected"] = loops.size();
  json["loops_accepted"] = s.loops_accepted;
  json["loops_used"] = ev.used;
  json["loops_refined"] = s.loops_refined;
  json["loops_partner_changed"] = s.loops_partner_changed;
  json["loops_rejected_by_point_overlap"] = s.loops_rejected_by_point_overlap;
  json["precision_overlap_30_matched_ransac"] = LoopPrecision(ev.overlap_matched_ransac, 0.3);
  json["optimizations"] = s.optimizations;
  json["ceres_solves"] = s.solves;
  json["precision_overlap_10"] = precision_10;
  json["precision_overlap_30"] = precision_30;
  json["precision_overlap_30_used"] = precision_used_30;
  json["precision_overlap_30_cells_0_2m"] = precision_coarse_30;
  json["precision_overlap_10_cells_0_2m"] = LoopPrecision(ev.overlap_coarse, 0.1);
  json["loops_below_1_percent_overlap"] = no_overlap;
  json["precision_overlap_10_common_area"] = LoopPrecision(ev.overlap_common, 0.1);
  json["precision_overlap_30_common_area"] = LoopPrecision(ev.overlap_common, 0.3);
  json["overlap_histogram_common_area"] = histogram_common.counts;
  if (!corrected_poses.empty()) {
    json["loops_truth_evaluated"] = ev.truth_evaluated;
    json["loops_truth_correct"] = ev.truth_correct;
    json["loops_truth_max_gap_scans"] = kTruthMaxGapScans;
    nlohmann::json tests = nlohmann::json::array();
    for (const OverlapTest& t : ev.overlap_tests) {
      tests.push_back({{"threshold", t.threshold},
                       {"correct", ev.truth_correct},
                       {"wrong", ev.truth_wrong},
                       {"all_cells_correct_passed", t.all_cells_correct},
                       {"all_cells_wrong_passed", t.all_cells_wrong},
                       {"common_area_correct_passed", t.common_correct},
                       {"common_area_wrong_passed", t.common_wrong}});
    }
    json["overlap_vs_truth"] = tests;
    json["loop_truth_error"] = {{"loops", ev.paired_loops},
                                {"translation_mean_m", ev.paired_final_m},
                                {"rotation_mean_deg", ev.paired_final_deg},
                                {"ransac_translation_mean_m", ev.paired_ransac_m},
                                {"ransac_rotation_mean_deg", ev.paired_ransac_deg}};
    json["precision_truth"] = ev.precision_truth();
  }
  json["overlap_histogram"] = histogram.counts;
  json["compression"] = stats.compression;
  json["scans_per_submap"] = stats.scans_per_submap;
  json["keypoints_per_submap"] = stats.keypoints_per_submap;
  json["distribution"] = stats.distribution;
  json["forced_submaps"] = stats.forced_submaps;
  json["seconds_per_submap"] = seconds_per_submap;
  json["seconds"] = {
      {"keypoints", keypoint_seconds},          {"slam", slam_seconds},
      {"odometry", s.seconds_odometry},         {"mapping", s.seconds_mapping},
      {"recognition", s.seconds_recognition},   {"loop_refinement", s.seconds_loop_refinement},
      {"optimization", s.seconds_optimization}, {"total", Seconds(start)}};
  json["config"] = {{"exclude_recent_submaps", config.exclude_recent_submaps},
                    {"exclude_recent_path_m", config.exclude_recent_path_m},
                    {"gate_base_m", config.gate_base_m},
                    {"gate_per_path", config.gate_per_path},
                    {"gate_base_rad", config.gate_base_rad},
                    {"gate_per_path_rad", config.gate_per_path_rad},
                    {"loop_sigma_m", config.loop_sigma_m},
                    {"loop_sigma_rad", config.loop_sigma_rad},
                    {"odometry_sigma_base_m", config.odometry_sigma_base_m},
                    {"odometry_sigma_per_m", config.odometry_sigma_per_m},
                    {"optimize_every_loops", config.optimize_every_loops},
                    {"loop_reject_sigmas", config.graph.loop_reject_sigmas},
                    {"loop_loss_scale", config.graph.loop_loss_scale},
                    {"loop_refine", config.loop_refinement.refine},
                    {"loop_partner_neighbours", config.loop_refinement.partner_neighbours},
                    {"loop_max_inlier_ratio_loss", config.loop_refinement.max_inlier_ratio_loss},
                    {"loop_min_point_overlap", config.loop_refinement.min_point_overlap},
                    {"place_preset", options.place_preset}};
  if (paper) {
    json["paper"] = {{"compression", paper->compression},
                     {"scans_per_submap", paper->scans_per_submap},
                     {"keypoints_per_submap", paper->keypoints_per_submap},
                     {"distribution", paper->distribution},
                     {"submaps", paper->submaps},
                     {"seconds_per_submap", paper->seconds_per_submap},
                     {"loops_detected", paper->loops_detected},
                     {"loops_used", paper->loops_used},
                     {"precision_overlap_30", paper->precision_overlap_30},
                     {"precision_overlap_10", paper->precision_overlap_10}};
  }

  // --- accuracy against corrected poses and relations
  std::vector<Eigen::Vector2d> figure_estimated, figure_truth, figure_loops;
  std::vector<RpePoint> rpe;
  AteSeries ate;
  if (!options.truth_path.empty()) {
    const PairedTrajectory paired = PairTrajectory(slam_by_raw, corrected_poses, pairs);
    const PairedTrajectory paired_icp = PairTrajectory(icp_by_raw, corrected_poses, pairs);
    const std::vector<std::size_t> deltas{1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000};
    rpe = RelativePoseErrorCurve(paired, deltas);
    ate = AbsoluteTrajectoryErrors(paired);
    const AteSeries ate_icp = AbsoluteTrajectoryErrors(paired_icp);
    fmt::print(
        "\nATE after SE(2) alignment ({} poses): SLAM {:.3f} m / {:.2f} deg RMSE, ICP "
        "odometry {:.3f} m / {:.2f} deg\n",
        paired.estimated.size(), ate.translation_rmse_m, ate.rotation_rmse_deg,
        ate_icp.translation_rmse_m, ate_icp.rotation_rmse_deg);
    fmt::print("RPE RMSE vs Delta:");
    for (const RpePoint& p : rpe) {
      if (p.count > 0) {
        fmt::print("  {}: {:.3f} m {:.2f} deg", p.delta, p.translation_rmse_m, p.rotation_rmse_deg);
      }
    }
    fmt::print("\n");
    json["ate_rmse_m"] = ate.translation_rmse_m;
    json["ate_rotation_rmse_deg"] = ate.rotation_rmse_deg;
    json["ate_icp_rmse_m"] = ate_icp.translation_rmse_m;
    json["ate_icp_rotation_rmse_deg"] = ate_icp.rotation_rmse_deg;
    json["truth_pairs"] = paired.estimated.size();
    nlohmann::json rpe_json = nlohmann::json::array();
    for (const RpePoint& p : rpe) {
      rpe_json.push_back({{"delta", p.delta},
                          {"count", p.count},
                          {"translation_rmse_m", p.translation_rmse_m},
                          {"rotation_rmse_deg", p.rotation_rmse_deg}});
    }
    json["rpe"] = rpe_json;
    for (std::size_t i = 0; i < paired.estimated.size(); ++i) {
      figure_estimated.push_back((ate.alignment * paired.estimated[i]).translation());
      figure_truth.push_back(paired.truth[i].translation());
    }
    for (const LoopClosure& loop : loops) {
      if (!slam.LoopUsed(loop)) continue;
      const int first = map.submaps[loop.query_submap].first_scan();
      figure_loops.push_back((ate.alignment * slam_by_raw[first]).translation());
    }
  } else {
    for (const OnlineSlam::ScanPose& pose : trajectory) {
      figure_estimated.push_back(pose.T_world_robot.translation());
    }
    for (const LoopClosure& loop : loops) {
      if (slam.LoopUsed(loop))
        figure_loops.push_back(map.submaps[loop.query_submap].origin().translation());
    }
  }
  if (!options.relations_path.empty()) {
    const RelationErrorReport r = EvaluateRelations(slam_timed, relations);
    const RelationErrorReport r_icp = EvaluateRelations(icp_timed, relations);
    fmt::print(
        "relations ({} of {}): SLAM {:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg; ICP odometry "
        "{:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg\n",
        r.matched, r.relations, r.all.translation_mean_m, r.all.translation_std_m,
        r.all.rotation_mean_deg, r.all.rotation_std_deg, r_icp.all.translation_mean_m,
        r_icp.all.translation_std_m, r_icp.all.rotation_mean_deg, r_icp.all.rotation_std_deg);
    json["relations"] = RelationJson(r);
    json["relations_icp"] = RelationJson(r_icp);
  }

  if (!options.figures_dir.empty()) {
    std::filesystem::create_directories(options.figures_dir);
    const std::string name = dataset ? *dataset : map.source_log;
    const std::filesystem::path dir(options.figures_dir);
    DrawTrajectoryFigure((dir / "trajectory.png").string(),
                         fmt::format("{}: SLAM ({} loops used of {})", name, ev.used, loops.size()),
                         figure_estimated, figure_truth, figure_loops);
    DrawHistogramFigure(
        (dir / "overlap_histogram.png").string(),
        fmt::format("{}: overlap of matched submaps ({} loops)", name, loops.size()),
        histogram.counts);
    DrawHistogramFigure(
        (dir / "overlap_histogram_common_area.png").string(),
        fmt::format("{}: overlap in the area both submaps observed ({} loops)", name, loops.size()),
        histogram_common.counts);
    if (!rpe.empty()) {
      CurvePanel t{"Delta (scans)", "RPE RMSE (m)", {}, {}, true};
      CurvePanel r{"Delta (scans)", "RPE RMSE (deg)", {}, {}, true};
      for (const RpePoint& p : rpe) {
        if (p.count == 0) continue;
        t.x.push_back(static_cast<double>(p.delta));
        t.y.push_back(p.translation_rmse_m);
        r.x.push_back(static_cast<double>(p.delta));
        r.y.push_back(p.rotation_rmse_deg);
      }
      DrawCurvesFigure((dir / "rpe.png").string(), name + ": RPE RMSE vs Delta", {t, r});
      CurvePanel at{"path length (m)", "ATE (m)", {}, {}, false};
      CurvePanel ar{"path length (m)", "ATE (deg)", {}, {}, false};
      for (const AtePoint& p : ate.points) {
        at.x.push_back(p.path_length_m);
        at.y.push_back(p.translation_m);
        ar.x.push_back(p.path_length_m);
        ar.y.push_back(p.rotation_deg);
      }
      DrawCurvesFigure((dir / "ate.png").string(), name + ": ATE vs path length", {at, ar});
    }
    fmt::print("figures written to {}\n", options.figures_dir);
  }
  if (!options.out_path.empty()) fmt::print("map written to {}\n", options.out_path);
  if (!options.json_path.empty()) WriteJson(options.json_path, json);
}

}  // namespace

void RegisterSlamCommand(CLI::App& app) {
  auto options = std::make_shared<SlamOptions>();
  CLI::App* command = app.add_subcommand(
      "slam",
      "Online SLAM on a raw log (paper Section 6.2.2): ICP odometry, submaps of stable keypoints, "
      "loop closure by place recognition, pose graph over submap origins (Ceres). Prints loop "
      "counts, loop precision by submap overlap, Table IX and, with --truth/--relations, "
      "ATE/RPE and relation errors.");
  command->add_option("input", options->input, "raw CARMEN log (.log or .log.gz)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out_path, "write the SLAM map (.kpm)");
  command->add_option("--trajectory", options->trajectory_path,
                      "write every scan's optimised pose (TSV: scan_index, timestamp, x, y, theta, "
                      "submap, ICP pose)");
  command->add_option("--truth", options->truth_path, "corrected log for ATE / RPE (needs --index)")
      ->check(CLI::ExistingFile);
  command->add_option("--index", options->index_path, "raw_index corrected_index TSV")
      ->check(CLI::ExistingFile);
  command->add_option("--relations", options->relations_path, "Kümmerle et al. relation file")
      ->check(CLI::ExistingFile);
  command->add_option("--json", options->json_path, "write the figures as JSON");
  command->add_option(
      "--loops", options->loops_path,
      "write one TSV row per detected loop (submaps, first scans, transform, "
      "consensus, gamma, overlap over all cells and over the common area, accepted, used, "
      "ground-truth check)");
  command->add_option("--figures", options->figures_dir,
                      "write trajectory, overlap histogram, RPE and ATE pictures (PNG) here");
  command->add_option("--order", options->order, "processing order: logger (default) or file");
  command->add_option("--place-preset", options->place_preset,
                      "place recognition preset: default or paper");
  command->add_option("--set", options->mapping_assignments,
                      "override a mapping parameter, KEY=VALUE (repeatable; see keyplace map)");
  command->add_option("--place-set", options->place_assignments,
                      "override a place recognition parameter, KEY=VALUE (repeatable)");
  SlamConfig& c = options->config;
  command
      ->add_option("--exclude-recent", c.exclude_recent_submaps,
                   "do not match a submap with its last N predecessors")
      ->capture_default_str();
  command
      ->add_option("--exclude-path", c.exclude_recent_path_m,
                   "nor with submaps less than this path (m) behind it")
      ->capture_default_str();
  command
      ->add_option("--optimize-every", c.optimize_every_loops,
                   "optimise after every N accepted loops")
      ->capture_default_str();
  command
      ->add_option("--reject-sigmas", c.graph.loop_reject_sigmas,
                   "switch off loops whose residual exceeds this many sigmas (0: never)")
      ->capture_default_str();
  command
      ->add_option("--loop-loss", c.graph.loop_loss_scale,
                   "Cauchy scale (sigmas) of the final robust solve (0: none)")
      ->capture_default_str();
  command->add_flag("--no-loop-refine", options->no_loop_refine,
                    "use the RANSAC loop transform as it is (no ICP refinement of loops)");
  command
      ->add_option("--partner-neighbours", c.loop_refinement.partner_neighbours,
                   "loop partner chosen among the matched submap and this many neighbours on each "
                   "side (0: the matched submap)")
      ->capture_default_str();
  command
      ->add_option("--loop-min-point-overlap", c.loop_refinement.min_point_overlap,
                   "optional verification, off by default: drop matches whose point overlap with "
                   "the loop partner is below this (0..1; correlates with the evaluated overlap)")
      ->capture_default_str();
  command->add_flag("--no-gate", options->no_gate,
                    "add every detected loop to the graph (no agreement test with the estimate)");
  command->callback([options] { RunSlam(*options); });
}

}  // namespace keyplace::cli
