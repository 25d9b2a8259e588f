#pragma once
// Internal: the field tables of SlamConfig and its pose graph and loop refinement.

#include "common/config_fields.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

const ConfigFields<PoseGraphConfig>& PoseGraphConfigFields();
const ConfigFields<LoopRefinementConfig>& LoopRefinementConfigFields();
// SlamConfig's own fields and its graph / loop refinement; its odometry, mapping and place
// sections are the top-level ones (Config::ToSlamConfig).
const ConfigFields<SlamConfig>& SlamConfigFields();

}  // namespace keyplace
