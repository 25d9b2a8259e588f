#pragma once
// Internal: the field tables of MappingConfig and OccupancyGridConfig (`mapping`, `grid`).

#include "common/config_fields.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"

namespace keyplace {

const ConfigFields<MappingConfig>& MappingConfigFields();
const ConfigFields<OccupancyGridConfig>& OccupancyGridConfigFields();

}  // namespace keyplace
