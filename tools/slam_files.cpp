// The JSON of figures and the loops / trajectory TSVs of `keyplace slam`.

#include <cmath>
#include <ostream>
#include <vector>

#include <fmt/core.h>

#include "command_output.hpp"
#include "eval_json.hpp"
#include "io/atomic_file.hpp"
#include "paper_tables.hpp"
#include "result_json.hpp"
#include "slam_output.hpp"

namespace keyplace::cli {
namespace {

double Deg(double rad) { return rad * 180.0 / M_PI; }

// The overlap histograms; the figures are SlamRunFields() and SlamEvaluationFields().
void AddHistogramJson(const SlamEvaluation& e, nlohmann::json& json) {
  json["overlap_histogram_common_area"] = e.histogram_common.counts;
  json["overlap_histogram"] = e.histogram.counts;
}

void AddLoopTruthJson(const SlamEvaluation& e, nlohmann::json& json) {
  const LoopEvaluation& ev = e.loops;
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
  if (ev.paired_loops == 0) {
    for (auto& [key, value] : json["loop_truth_error"].items()) {
      if (key != "loops") value = nullptr;
    }
  }
}

nlohmann::json PaperJson(const PaperSlamRow& paper) {
  return {{"compression", paper.compression},
          {"scans_per_submap", paper.scans_per_submap},
          {"keypoints_per_submap", paper.keypoints_per_submap},
          {"distribution", paper.distribution},
          {"submaps", paper.submaps},
          {"seconds_per_submap", paper.seconds_per_submap},
          {"loops_detected", paper.loops_detected},
          {"loops_used", paper.loops_used},
          {"precision_overlap_30", paper.precision_overlap_30},
          {"precision_overlap_10", paper.precision_overlap_10}};
}

void AddRpeJson(const SlamAccuracy& a, nlohmann::json& json) {
  nlohmann::json rpe = nlohmann::json::array();
  for (const RpePoint& p : a.rpe) {
    rpe.push_back({{"delta", p.delta},
                   {"count", p.count},
                   {"translation_rmse_m", p.translation_rmse_m},
                   {"rotation_rmse_deg", p.rotation_rmse_deg}});
  }
  json["rpe"] = rpe;
}

}  // namespace

nlohmann::json SlamJson(const SlamReport& r, double total_seconds) {
  nlohmann::json json;
  json["log"] = r.log_path;
  json["dataset"] = r.dataset ? *r.dataset : "";
  json["order"] = ToString(r.run.order);
  AddResultFields(r.run, SlamRunFields(), json);
  AddResultFields(r.evaluation, SlamEvaluationFields(), json);
  AddResultFields(r.evaluation.mapping, MappingStatsFields(), json);
  json["seconds_total"] = total_seconds;
  AddHistogramJson(r.evaluation, json);
  if (r.evaluation.has_truth) AddLoopTruthJson(r.evaluation, json);
  json["config"] = ConfigJson(r.config);
  if (const PaperSlamRow* paper = r.dataset ? PaperSlam(*r.dataset) : nullptr) {
    json["paper"] = PaperJson(*paper);
  }
  if (r.evaluation.accuracy) AddRpeJson(*r.evaluation.accuracy, json);
  if (r.evaluation.relations) json["relations"] = RelationJson(*r.evaluation.relations);
  if (r.evaluation.relations_icp) json["relations_icp"] = RelationJson(*r.evaluation.relations_icp);
  return json;
}

void WriteTrajectoryTsv(const std::string& path, const SlamRun& run) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "scan_index\ttimestamp_s\tx_m\ty_m\ttheta_rad\tsubmap\ticp_x_m\ticp_y_m\t"
           "icp_theta_rad\n";
    for (const OnlineSlam::ScanPose& pose : run.trajectory) {
      out << fmt::format("{}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\n",
                         pose.scan_index, pose.timestamp_s, pose.T_world_robot.x,
                         pose.T_world_robot.y, pose.T_world_robot.theta, pose.submap,
                         pose.T_world_robot_icp.x, pose.T_world_robot_icp.y,
                         pose.T_world_robot_icp.theta);
    }
  });
}

void WriteLoopsTsv(const std::string& path, const SlamRun& run, const LoopEvaluation& e) {
  const std::vector<LoopClosure>& loops = run.slam->loops();
  const std::vector<Submap>& submaps = run.map.submaps;
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "query_submap\tquery_first_scan\treference_submap\treference_first_scan\tx_m\ty_m\t"
           "theta_rad\tpairs\tconsensus\tgamma\tconfidence\toverlap\toverlap_0_2m\t"
           "path_between_m\tgate_m\tgate_deg\taccepted\tused\ttruth_correct\ttruth_error_m\t"
           "matched_submap\tref_x_m\tref_y_m\tref_theta_rad\toverlap_matched_ransac\trefined\t"
           "refine_correction_m\trefine_correction_deg\tinlier_ratio_initial\tinlier_ratio\t"
           "point_overlap\trefine_status\ttruth_error_deg\ttruth_error_ransac_m\t"
           "truth_error_ransac_deg\toverlap_common\n";
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const LoopClosure& l = loops[k];
      out << fmt::format(
          "{}\t{}\t{}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\t{}\t{}\t{:.4f}\t{:.4f}\t{:.4f}\t{:.4f}\t"
          "{:.2f}\t{:.3f}\t{:.2f}\t{}\t{}\t{}\t{:.3f}\t{}\t{:.6f}\t{:.6f}\t{:.6f}\t{:.4f}\t{}\t"
          "{:.4f}\t{:.3f}\t{:.4f}\t{:.4f}\t{:.4f}\t{}\t{:.3f}\t{:.3f}\t{:.3f}\t{:.4f}\n",
          l.query_submap, submaps[l.query_submap].first_scan(), l.reference_submap,
          submaps[l.reference_submap].first_scan(), l.T_ref_cur.x, l.T_ref_cur.y, l.T_ref_cur.theta,
          l.pairs, l.consensus, l.gamma, l.confidence, e.overlap[k], e.overlap_coarse[k],
          l.path_between_m, l.gate_translation_m, Deg(l.gate_rotation_rad), l.accepted ? 1 : 0,
          e.used[k] ? 1 : 0, e.truth[k], e.truth_error_m[k], l.matched_submap,
          l.T_matched_cur_ransac.x, l.T_matched_cur_ransac.y, l.T_matched_cur_ransac.theta,
          e.overlap_matched_ransac[k], l.refined ? 1 : 0, l.refine_correction_m,
          Deg(l.refine_correction_rad), l.refine_inlier_ratio_initial, l.refine_inlier_ratio,
          l.point_overlap, ToString(l.refine_status), e.truth_error_deg[k],
          e.truth_error_ransac_m[k], e.truth_error_ransac_deg[k], e.overlap_common[k]);
    }
  });
}

}  // namespace keyplace::cli
