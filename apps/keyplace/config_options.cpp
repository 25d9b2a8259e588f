#include "config_options.hpp"

#include <stdexcept>

namespace keyplace::cli {

std::map<std::string, std::string> ParseAssignments(const std::vector<std::string>& items) {
  std::map<std::string, std::string> values;
  for (const auto& item : items) {
    const auto equals = item.find('=');
    if (equals == std::string::npos || equals == 0 || equals + 1 == item.size()) {
      throw std::invalid_argument("--set '" + item + "': expected KEY=VALUE");
    }
    values[item.substr(0, equals)] = item.substr(equals + 1);
  }
  return values;
}

}  // namespace keyplace::cli
