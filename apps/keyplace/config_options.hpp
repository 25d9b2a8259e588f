#pragma once
// Command-line overrides of config structs: repeated --set KEY=VALUE.

#include <map>
#include <string>
#include <vector>

namespace keyplace::cli {

/// Splits "key=value" items; throws std::invalid_argument naming a malformed item.
std::map<std::string, std::string> ParseAssignments(const std::vector<std::string>& items);

}  // namespace keyplace::cli
