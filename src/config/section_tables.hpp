#pragma once
// Internal: the field table of every config struct, each defined beside its struct's Validate
// (src/<module>/..._config.cpp), composed into the whole configuration in config.cpp.

#include "common/config_fields.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "keyplace/localization/node_config.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/registration/icp.hpp"
#include "keyplace/registration/scan_odometry.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

const ConfigFields<FlirtConfig>& FlirtConfigFields();
const ConfigFields<IcpConfig>& IcpConfigFields();
const ConfigFields<ScanOdometryConfig>& ScanOdometryConfigFields();
const ConfigFields<MappingConfig>& MappingConfigFields();
const ConfigFields<RansacConfig>& RansacConfigFields();
const ConfigFields<PlaceRecognitionConfig>& PlaceConfigFields();
const ConfigFields<PoseGraphConfig>& PoseGraphConfigFields();
const ConfigFields<LoopRefinementConfig>& LoopRefinementConfigFields();
// SlamConfig's own fields and its graph / loop refinement; its odometry, mapping and place
// sections are the top-level ones (Config::ToSlamConfig).
const ConfigFields<SlamConfig>& SlamConfigFields();
const ConfigFields<LocalizerConfig>& LocalizerConfigFields();
const ConfigFields<EvaluationConfig>& EvaluationConfigFields();
const ConfigFields<OccupancyGridConfig>& OccupancyGridConfigFields();
const ConfigFields<MergeOptions>& MergeOptionsFields();
const ConfigFields<BagInputConfig>& BagInputConfigFields();
const ConfigFields<NodeConfig>& NodeConfigFields();

}  // namespace keyplace
