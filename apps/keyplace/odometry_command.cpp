// keyplace odometry LOG: scan-matching odometry (point-to-line ICP against a local map,
// initialised by odometry) and its accuracy against the Kümmerle et al. (2009) relations and
// against corrected poses.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "eval_json.hpp"
#include "keyplace/eval/relation_error.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/registration/scan_odometry.hpp"

namespace keyplace::cli {
namespace {

struct OdometryOptions {
  std::string input;
  std::string out_path;
  std::string relations_path;
  std::string relation_errors_path;
  std::string json_path;
  std::string corrected_path;
  std::string index_path;
  std::string scans;
  std::string order = "logger";
  double local_max_dt_s = 5.0;
  ScanOdometryConfig config;
  std::string kernel = "cauchy";
};

nlohmann::json DriftJson(const DriftReport& d) {
  return {{"pairs", d.pairs},           {"consecutive", StatsJson(d.consecutive)},
          {"ate_rmse_m", d.ate_rmse_m}, {"ate_mean_m", d.ate_mean_m},
          {"ate_max_m", d.ate_max_m},   {"ate_rotation_rmse_deg", d.ate_rotation_rmse_deg}};
}

nlohmann::json ConfigJson(const ScanOdometryConfig& c) {
  const IcpConfig& i = c.icp;
  return {{"min_range_m", c.min_range_m},
          {"max_range_m", c.max_range_m},
          {"source_min_spacing_m", c.source_min_spacing_m},
          {"local_map_scans", c.local_map_scans},
          {"keyframe_translation_m", c.keyframe_translation_m},
          {"keyframe_rotation_rad", c.keyframe_rotation_rad},
          {"max_correction_translation_m", c.max_correction_translation_m},
          {"max_correction_rotation_rad", c.max_correction_rotation_rad},
          {"icp",
           {{"max_correspondence_distance_m", i.max_correspondence_distance_m},
            {"inlier_distance_m", i.inlier_distance_m},
            {"kernel", ToString(i.kernel)},
            {"kernel_scale_m", i.kernel_scale_m},
            {"normal_neighbours", i.normal_neighbours},
            {"normal_max_neighbour_distance_m", i.normal_max_neighbour_distance_m},
            {"normal_max_eigenvalue_ratio", i.normal_max_eigenvalue_ratio},
            {"max_iterations", i.max_iterations},
            {"convergence_translation_m", i.convergence_translation_m},
            {"convergence_rotation_rad", i.convergence_rotation_rad},
            {"degeneracy_min_eigenvalue", i.degeneracy_min_eigenvalue},
            {"min_points", i.min_points},
            {"min_inliers", i.min_inliers},
            {"min_inlier_ratio", i.min_inlier_ratio}}}};
}

RobustKernel ParseKernel(const std::string& name) {
  if (name == "none") return RobustKernel::kNone;
  if (name == "huber") return RobustKernel::kHuber;
  if (name == "cauchy") return RobustKernel::kCauchy;
  if (name == "tukey") return RobustKernel::kTukey;
  throw std::invalid_argument("--kernel '" + name + "': expected none, huber, cauchy or tukey");
}

void PrintStatsRow(const std::string& label, const ErrorStats& s) {
  fmt::print(
      "  {:<10} {:>5}  {:8.4f} ± {:<8.4f} m  {:7.3f} ± {:<7.3f} deg  (max {:.3f} m, {:.2f} deg)\n",
      label, s.count, s.translation_mean_m, s.translation_std_m, s.rotation_mean_deg,
      s.rotation_std_deg, s.translation_max_m, s.rotation_max_deg);
}

void PrintRelations(const std::string& name, const RelationErrorReport& r) {
  fmt::print("{} relation error ({} of {} relations matched):\n", name, r.matched, r.relations);
  PrintStatsRow("all", r.all);
  PrintStatsRow("local", r.local);
  PrintStatsRow("loop", r.loop);
}

void RunOdometry(OdometryOptions options) {
  options.config.icp.kernel = ParseKernel(options.kernel);
  ValidateScanOdometryConfig(options.config);
  if (options.corrected_path.empty() != options.index_path.empty()) {
    throw std::invalid_argument("--corrected and --raw-to-corrected must be given together");
  }

  const CarmenLog log = ReadLogWithScans(options.input);
  // Processing order: file order, or sorted (stably) by logger or ipc timestamp.
  std::vector<std::size_t> order(log.scans.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (options.order == "logger") {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return log.scans[a].logger_timestamp_s < log.scans[b].logger_timestamp_s;
    });
  } else if (options.order == "ipc") {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return log.scans[a].timestamp_s < log.scans[b].timestamp_s;
    });
  } else if (options.order != "file") {
    throw std::invalid_argument("--order '" + options.order + "': expected logger, ipc or file");
  }
  ScanRange range{0, order.size()};
  if (!options.scans.empty()) range = ParseScanRange(options.scans, order.size());

  ScanOdometry odometry(options.config);
  std::vector<ScanOdometryResult> results;
  results.reserve(range.end - range.begin);
  std::vector<TimedPose> icp_trajectory;
  std::vector<TimedPose> odometry_trajectory;
  std::vector<Pose2> icp_by_raw_index(log.scans.size());
  std::vector<std::uint8_t> has_estimate(log.scans.size(), 0);
  std::size_t missing_odometry = 0;
  Progress progress("odometry", range.end - range.begin);
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = range.begin; k < range.end; ++k) {
    const LogScan& scan = log.scans[order[k]];
    const ScanOdometryResult result = odometry.Add(scan, scan.odometry_pose);
    icp_trajectory.push_back({scan.timestamp_s, result.T_world_robot});
    if (scan.odometry_pose) {
      odometry_trajectory.push_back({scan.timestamp_s, *scan.odometry_pose});
    } else {
      ++missing_odometry;
    }
    icp_by_raw_index[order[k]] = result.T_world_robot;
    has_estimate[order[k]] = 1;
    results.push_back(result);
    progress.Update(k + 1 - range.begin);
  }
  progress.Finish();
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Per-scan statistics.
  std::size_t not_converged = 0, fallback_correction = 0, fallback_points = 0, degenerate = 0,
              keyframes = 0;
  double seconds_sum = 0.0, seconds_max = 0.0, iterations_sum = 0.0;
  std::size_t registered = 0;
  for (const ScanOdometryResult& r : results) {
    seconds_sum += r.seconds;
    seconds_max = std::max(seconds_max, r.seconds);
    keyframes += r.keyframe ? 1 : 0;
    degenerate += r.degenerate ? 1 : 0;
    switch (r.status) {
      case ScanOdometryStatus::kRegistered:
        ++registered;
        iterations_sum += r.iterations;
        break;
      case ScanOdometryStatus::kFallbackNotConverged:
        ++not_converged;
        break;
      case ScanOdometryStatus::kFallbackCorrectionTooLarge:
        ++fallback_correction;
        break;
      case ScanOdometryStatus::kFallbackTooFewPoints:
        ++fallback_points;
        break;
      case ScanOdometryStatus::kFirstScan:
        break;
    }
  }
  const double n = std::max<double>(1.0, static_cast<double>(results.size()));

  nlohmann::json json;
  json["log"] = options.input;
  json["order"] = options.order;
  json["scans"] = results.size();
  json["scans_in_log"] = log.scans.size();
  json["registered"] = registered;
  json["not_converged"] = not_converged;
  json["fallback_correction_too_large"] = fallback_correction;
  json["fallback_too_few_points"] = fallback_points;
  json["degenerate"] = degenerate;
  json["keyframes"] = keyframes;
  json["missing_odometry"] = missing_odometry;
  json["seconds_per_scan_mean"] = seconds_sum / n;
  json["seconds_per_scan_max"] = seconds_max;
  json["seconds_total"] = total_s;
  json["iterations_mean"] = registered > 0 ? iterations_sum / registered : 0.0;
  json["config"] = ConfigJson(options.config);

  fmt::print("scans           {} of {} ({} order)\n", results.size(), log.scans.size(),
             options.order);
  fmt::print("registered      {}\n", registered);
  fmt::print("fallbacks       {} not converged, {} correction too large, {} too few points\n",
             not_converged, fallback_correction, fallback_points);
  fmt::print("degenerate      {}\n", degenerate);
  fmt::print("key scans       {}\n", keyframes);
  fmt::print("time per scan   {:.3f} ms mean, {:.3f} ms max ({:.1f} s in total)\n",
             1e3 * seconds_sum / n, 1e3 * seconds_max, total_s);

  if (!options.relations_path.empty()) {
    const std::vector<Relation> relations = ReadRelations(options.relations_path);
    RelationErrorConfig relation_config;
    relation_config.local_max_dt_s = options.local_max_dt_s;
    const RelationErrorReport icp = EvaluateRelations(icp_trajectory, relations, relation_config);
    const RelationErrorReport odo =
        EvaluateRelations(odometry_trajectory, relations, relation_config);
    PrintRelations("ICP", icp);
    PrintRelations("odometry", odo);
    json["relations_file"] = options.relations_path;
    json["local_max_dt_s"] = options.local_max_dt_s;
    json["icp"] = RelationJson(icp);
    json["odometry"] = RelationJson(odo);
    if (!options.relation_errors_path.empty()) {
      // Per relation: both trajectories' errors side by side (same relation order).
      WriteFileAtomically(options.relation_errors_path, [&](std::ostream& out) {
        out << "# line\tt_a\tt_b\tdt_s\tlocal\ticp_translation_m\ticp_rotation_deg"
               "\todometry_translation_m\todometry_rotation_deg\n";
        std::size_t j = 0;
        for (const RelationErrorItem& item : icp.items) {
          while (j < odo.items.size() && odo.items[j].relation_index < item.relation_index) ++j;
          const Relation& rel = relations[item.relation_index];
          out << fmt::format("{}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{:.6f}\t{:.6f}\t", rel.line,
                             rel.timestamp_a_s, rel.timestamp_b_s, item.dt_s, item.local ? 1 : 0,
                             item.error.translation_m, item.error.rotation_deg);
          if (j < odo.items.size() && odo.items[j].relation_index == item.relation_index) {
            out << fmt::format("{:.6f}\t{:.6f}\n", odo.items[j].error.translation_m,
                               odo.items[j].error.rotation_deg);
          } else {
            out << "nan\tnan\n";
          }
        }
      });
    }
  }

  if (!options.corrected_path.empty()) {
    const CarmenLog corrected = ReadLogWithScans(options.corrected_path);
    std::vector<Pose2> corrected_poses;
    for (const LogScan& scan : corrected.scans) {
      if (!scan.corrected_pose) {
        throw std::invalid_argument(options.corrected_path + ":" + std::to_string(scan.line) +
                                    ": scan has no corrected pose");
      }
      corrected_poses.push_back(*scan.corrected_pose);
    }
    std::vector<IndexPair> pairs;
    for (const IndexPair& pair : ReadIndexPairs(options.index_path)) {
      if (pair.raw_index < has_estimate.size() && has_estimate[pair.raw_index]) {
        pairs.push_back(pair);
      }
    }
    std::vector<Pose2> odometry_by_raw_index(log.scans.size());
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      if (log.scans[i].odometry_pose) odometry_by_raw_index[i] = *log.scans[i].odometry_pose;
    }
    const DriftReport icp_drift = EvaluateDrift(icp_by_raw_index, corrected_poses, pairs);
    const DriftReport odo_drift = EvaluateDrift(odometry_by_raw_index, corrected_poses, pairs);
    fmt::print("drift against corrected poses ({} scans):\n", icp_drift.pairs);
    for (const auto& [name, d] :
         {std::pair<std::string, const DriftReport&>{"ICP", icp_drift},
          std::pair<std::string, const DriftReport&>{"odometry", odo_drift}}) {
      fmt::print(
          "  {:<10} consecutive {:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg; ATE rmse {:.3f} m "
          "(max {:.3f} m), {:.2f} deg\n",
          name, d.consecutive.translation_mean_m, d.consecutive.translation_std_m,
          d.consecutive.rotation_mean_deg, d.consecutive.rotation_std_deg, d.ate_rmse_m,
          d.ate_max_m, d.ate_rotation_rmse_deg);
    }
    json["drift"] = {{"corrected_log", options.corrected_path},
                     {"index_file", options.index_path},
                     {"icp", DriftJson(icp_drift)},
                     {"odometry", DriftJson(odo_drift)}};
  }

  if (!options.out_path.empty()) {
    WriteFileAtomically(options.out_path, [&](std::ostream& out) {
      out << "# timestamp_s\tx_m\ty_m\ttheta_rad\n";
      for (const TimedPose& p : icp_trajectory) {
        out << fmt::format("{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\n", p.timestamp_s, p.pose.x, p.pose.y,
                           p.pose.theta);
      }
    });
  }
  if (!options.json_path.empty()) WriteJson(options.json_path, json);
}

}  // namespace

void RegisterOdometryCommand(CLI::App& app) {
  auto options = std::make_shared<OdometryOptions>();
  CLI::App* command = app.add_subcommand(
      "odometry",
      "Scan-matching odometry on a raw log: every scan is registered with point-to-line ICP "
      "against a local map of the last key scans, initialised by the odometry increment; when "
      "ICP fails the odometry increment is used and the scan is counted as a fallback. Prints "
      "the run statistics and, with --relations, the relation error of Kümmerle et al. (2009) "
      "for the ICP trajectory and for raw odometry: mean ± std of the translational (m) and "
      "rotational (deg) error of the relative poses, over all relations and split into local "
      "(|t_b - t_a| < --local-dt) and loop relations. The trajectory is the robot pose, in the "
      "odometry frame of the first scan.");
  command->add_option("input", options->input, "raw CARMEN log with odometry (.log or .log.gz)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--out", options->out_path,
                      "write the ICP trajectory as TSV: ipc timestamp (s), x (m), y (m), theta "
                      "(rad), one row per scan in processing order");
  command
      ->add_option("--relations", options->relations_path,
                   "Kümmerle relation file (t_a t_b dx dy dz droll dpitch dyaw; times are "
                   "ipc timestamps of the raw log, matched exactly)")
      ->check(CLI::ExistingFile);
  command->add_option("--relation-errors", options->relation_errors_path,
                      "with --relations: write the error of every matched relation as TSV");
  command
      ->add_option("--corrected", options->corrected_path,
                   "corrected log (ROBOTLASER1 + VERTEX2) for drift: consecutive relative error "
                   "and ATE after SE(2) alignment; needs --raw-to-corrected")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--raw-to-corrected", options->index_path,
                   "raw_index corrected_index TSV pairing raw scans with corrected scans")
      ->check(CLI::ExistingFile);
  command->add_option("--json", options->json_path,
                      "also write all figures (run statistics, relation errors, drift, config) as "
                      "JSON to FILE");
  command->add_option("--scans", options->scans,
                      "process only scans A:B of the processing order (half-open, e.g. 0:500)");
  command
      ->add_option("--order", options->order,
                   "processing order: logger (by logger_timestamp; needed for Intel raw, whose "
                   "ipc stamps are not monotonic), ipc, or file")
      ->capture_default_str();
  command
      ->add_option("--local-dt", options->local_max_dt_s,
                   "relations with |t_b - t_a| below this (s) are local, the others loop")
      ->capture_default_str();
  // Tuning knobs (defaults = ScanOdometryConfig / IcpConfig defaults).
  command
      ->add_option("--local-map-scans", options->config.local_map_scans,
                   "key scans in the local map")
      ->capture_default_str();
  command
      ->add_option("--keyframe-translation", options->config.keyframe_translation_m,
                   "a scan becomes a key scan after moving this far (m)")
      ->capture_default_str();
  command
      ->add_option("--keyframe-rotation", options->config.keyframe_rotation_rad,
                   "... or turning this much (rad)")
      ->capture_default_str();
  command
      ->add_option("--source-spacing", options->config.source_min_spacing_m,
                   "registered scan: skip points closer than this to the previous kept one (m)")
      ->capture_default_str();
  command->add_option("--min-range", options->config.min_range_m, "shortest beam used (m)")
      ->capture_default_str();
  command
      ->add_option("--max-range", options->config.max_range_m,
                   "beams at or beyond this range are not used (m)")
      ->capture_default_str();
  command
      ->add_option("--correspondence-distance", options->config.icp.max_correspondence_distance_m,
                   "max distance of a source point to its nearest map point (m)")
      ->capture_default_str();
  command->add_option("--kernel", options->kernel, "robust kernel: none, huber, cauchy, tukey")
      ->capture_default_str();
  command
      ->add_option("--kernel-scale", options->config.icp.kernel_scale_m,
                   "scale of the robust kernel on the point-to-line residual (m)")
      ->capture_default_str();
  command
      ->add_option("--normal-neighbours", options->config.icp.normal_neighbours,
                   "neighbours for the normal of a map point")
      ->capture_default_str();
  command
      ->add_option("--normal-radius", options->config.icp.normal_max_neighbour_distance_m,
                   "neighbours farther than this are ignored for a normal (m)")
      ->capture_default_str();
  command
      ->add_option("--degeneracy", options->config.icp.degeneracy_min_eigenvalue,
                   "information eigenvalue below which a direction is held at the odometry "
                   "guess (0 = off)")
      ->capture_default_str();
  command
      ->add_option("--max-iterations", options->config.icp.max_iterations,
                   "Gauss-Newton iterations per scan")
      ->capture_default_str();
  command
      ->add_option("--convergence-translation", options->config.icp.convergence_translation_m,
                   "ICP stops when an increment moves less than this (m) ...")
      ->capture_default_str();
  command
      ->add_option("--convergence-rotation", options->config.icp.convergence_rotation_rad,
                   "... and turns less than this (rad)")
      ->capture_default_str();
  command
      ->add_option("--max-correction", options->config.max_correction_translation_m,
                   "ICP results further than this from the odometry prediction are rejected "
                   "(m)")
      ->capture_default_str();
  command->callback([options] { RunOdometry(*options); });
}

}  // namespace keyplace::cli
