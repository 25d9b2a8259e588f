#pragma once
// Internal: the field tables of PlaceRecognitionConfig and its RANSAC (the `place` section).

#include "common/config_fields.hpp"
#include "keyplace/place/place_config.hpp"

namespace keyplace {

const ConfigFields<RansacConfig>& RansacConfigFields();
const ConfigFields<PlaceRecognitionConfig>& PlaceConfigFields();

}  // namespace keyplace
