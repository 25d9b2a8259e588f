#pragma once
// Internal: the field tables of the localization configs (`localization`, `merge`, `node`).

#include "common/config_fields.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/localization/node_config.hpp"

namespace keyplace {

const ConfigFields<LocalizerConfig>& LocalizerConfigFields();
const ConfigFields<MergeOptions>& MergeOptionsFields();
const ConfigFields<NodeConfig>& NodeConfigFields();

}  // namespace keyplace
