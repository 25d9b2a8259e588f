// The field table of FlirtConfig (docs in keyplace/features/flirt.hpp).

#include "features/features_fields.hpp"

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

}  // namespace keyplace
