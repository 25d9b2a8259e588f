// The field tables of the registration configs (docs in their headers).

#include "registration/registration_fields.hpp"

namespace keyplace {

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
              "odometry, and an accepted one is retried from that step when the odometry's total "
              "says its last step caught up; a failed one is retried from that total first when "
              "both it and the previous step part from the odometry's last step")
        .Double("recovery_window_translation_m", &C::recovery_window_translation_m, "m",
                "the search covers this much translation around the prediction ...")
        .Double("recovery_window_rotation_rad", &C::recovery_window_rotation_rad, "rad",
                "... and this much rotation")
        .Double("recovery_step_translation_m", &C::recovery_step_translation_m, "m",
                "translation step of the search")
        .Double("recovery_step_rotation_rad", &C::recovery_step_rotation_rad, "rad",
                "rotation step of the search")
        .Bool("grid_refinement", &C::grid_refinement,
              "refine key scans on a probability grid of the last 90, and take a recovery only "
              "where it "
              "fits that grid better")
        .Nested("icp", &C::icp, IcpConfigFields());
    return table;
  }();
  return fields;
}

}  // namespace keyplace
