#pragma once
// Internal: the field tables of IcpConfig and ScanOdometryConfig (the `odometry` section).

#include "common/config_fields.hpp"
#include "keyplace/registration/icp.hpp"
#include "keyplace/registration/scan_odometry.hpp"

namespace keyplace {

const ConfigFields<IcpConfig>& IcpConfigFields();
const ConfigFields<ScanOdometryConfig>& ScanOdometryConfigFields();

}  // namespace keyplace
