#include "odometry_output.hpp"

#include <algorithm>
#include <ostream>
#include <utility>

#include <fmt/core.h>

#include "eval_json.hpp"
#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

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
      "recovered       {} (ICP failed from the prediction, converged from a searched pose)\n",
      s.recovered);
  fmt::print("fallbacks       {} not converged, {} correction too large, {} too few points\n",
             s.not_converged, s.fallback_correction_too_large, s.fallback_too_few_points);
  fmt::print("degenerate      {}\n", s.degenerate);
  fmt::print("key scans       {}\n", s.keyframes);
  fmt::print("time per scan   {:.3f} ms mean, {:.3f} ms max ({:.1f} s in total)\n",
             1e3 * s.seconds_per_scan_mean, 1e3 * s.seconds_per_scan_max, s.seconds_total);
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
