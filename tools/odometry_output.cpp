#include "odometry_output.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <utility>

#include <fmt/core.h>

#include "eval_json.hpp"
#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

double RadToDeg(double rad) { return rad * 180.0 / M_PI; }

void PrintStatsRow(const std::string& label, const ErrorStats& s) {
  if (s.count == 0) {
    fmt::print("  {:<10} {:>5}  no relations\n", label, 0);
    return;
  }
  fmt::print(
      "  {:<10} {:>5}  {:8.4f} ± {:<8.4f} m  {:7.3f} ± {:<7.3f} deg  (max {:.3f} m, {:.2f} deg)\n",
      label, s.count, s.translation_mean_m, s.translation_std_m, s.rotation_mean_deg,
      s.rotation_std_deg, s.translation_max_m, s.rotation_max_deg);
}

void PrintRelations(const std::string& name, const RelationErrorReport& r) {
  if (!r.refusal.empty()) {
    fmt::print("{} relation error: none, {}\n", name, r.refusal);
    return;
  }
  fmt::print("{} relation error ({} of {} relations matched{}):\n", name, r.matched, r.relations,
             OutsideSpanNote(r));
  PrintStatsRow("all", r.all);
  PrintStatsRow("local", r.local);
  PrintStatsRow("loop", r.loop);
}

}  // namespace

void PrintOdometryRun(const OdometryRun& run) {
  const OdometryRunStats& s = run.stats;
  fmt::print("scans           {} of {} ({} order)\n", s.scans, run.log_scans, ToString(run.order));
  fmt::print("registered      {}\n", s.registered);
  fmt::print(
      "recovered       {} (the prediction was wrong: ICP converged from a searched pose, or the "
      "odometry glitched)\n",
      s.recovered);
  fmt::print(
      "fallbacks       {} not converged, {} correction too large, {} too few points, {} weak "
      "matches the odometry contradicts\n",
      s.not_converged, s.fallback_correction_too_large, s.fallback_too_few_points,
      s.fallback_weak_match);
  fmt::print("degenerate      {}\n", s.degenerate);
  fmt::print("key scans       {}\n", s.keyframes);
  fmt::print("time per scan   {:.3f} ms mean, {:.3f} ms max ({:.1f} s in total)\n",
             1e3 * s.seconds_per_scan_mean, 1e3 * s.seconds_per_scan_max, s.seconds_total);
}

void PrintStepDisagreement(const OdometryStepDisagreement& summary) {
  if (summary.steps == 0) {
    fmt::print("ICP vs odometry no step where ICP converged between two odometry poses\n");
    return;
  }
  fmt::print(
      "ICP vs odometry median {:.3f} m, {:.2f} deg per step; 99 % below {:.3f} m, {:.2f} deg "
      "({} steps where ICP converged)\n",
      summary.median_m, RadToDeg(summary.median_rad), summary.p99_m, RadToDeg(summary.p99_rad),
      summary.steps);
}

nlohmann::json StepDisagreementJson(const OdometryStepDisagreement& summary) {
  nlohmann::json json = {{"steps", summary.steps}};
  const bool any = summary.steps > 0;
  json["median_m"] = any ? nlohmann::json(summary.median_m) : nlohmann::json(nullptr);
  json["p99_m"] = any ? nlohmann::json(summary.p99_m) : nlohmann::json(nullptr);
  json["median_deg"] = any ? nlohmann::json(RadToDeg(summary.median_rad)) : nlohmann::json(nullptr);
  json["p99_deg"] = any ? nlohmann::json(RadToDeg(summary.p99_rad)) : nlohmann::json(nullptr);
  return json;
}

nlohmann::json OdometryRunJson(const OdometryRun& run) {
  const OdometryRunStats& s = run.stats;
  return {{"order", ToString(run.order)},
          {"scans", s.scans},
          {"scans_in_log", run.log_scans},
          {"registered", s.registered},
          {"recovered", s.recovered},
          {"not_converged", s.not_converged},
          {"fallback_correction_too_large", s.fallback_correction_too_large},
          {"fallback_too_few_points", s.fallback_too_few_points},
          {"fallback_weak_match", s.fallback_weak_match},
          {"degenerate", s.degenerate},
          {"keyframes", s.keyframes},
          {"missing_odometry", s.missing_odometry},
          {"seconds_per_scan_mean", s.seconds_per_scan_mean},
          {"seconds_per_scan_max", s.seconds_per_scan_max},
          {"seconds_total", s.seconds_total},
          {"iterations_mean", s.iterations_mean}};
}

void PrintOdometryRelations(const OdometryRelationErrors& errors) {
  PrintRelations("ICP", errors.icp);
  PrintRelations("odometry", errors.odometry);
}

void PrintOdometryDrift(const OdometryDrift& drift) {
  fmt::print("drift against corrected poses ({} scans):\n", drift.icp.pairs);
  for (const auto& [name, d] :
       {std::pair<std::string, const DriftReport&>{"ICP", drift.icp},
        std::pair<std::string, const DriftReport&>{"odometry", drift.odometry}}) {
    fmt::print(
        "  {:<10} consecutive {:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg; ATE rmse {:.3f} m "
        "(max {:.3f} m), {:.2f} deg; worst {}-step heading {}\n",
        name, d.consecutive.translation_mean_m, d.consecutive.translation_std_m,
        d.consecutive.rotation_mean_deg, d.consecutive.rotation_std_deg, d.ate_rmse_m, d.ate_max_m,
        d.ate_rotation_rmse_deg, kDriftWindowSteps,
        d.window_heading_max_deg ? fmt::format("{:.2f} deg (from raw scan {})",
                                               *d.window_heading_max_deg, d.window_start_raw_index)
                                 : std::string("n/a (too few scans)"));
  }
}

nlohmann::json DriftJson(const DriftReport& d) {
  return {
      {"pairs", d.pairs},
      {"consecutive", StatsJson(d.consecutive)},
      {"ate_rmse_m", d.ate_rmse_m},
      {"ate_mean_m", d.ate_mean_m},
      {"ate_max_m", d.ate_max_m},
      {"ate_rotation_rmse_deg", d.ate_rotation_rmse_deg},
      {"window_steps", kDriftWindowSteps},
      {"window_heading_max_deg", d.window_heading_max_deg
                                     ? nlohmann::json(*d.window_heading_max_deg)
                                     : nlohmann::json(nullptr)},
      {"window_start_raw_index", d.window_heading_max_deg ? nlohmann::json(d.window_start_raw_index)
                                                          : nlohmann::json(nullptr)}};
}

void WriteRelationErrorsTsv(const std::string& path, const std::vector<Relation>& relations,
                            const OdometryRelationErrors& errors) {
  const std::vector<RelationErrorItem>& odo = errors.odometry.items;
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# line\tt_a\tt_b\tdt_s\tlocal\ticp_translation_m\ticp_rotation_deg"
           "\todometry_translation_m\todometry_rotation_deg\n";
    std::size_t j = 0;
    for (const RelationErrorItem& item : errors.icp.items) {
      while (j < odo.size() && odo[j].relation_index < item.relation_index) ++j;
      const Relation& rel = relations[item.relation_index];
      out << fmt::format("{}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{:.6f}\t{:.6f}\t", rel.line,
                         rel.timestamp_a_s, rel.timestamp_b_s, item.dt_s, item.local ? 1 : 0,
                         item.error.translation_m, item.error.rotation_deg);
      if (j < odo.size() && odo[j].relation_index == item.relation_index) {
        out << fmt::format("{:.6f}\t{:.6f}\n", odo[j].error.translation_m,
                           odo[j].error.rotation_deg);
      } else {
        out << "nan\tnan\n";
      }
    }
  });
}

void WriteStepsTsv(const std::string& path, const std::vector<OdometryStep>& steps) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# scan_index\ttimestamp_s\tstatus\tinlier_ratio\tresidual_rms_m\titerations\t"
           "degenerate\ticp_dx_m\ticp_dy_m\ticp_dtheta_rad\todometry_dx_m\todometry_dy_m\t"
           "odometry_dtheta_rad\tdisagreement_m\tdisagreement_deg\n";
    for (const OdometryStep& step : steps) {
      const Pose2& icp = step.T_previous_current_icp;
      out << fmt::format("{}\t{:.6f}\t{}\t{:.4f}\t{:.5f}\t{}\t{:d}\t{:.6f}\t{:.6f}\t{:.6f}\t",
                         step.scan_index, step.timestamp_s, ToString(step.status),
                         step.inlier_ratio, step.residual_rms_m, step.iterations,
                         step.degenerate ? 1 : 0, icp.x, icp.y, icp.theta);
      if (step.T_previous_current_odometry) {
        const Pose2& odometry = *step.T_previous_current_odometry;
        out << fmt::format("{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.4f}\n", odometry.x, odometry.y,
                           odometry.theta, step.disagreement_m, RadToDeg(step.disagreement_rad));
      } else {
        out << "nan\tnan\tnan\tnan\tnan\n";
      }
    }
  });
}

void WriteTrajectoryTsv(const std::string& path, const std::vector<TimedPose>& trajectory) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "# timestamp_s\tx_m\ty_m\ttheta_rad\n";
    for (const TimedPose& p : trajectory) {
      out << fmt::format("{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\n", p.timestamp_s, p.pose.x, p.pose.y,
                         p.pose.theta);
    }
  });
}

}  // namespace keyplace::cli
