#pragma once
// Internal: the field table of BagInputConfig (the `input` section).

#include "common/config_fields.hpp"
#include "keyplace/io/bag_input_config.hpp"

namespace keyplace {

const ConfigFields<BagInputConfig>& BagInputConfigFields();

}  // namespace keyplace
