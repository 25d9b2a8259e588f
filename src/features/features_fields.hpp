#pragma once
// Internal: the field table of FlirtConfig (the `features` section).

#include "common/config_fields.hpp"
#include "keyplace/features/flirt.hpp"

namespace keyplace {

const ConfigFields<FlirtConfig>& FlirtConfigFields();

}  // namespace keyplace
