#pragma once
// How a log is read and prepared under a configuration: the one place where the configuration's
// input, odometry and features sections become LogInputOptions, for every command and the Python
// module alike.

#include "keyplace/config/config.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace {

/// LogInputOptions with the bag input (input), the ICP odometry (odometry) and the keypoints
/// (features) of `config`; everything else (pose source, scan range, cache) at its default, for
/// the caller to set.
LogInputOptions LogInputOptionsFor(const Config& config);

}  // namespace keyplace
