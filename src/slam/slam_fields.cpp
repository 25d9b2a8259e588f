// The field tables of the SLAM configs (docs in their headers).

#include "slam/slam_fields.hpp"
#include "registration/registration_fields.hpp"

namespace keyplace {

const ConfigFields<PoseGraphConfig>& PoseGraphConfigFields() {
  using C = PoseGraphConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("PoseGraphConfig");
    table
        .Double("loop_reject_sigmas", &C::loop_reject_sigmas, "sigma",
                "switch off loops whose whitened residual exceeds this (0 = never)")
        .Int("max_rejection_rounds", &C::max_rejection_rounds, "", "rejection rounds per solve")
        .Double("loop_loss_scale", &C::loop_loss_scale, "sigma",
                "Cauchy scale of the final robust solve on loop edges (0 = none)")
        .Int("max_iterations", &C::max_iterations, "", "Ceres iterations per solve")
        .Int("threads", &C::threads, "", "Ceres threads (1 = deterministic)");
    return table;
  }();
  return fields;
}

const ConfigFields<LoopRefinementConfig>& LoopRefinementConfigFields() {
  using C = LoopRefinementConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("LoopRefinementConfig");
    table.Bool("refine", &C::refine, "refine each loop by ICP between the submaps' point clouds")
        .Nested("icp", &C::icp, IcpConfigFields())
        .Double("max_correction_m", &C::max_correction_m, "m",
                "keep the RANSAC transform when refinement moves the origin further ...")
        .Double("max_correction_rad", &C::max_correction_rad, "rad", "... or turns it more")
        .Double("max_inlier_ratio_loss", &C::max_inlier_ratio_loss, "",
                "... or loses more than this inlier ratio")
        .Int("partner_neighbours", &C::partner_neighbours, "",
             "loop partner chosen among the matched submap and this many neighbours per side")
        .Double("min_point_overlap", &C::min_point_overlap, "",
                "drop found matches with less point overlap than this (0 = off)")
        .Double("voxel_m", &C::voxel_m, "m", "submap point clouds: one point per voxel")
        .Double("min_range_m", &C::min_range_m, "m", "shortest beam in the clouds")
        .Double("max_range_m", &C::max_range_m, "m", "beams at or beyond this are not used");
    return table;
  }();
  return fields;
}

const ConfigFields<SlamConfig>& SlamConfigFields() {
  using C = SlamConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("SlamConfig");
    table
        .Int("exclude_recent_submaps", &C::exclude_recent_submaps, "",
             "a submap is not matched with its last N predecessors ...")
        .Double("exclude_recent_path_m", &C::exclude_recent_path_m, "m",
                "... nor with submaps less than this path behind it")
        .Double("loop_search_near_m", &C::loop_search_near_m, "m",
                "retrieval words: loop queries also pair the submaps whose origin the estimate "
                "puts this close to theirs (0 = words alone)")
        .Bool("all_scan_loop_queries", &C::all_scan_loop_queries,
              "loop queries with the keypoints of all the submap's scans, not its stable ones "
              "(when place.query_keypoints = all_scans)")
        .Double("gate_base_m", &C::gate_base_m, "m",
                "loop gate: allowed disagreement with the estimate (0 = no gate) ...")
        .Double("gate_per_path", &C::gate_per_path, "m/m", "... plus this per m of path")
        .Double("gate_base_rad", &C::gate_base_rad, "rad", "allowed rotation disagreement ...")
        .Double("gate_per_path_rad", &C::gate_per_path_rad, "rad/m", "... plus this per m of path")
        .Double("odometry_sigma_base_m", &C::odometry_sigma_base_m, "m",
                "odometry edge sigma_xy = base + per_m * distance")
        .Double("odometry_sigma_per_m", &C::odometry_sigma_per_m, "m/m",
                "growth of sigma_xy per m of edge translation")
        .Double("odometry_sigma_base_rad", &C::odometry_sigma_base_rad, "rad",
                "odometry edge sigma_theta = base + per_rad * angle + rad_per_m * distance")
        .Double("odometry_sigma_per_rad", &C::odometry_sigma_per_rad, "rad/rad",
                "growth of sigma_theta per rad of edge rotation")
        .Double("odometry_sigma_rad_per_m", &C::odometry_sigma_rad_per_m, "rad/m",
                "growth of sigma_theta per m of edge translation")
        .Double("loop_sigma_m", &C::loop_sigma_m, "m",
                "loop edge sigma at loop_reference_consensus inliers")
        .Double("loop_sigma_rad", &C::loop_sigma_rad, "rad",
                "loop edge sigma_theta at loop_reference_consensus inliers")
        .Int("loop_reference_consensus", &C::loop_reference_consensus, "",
             "loop sigmas scale with sqrt(this / consensus)")
        .Int("optimize_every_loops", &C::optimize_every_loops, "",
             "optimise the graph after every N accepted loops the estimate does not already meet")
        .Double("defer_loop_residual_sigmas", &C::defer_loop_residual_sigmas, "sigma",
                "a loop whose whitened residual at the current estimate is at most this waits "
                "for the next optimisation (0: every loop is optimised at once)")
        .Nested("graph", &C::graph, PoseGraphConfigFields())
        .Nested("loop_refinement", &C::loop_refinement, LoopRefinementConfigFields());
    return table;
  }();
  return fields;
}

}  // namespace keyplace
