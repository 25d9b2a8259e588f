// The figures of SlamRun and SlamEvaluation (docs in keyplace/eval/slam_evaluation.hpp).

#include <cstdint>

#include "keyplace/eval/slam_evaluation.hpp"

namespace keyplace {
namespace {

// A run's counters live in its OnlineSlam (SlamStats).
ResultFields<SlamRun>& AddStatsCount(ResultFields<SlamRun>& table, const char* name,
                                     std::size_t SlamStats::*member, const char* meaning) {
  return table.Add(name, "", meaning, [member](const SlamRun& run) -> ResultValue {
    return CountValue(run.slam->stats().*member);
  });
}

ResultFields<SlamRun>& AddStatsSeconds(ResultFields<SlamRun>& table, const char* name,
                                       double SlamStats::*member, const char* meaning) {
  return table.Add(name, "s", meaning, [member](const SlamRun& run) -> ResultValue {
    return run.slam->stats().*member;
  });
}

// A loop precision is a share of the loops: missing when there are none.
ResultFields<SlamEvaluation>& AddPrecision(ResultFields<SlamEvaluation>& table, const char* name,
                                           double LoopPrecisions::*member, const char* meaning) {
  return table.Add(name, "", meaning, [member](const SlamEvaluation& e) -> ResultValue {
    if (e.loops.overlap.empty()) return {};
    return e.precision.*member;
  });
}

// A figure against ground truth: missing without the ATE alignment.
ResultFields<SlamEvaluation>& AddAccuracy(ResultFields<SlamEvaluation>& table, const char* name,
                                          const char* unit, const char* meaning,
                                          double (*read)(const SlamAccuracy&)) {
  return table.Add(name, unit, meaning, [read](const SlamEvaluation& e) -> ResultValue {
    if (!e.accuracy) return {};
    return read(*e.accuracy);
  });
}

// A count of the loop check against ground truth: missing without truth.
ResultFields<SlamEvaluation>& AddTruthCount(ResultFields<SlamEvaluation>& table, const char* name,
                                            const char* meaning,
                                            std::int64_t (*read)(const SlamEvaluation&)) {
  return table.Add(name, "", meaning, [read](const SlamEvaluation& e) -> ResultValue {
    if (!e.has_truth) return {};
    return read(e);
  });
}

ResultFields<SlamRun> MakeSlamRunFields() {
  ResultFields<SlamRun> table;
  table.Count("scans", &SlamRun::scans, "scans of the log given to SLAM");
  AddStatsCount(table, "queries", &SlamStats::queries, "completed submaps matched against the map");
  table.Add("loops_detected", "", "loops place recognition found (accepted or not)",
            [](const SlamRun& run) -> ResultValue { return CountValue(run.slam->loops().size()); });
  AddStatsCount(table, "loops_accepted", &SlamStats::loops_accepted, "loops that passed the gate");
  AddStatsCount(table, "loops_deferred", &SlamStats::loops_deferred,
                "of those, loops the estimate already met within their sigmas (optimised later)");
  AddStatsCount(table, "loops_refined", &SlamStats::loops_refined,
                "loop transforms refined by ICP");
  AddStatsCount(table, "loops_partner_changed", &SlamStats::loops_partner_changed,
                "loops whose partner is a neighbour of the matched submap");
  AddStatsCount(table, "loops_rejected_by_point_overlap",
                &SlamStats::loops_rejected_by_point_overlap,
                "matches dropped by slam.loop_refinement.min_point_overlap");
  AddStatsCount(table, "optimizations", &SlamStats::optimizations, "pose graph optimisations");
  AddStatsCount(table, "ceres_solves", &SlamStats::solves, "Ceres solves of those");
  table
      .Number("seconds_keypoints", &SlamRun::seconds_keypoints, "s",
              "FLIRT keypoints of every scan, before SLAM or (keyplace slam) while it ran, "
              "within seconds_slam")
      .Number("seconds_slam", &SlamRun::seconds_slam, "s", "AddScan of every scan and Finish");
  AddStatsSeconds(table, "seconds_odometry", &SlamStats::seconds_odometry, "... of which ICP");
  AddStatsSeconds(table, "seconds_mapping", &SlamStats::seconds_mapping, "... submaps");
  AddStatsSeconds(table, "seconds_recognition", &SlamStats::seconds_recognition,
                  "... place recognition and loop refinement");
  AddStatsSeconds(table, "seconds_loop_refinement", &SlamStats::seconds_loop_refinement,
                  "... of which loop refinement and partner choice");
  AddStatsSeconds(table, "seconds_optimization", &SlamStats::seconds_optimization,
                  "... pose graph optimisation");
  return table;
}

void AddLoopFigures(ResultFields<SlamEvaluation>& table) {
  table.Add("loops_used", "", "loops used in the final graph",
            [](const SlamEvaluation& e) -> ResultValue { return CountValue(e.loops.used_count); });
  AddPrecision(table, "precision_overlap_10", &LoopPrecisions::overlap_10,
               "share of loops whose submaps overlap by 10 % (Figure 10)");
  AddPrecision(table, "precision_overlap_30", &LoopPrecisions::overlap_30, "... by 30 %");
  table.Add("precision_overlap_30_used", "", "... of the loops used in the final graph",
            [](const SlamEvaluation& e) -> ResultValue {
              if (e.loops.used_count == 0) return {};
              return e.precision.used_overlap_30;
            });
  AddPrecision(table, "precision_overlap_10_cells_0_2m", &LoopPrecisions::cells_0_2m_10,
               "at 10 % on 0.2 m cells (sensitivity of the measure)");
  AddPrecision(table, "precision_overlap_30_cells_0_2m", &LoopPrecisions::cells_0_2m_30,
               "at 30 % on 0.2 m cells");
  AddPrecision(table, "precision_overlap_10_common_area", &LoopPrecisions::common_area_10,
               "at 10 % over the area both submaps observed");
  AddPrecision(table, "precision_overlap_30_common_area", &LoopPrecisions::common_area_30,
               "at 30 % over the area both submaps observed");
  AddPrecision(table, "precision_overlap_30_matched_ransac", &LoopPrecisions::matched_ransac_30,
               "at 30 % before loop refinement and partner choice");
  table.Count("loops_below_1_percent_overlap", &SlamEvaluation::loops_below_1_percent,
              "loops whose submaps overlap by less than 1 %");
}

void AddTruthFigures(ResultFields<SlamEvaluation>& table) {
  AddTruthCount(table, "loops_truth_evaluated",
                "loops whose submap origins are near a scan with a truth pose",
                [](const SlamEvaluation& e) -> std::int64_t { return e.loops.truth_evaluated; });
  AddTruthCount(table, "loops_truth_correct", "... within 0.5 m and 10 deg of the truth",
                [](const SlamEvaluation& e) -> std::int64_t { return e.loops.truth_correct; });
  AddTruthCount(table, "loops_truth_max_gap_scans",
                "how far (scans) an origin may be from a scan with a truth pose",
                [](const SlamEvaluation& e) -> std::int64_t { return e.truth_max_gap_scans; });
  table.Add("precision_truth", "", "loops_truth_correct / loops_truth_evaluated",
            [](const SlamEvaluation& e) -> ResultValue {
              if (!e.has_truth || e.loops.truth_evaluated == 0) return {};
              return e.loops.precision_truth();
            });
  table.Add("truth_pairs", "", "scans with a truth pose, paired for ATE and RPE",
            [](const SlamEvaluation& e) -> ResultValue {
              if (!e.accuracy) return {};
              return CountValue(e.accuracy->truth_pairs);
            });
  AddAccuracy(table, "ate_rmse_m", "m", "ATE of SLAM after SE(2) alignment, RMSE",
              [](const SlamAccuracy& a) { return a.ate.translation_rmse_m; });
  AddAccuracy(table, "ate_rotation_rmse_deg", "deg", "... rotation",
              [](const SlamAccuracy& a) { return a.ate.rotation_rmse_deg; });
  AddAccuracy(table, "ate_icp_rmse_m", "m", "ATE of the ICP odometry, RMSE",
              [](const SlamAccuracy& a) { return a.ate_icp.translation_rmse_m; });
  AddAccuracy(table, "ate_icp_rotation_rmse_deg", "deg", "... rotation",
              [](const SlamAccuracy& a) { return a.ate_icp.rotation_rmse_deg; });
}

ResultFields<SlamEvaluation> MakeSlamEvaluationFields() {
  ResultFields<SlamEvaluation> table;
  AddLoopFigures(table);
  AddTruthFigures(table);
  table.Number("seconds_per_submap", &SlamEvaluation::seconds_per_submap, "s",
               "SLAM time per submap (Table IX)");
  return table;
}

}  // namespace

const ResultFields<SlamRun>& SlamRunFields() {
  static const ResultFields<SlamRun> fields = MakeSlamRunFields();
  return fields;
}

const ResultFields<SlamEvaluation>& SlamEvaluationFields() {
  static const ResultFields<SlamEvaluation> fields = MakeSlamEvaluationFields();
  return fields;
}

}  // namespace keyplace
