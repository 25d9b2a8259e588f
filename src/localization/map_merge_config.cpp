#include <cmath>
#include <stdexcept>

#include "common/config_fields.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "localization/localization_fields.hpp"

namespace keyplace {

void Validate(const MergeOptions& options) {
  if (options.min_agreeing < 1) {
    throw std::invalid_argument("MergeOptions.min_agreeing must be >= 1");
  }
  if (!(options.agree_m > 0.0 && std::isfinite(options.agree_m)) ||
      !(options.agree_deg > 0.0 && options.agree_deg <= 180.0)) {
    throw std::invalid_argument(
        "MergeOptions.agree_m must be positive and finite, agree_deg in (0, 180]");
  }
}

const ConfigFields<MergeOptions>& MergeOptionsFields() {
  using C = MergeOptions;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("MergeOptions");
    table
        .Int("min_agreeing", &C::min_agreeing, "",
             "merge: submaps of B recognised in A that must agree on where B lies")
        .Double("agree_m", &C::agree_m, "m",
                "two recognitions agree when they put a B submap origin this close ...")
        .Double("agree_deg", &C::agree_deg, "deg", "... and this close in heading");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
