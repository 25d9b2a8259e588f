// The printed summary and the pictures of `keyplace slam`.

#include "slam_output.hpp"

#include <filesystem>
#include <vector>

#include <fmt/core.h>

#include "eval_json.hpp"
#include "paper_tables.hpp"
#include "slam_figures.hpp"

namespace keyplace::cli {
namespace {

void PrintLoopCounts(const SlamReport& r) {
  const SlamStats& s = r.run.slam->stats();
  const LoopEvaluation& ev = r.evaluation.loops;
  const LoopPrecisions& p = r.evaluation.precision;
  fmt::print("submaps            {} ({} queried)\n", s.submaps, s.queries);
  fmt::print("loops              {} detected, {} accepted by the gate, {} used in the graph\n",
             r.run.slam->loops().size(), s.loops_accepted, ev.used_count);
  fmt::print(
      "loop refinement    {} refined by ICP, {} with a neighbour of the matched submap as "
      "partner",
      s.loops_refined, s.loops_partner_changed);
  if (!r.run.slam->loops().empty()) {
    fmt::print("; precision at 30 % before refinement and partner choice {:.3f}",
               p.matched_ransac_30);
  }
  fmt::print("\n");
  const double min_point_overlap = r.config.slam.loop_refinement.min_point_overlap;
  if (min_point_overlap > 0.0) {
    fmt::print(
        "                   {} matches dropped by slam.loop_refinement.min_point_overlap {:.2f}\n",
        s.loops_rejected_by_point_overlap, min_point_overlap);
  }
  fmt::print(
      "optimisations      {} ({} Ceres solves, {:.2f} s); {} loops already met by the estimate "
      "waited for a later one\n",
      s.optimizations, s.solves, s.seconds_optimization, s.loops_deferred);
}

void PrintLoopPrecision(const SlamReport& r) {
  const LoopEvaluation& ev = r.evaluation.loops;
  const LoopPrecisions& p = r.evaluation.precision;
  if (r.run.slam->loops().empty()) {
    fmt::print("loop precision     no loops\n");
    return;
  }
  fmt::print("loop precision     {:.3f} at 10 % overlap, {:.3f} at 30 % ", p.overlap_10,
             p.overlap_30);
  if (ev.used_count == 0) {
    fmt::print("(none used)\n");
  } else {
    fmt::print("({:.3f} of the used)\n", p.used_overlap_30);
  }
  fmt::print("                   {:.3f} at 30 % with 0.2 m cells (sensitivity of the measure)\n",
             p.cells_0_2m_30);
  fmt::print(
      "                   {:.3f} at 10 %, {:.3f} at 30 % counting only the area both submaps "
      "observed\n",
      p.common_area_10, p.common_area_30);
  if (!r.evaluation.has_truth) return;
  if (ev.truth_evaluated == 0) {
    fmt::print(
        "                   no loop can be checked against ground truth (none within {} "
        "scans of a corrected scan)\n",
        r.evaluation.truth_max_gap_scans);
    return;
  }
  fmt::print(
      "                   {:.3f} against ground truth (0.5 m, 10 deg): {} of {} loops whose "
      "submap origins are at most {} scans from a corrected scan (mean {:.1f})\n",
      ev.precision_truth(), ev.truth_correct, ev.truth_evaluated, r.evaluation.truth_max_gap_scans,
      ev.truth_mean_gap_scans);
  if (ev.paired_loops == 0) return;
  fmt::print(
      "                   loop transform error against ground truth, mean over {} loops: "
      "{:.3f} m / {:.2f} deg (place recognition's RANSAC estimate: {:.3f} m / {:.2f} deg)\n",
      ev.paired_loops, ev.paired_final_m, ev.paired_final_deg, ev.paired_ransac_m,
      ev.paired_ransac_deg);
}

void PrintOverlaps(const SlamEvaluation& e) {
  const LoopEvaluation& ev = e.loops;
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
  const auto& h = e.histogram.counts;
  const auto& c = e.histogram_common.counts;
  fmt::print(
      "overlap histogram  [0,10) {}  [10,20) {}  [20,30) {}  [30,40) {}  [40,100] {}"
      "  ({} below 1 %)\n",
      h[0], h[1], h[2], h[3], h[4], e.loops_below_1_percent);
  fmt::print("  in common area    [0,10) {}  [10,20) {}  [20,30) {}  [30,40) {}  [40,100] {}\n",
             c[0], c[1], c[2], c[3], c[4]);
}

void PrintTimesAndTableIX(const SlamReport& r) {
  const SlamStats& s = r.run.slam->stats();
  fmt::print(
      "time               keypoints {:.1f} s{}, slam {:.1f} s (odometry {:.1f}, mapping "
      "{:.1f}, recognition {:.1f} of which loop refinement {:.1f}, optimisation {:.1f})\n",
      r.run.seconds_keypoints, r.run.keypoints_beside_slam ? " while SLAM ran" : "",
      r.run.seconds_slam, s.seconds_odometry, s.seconds_mapping, s.seconds_recognition,
      s.seconds_loop_refinement, s.seconds_optimization);
  const MappingStats& m = r.evaluation.mapping;
  const PaperSlamRow* paper = r.dataset ? PaperSlam(*r.dataset) : nullptr;
  fmt::print("\nTable IX ({})   {:>8} {:>8} {:>10} {:>8} {:>8} {:>9}\n",
             r.dataset ? *r.dataset : "?", "Compress", "#Scans", "#Keypoints", "Distrib",
             "#Submaps", "Time (s)");
  if (paper) {
    fmt::print("  paper          {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n",
               paper->compression, paper->scans_per_submap, paper->keypoints_per_submap,
               paper->distribution, paper->submaps, paper->seconds_per_submap);
  }
  fmt::print("  keyplace       {:8.2f} {:8.2f} {:10.2f} {:8.2f} {:8d} {:9.3f}\n", m.compression,
             m.scans_per_submap, m.keypoints_per_submap, m.distribution,
             static_cast<int>(m.submaps), r.evaluation.seconds_per_submap);
  if (paper) {
    fmt::print(
        "Section 6.2.2: paper {} loops detected, {} used, precision {:.2f} at 30 %, "
        "{:.2f} at 10 %\n",
        paper->loops_detected, paper->loops_used, paper->precision_overlap_30,
        paper->precision_overlap_10);
  }
}

void PrintAccuracy(const SlamEvaluation& e) {
  if (e.accuracy) {
    const SlamAccuracy& a = *e.accuracy;
    fmt::print(
        "\nATE after SE(2) alignment ({} poses): SLAM {:.3f} m / {:.2f} deg RMSE, ICP "
        "odometry {:.3f} m / {:.2f} deg\n",
        a.truth_pairs, a.ate.translation_rmse_m, a.ate.rotation_rmse_deg,
        a.ate_icp.translation_rmse_m, a.ate_icp.rotation_rmse_deg);
    fmt::print("RPE RMSE vs Delta:");
    for (const RpePoint& p : a.rpe) {
      if (p.count > 0) {
        fmt::print("  {}: {:.3f} m {:.2f} deg", p.delta, p.translation_rmse_m, p.rotation_rmse_deg);
      }
    }
    fmt::print("\n");
  }
  if (e.relations && !e.relations->refusal.empty()) {
    fmt::print("relations: no relation error, {}\n", e.relations->refusal);
  } else if (e.relations && e.relations_icp) {
    const RelationErrorReport& r = *e.relations;
    const ErrorStats& i = e.relations_icp->all;
    fmt::print(
        "relations ({} of {}{}): SLAM {:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg; ICP odometry "
        "{:.4f} ± {:.4f} m, {:.3f} ± {:.3f} deg\n",
        r.matched, r.relations, OutsideSpanNote(r), r.all.translation_mean_m,
        r.all.translation_std_m, r.all.rotation_mean_deg, r.all.rotation_std_deg,
        i.translation_mean_m, i.translation_std_m, i.rotation_mean_deg, i.rotation_std_deg);
  }
}

// RPE RMSE vs Delta and ATE vs path length, translation and rotation side by side.
void DrawAccuracyFigures(const std::filesystem::path& dir, const std::string& name,
                         const SlamAccuracy& a) {
  CurvePanel t{"Delta (scans)", "RPE RMSE (m)", {}, {}, true};
  CurvePanel r{"Delta (scans)", "RPE RMSE (deg)", {}, {}, true};
  for (const RpePoint& p : a.rpe) {
    if (p.count == 0) continue;
    t.x.push_back(static_cast<double>(p.delta));
    t.y.push_back(p.translation_rmse_m);
    r.x.push_back(static_cast<double>(p.delta));
    r.y.push_back(p.rotation_rmse_deg);
  }
  DrawCurvesFigure((dir / "rpe.png").string(), name + ": RPE RMSE vs Delta", {t, r});
  CurvePanel at{"path length (m)", "ATE (m)", {}, {}, false};
  CurvePanel ar{"path length (m)", "ATE (deg)", {}, {}, false};
  for (const AtePoint& p : a.ate.points) {
    at.x.push_back(p.path_length_m);
    at.y.push_back(p.translation_m);
    ar.x.push_back(p.path_length_m);
    ar.y.push_back(p.rotation_deg);
  }
  DrawCurvesFigure((dir / "ate.png").string(), name + ": ATE vs path length", {at, ar});
}

}  // namespace

void PrintSlamReport(const SlamReport& r) {
  fmt::print("log                {} ({} scans, {} order)\n", r.log_path, r.run.scans,
             ToString(r.run.order));
  PrintLoopCounts(r);
  PrintLoopPrecision(r);
  PrintOverlaps(r.evaluation);
  PrintTimesAndTableIX(r);
  PrintAccuracy(r.evaluation);
}

void DrawSlamFigures(const std::string& dir_name, const SlamReport& r) {
  std::filesystem::create_directories(dir_name);
  const std::filesystem::path dir(dir_name);
  const std::string name = r.dataset ? *r.dataset : r.run.map.source_log;
  const SlamEvaluation& e = r.evaluation;
  const std::size_t loops = r.run.slam->loops().size();
  DrawTrajectoryFigure(
      (dir / "trajectory.png").string(),
      fmt::format("{}: SLAM ({} loops used of {})", name, e.loops.used_count, loops),
      e.figure.estimated, e.figure.truth, e.figure.loops_used);
  DrawHistogramFigure((dir / "overlap_histogram.png").string(),
                      fmt::format("{}: overlap of matched submaps ({} loops)", name, loops),
                      e.histogram.counts);
  DrawHistogramFigure(
      (dir / "overlap_histogram_common_area.png").string(),
      fmt::format("{}: overlap in the area both submaps observed ({} loops)", name, loops),
      e.histogram_common.counts);
  if (e.accuracy && !e.accuracy->rpe.empty()) DrawAccuracyFigures(dir, name, *e.accuracy);
}

}  // namespace keyplace::cli
