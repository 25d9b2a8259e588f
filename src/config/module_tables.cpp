// Field tables of the feature, registration and SLAM configs (docs in their headers).

#include "config/section_tables.hpp"

namespace keyplace {

const ConfigFields<FlirtConfig>& FlirtConfigFields() {
  using C = FlirtConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("FlirtConfig");
    table.Int("num_scales", &C::num_scales, "", "number of smoothing scales")
        .Double("base_sigma_m", &C::base_sigma_m, "m", "sigma of scale 0")
        .Double("sigma_step", &C::sigma_step, "", "sigma_l = base_sigma_m * sigma_step^l")
        .Int("dmst", &C::dmst, "", "the geodesic graph is the union of dmst + 1 spanning trees")
        .Double("min_peak", &C::min_peak, "", "a peak needs a signal above this")
        .Double("min_peak_difference", &C::min_peak_difference, "",
                "... and above each neighbour's by this")
        .Double("duplicate_box_m", &C::duplicate_box_m, "m",
                "a keypoint this close (both axes) to an accepted one is dropped")
        .Double("kernel_cutoff_sigmas", &C::kernel_cutoff_sigmas, "",
                "smoothing ignores geodesic neighbours beyond this many sigmas")
        .Double("descriptor_min_rho_m", &C::descriptor_min_rho_m, "m",
                "inner radius of the innermost descriptor ring")
        .Double("descriptor_max_rho_m", &C::descriptor_max_rho_m, "m",
                "outer radius of the outermost descriptor ring")
        .Double("descriptor_radial_border_m", &C::descriptor_radial_border_m, "m",
                "descriptor rings overlap by this much")
        .Double("descriptor_angular_border_rad", &C::descriptor_angular_border_rad, "rad",
                "descriptor sectors overlap by this much");
    return table;
  }();
  return fields;
}

const ConfigFields<IcpConfig>& IcpConfigFields() {
  using C = IcpConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("IcpConfig");
    table
        .Double("max_correspondence_distance_m", &C::max_correspondence_distance_m, "m",
                "a source point pairs with its nearest target point within this")
        .Double("inlier_distance_m", &C::inlier_distance_m, "m",
                "point-to-line distance of an inlier (inlier ratio, residual)")
        .Enum("kernel", &C::kernel,
              {{RobustKernel::kNone, "none"},
               {RobustKernel::kHuber, "huber"},
               {RobustKernel::kCauchy, "cauchy"},
               {RobustKernel::kTukey, "tukey"}},
              "robust kernel on the point-to-line residual")
        .Double("kernel_scale_m", &C::kernel_scale_m, "m", "scale of the robust kernel")
        .Int("normal_neighbours", &C::normal_neighbours, "",
             "neighbours fitting the line through each target point")
        .Double("normal_max_neighbour_distance_m", &C::normal_max_neighbour_distance_m, "m",
                "neighbours farther than this are ignored for a normal")
        .Double("normal_max_eigenvalue_ratio", &C::normal_max_eigenvalue_ratio, "",
                "a normal is used when the neighbourhood is this line-like (0..1)")
        .Int("max_iterations", &C::max_iterations, "", "Gauss-Newton iterations")
        .Double("convergence_translation_m", &C::convergence_translation_m, "m",
                "converged when an increment moves less than this ...")
        .Double("convergence_rotation_rad", &C::convergence_rotation_rad, "rad",
                "... and turns less than this")
        .Double("degeneracy_min_eigenvalue", &C::degeneracy_min_eigenvalue, "",
                "weaker information directions are held at the guess (0 = off)")
        .Int("min_points", &C::min_points, "", "fewer source or target points: no alignment")
        .Int("min_inliers", &C::min_inliers, "", "converged only with this many inliers ...")
        .Double("min_inlier_ratio", &C::min_inlier_ratio, "", "... and this inlier ratio");
    return table;
  }();
  return fields;
}

const ConfigFields<ScanOdometryConfig>& ScanOdometryConfigFields() {
  using C = ScanOdometryConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("ScanOdometryConfig");
    table.Double("min_range_m", &C::min_range_m, "m", "shortest beam used")
        .Double("max_range_m", &C::max_range_m, "m", "beams at or beyond this are not used")
        .Double("source_min_spacing_m", &C::source_min_spacing_m, "m",
                "registered scan: skip points closer than this to the previous kept one")
        .Int("local_map_scans", &C::local_map_scans, "", "key scans in the local map")
        .Double("keyframe_translation_m", &C::keyframe_translation_m, "m",
                "a scan becomes a key scan after moving this far ...")
        .Double("keyframe_rotation_rad", &C::keyframe_rotation_rad, "rad",
                "... or turning this much")
        .Double("max_correction_translation_m", &C::max_correction_translation_m, "m",
                "ICP results further than this from the odometry prediction are rejected (unless "
                "recovered) ...")
        .Double("max_correction_rotation_rad", &C::max_correction_rotation_rad, "rad",
                "... or turned more than this")
        .Bool("recovery_search", &C::recovery_search,
              "a failed or rejected ICP retries from the best pose of a correlative search; a "
              "rejected one is taken when the previous step repeated confirms it against the "
              "odometry")
        .Double("recovery_window_translation_m", &C::recovery_window_translation_m, "m",
                "the search covers this much translation around the prediction ...")
        .Double("recovery_window_rotation_rad", &C::recovery_window_rotation_rad, "rad",
                "... and this much rotation")
        .Double("recovery_step_translation_m", &C::recovery_step_translation_m, "m",
                "translation step of the search")
        .Double("recovery_step_rotation_rad", &C::recovery_step_rotation_rad, "rad",
                "rotation step of the search")
        .Nested("icp", &C::icp, IcpConfigFields());
    return table;
  }();
  return fields;
}

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
             "optimise the graph after every N accepted loops")
        .Nested("graph", &C::graph, PoseGraphConfigFields())
        .Nested("loop_refinement", &C::loop_refinement, LoopRefinementConfigFields());
    return table;
  }();
  return fields;
}

}  // namespace keyplace
