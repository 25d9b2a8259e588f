#pragma once
// The essential settings: the few a user changes for a robot and a building (sensor range, bag
// topics and frames, submap size, how sure a fix must be, the node's outputs). `keyplace
// dump-config` shows them and every setting that differs from the defaults; `--all` shows all.

#include <string>
#include <vector>

#include "keyplace/config/config.hpp"

namespace keyplace {

/// The essential keys ("section.key"), in the order of the configuration's field table.
const std::vector<std::string>& EssentialConfigKeys();

/// True for a key of EssentialConfigKeys().
bool IsEssentialConfigKey(const std::string& key);

/// ConfigToYaml restricted to the essential settings and those whose value differs from
/// Config{}'s: applied to the defaults (as `--config` does under the default preset) it gives
/// `config` back. A comment at its end counts the settings left out.
std::string EssentialConfigToYaml(const Config& config);

}  // namespace keyplace
