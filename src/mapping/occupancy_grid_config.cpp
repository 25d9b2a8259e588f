#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/config_fields.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
#include "mapping/mapping_fields.hpp"

namespace keyplace {

void Validate(const OccupancyGridConfig& config) {
  const auto fail = [](const std::string& message) {
    throw std::invalid_argument("OccupancyGridConfig." + message);
  };
  if (!(config.resolution_m >= 0.001 && config.resolution_m <= 10.0)) {
    fail("resolution_m must be in [0.001, 10] m");
  }
  const auto probability = [&](double value, const char* name) {
    if (!(value > 0.0 && value < 1.0)) fail(std::string(name) + " must be in (0, 1)");
  };
  probability(config.hit_probability, "hit_probability");
  probability(config.miss_probability, "miss_probability");
  probability(config.min_probability, "min_probability");
  probability(config.max_probability, "max_probability");
  probability(config.occupied_thresh, "occupied_thresh");
  probability(config.free_thresh, "free_thresh");
  if (!(config.hit_probability > 0.5)) fail("hit_probability must be above 0.5");
  if (!(config.miss_probability < 0.5)) fail("miss_probability must be below 0.5");
  if (!(config.min_probability < config.max_probability)) {
    fail("min_probability must be below max_probability");
  }
  if (!(config.free_thresh < config.occupied_thresh)) {
    fail("free_thresh must be below occupied_thresh");
  }
  if (!(config.max_trace_range_m > 0.0 && std::isfinite(config.max_trace_range_m))) {
    fail("max_trace_range_m must be positive and finite");
  }
  if (config.max_cells < 1 || config.max_cells > (std::int64_t{1} << 30)) {
    fail("max_cells must be in [1, 2^30]");
  }
}

const ConfigFields<OccupancyGridConfig>& OccupancyGridConfigFields() {
  using C = OccupancyGridConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("OccupancyGridConfig");
    table.Double("resolution_m", &C::resolution_m, "m", "side of a cell of the exported grid")
        .Double("hit_probability", &C::hit_probability, "",
                "occupancy a beam's endpoint gives its cell (log-odds update)")
        .Double("miss_probability", &C::miss_probability, "",
                "occupancy a crossed cell gets (log-odds update)")
        .Double("min_probability", &C::min_probability, "", "log-odds clamped below at this")
        .Double("max_probability", &C::max_probability, "", "log-odds clamped above at this")
        .Double("occupied_thresh", &C::occupied_thresh, "",
                "a cell at or above this probability is occupied in the image")
        .Double("free_thresh", &C::free_thresh, "", "a cell at or below this is free in the image")
        .Double("max_trace_range_m", &C::max_trace_range_m, "m",
                "beams are traced this far at most")
        .Int("max_cells", &C::max_cells, "", "a larger grid is an error (raise resolution_m)");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
