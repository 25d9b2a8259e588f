#pragma once
// Internal: the one way keyplace parses YAML (configurations, map_server maps, rosbag2
// metadata.yaml). yaml-cpp alone resolves a key given twice to one of its values, ignores every
// document after the first and reports nesting beyond its limit as "bad file"; these are refused
// here with the file and line.

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace keyplace {

/// Mapping entries visited when looking for duplicate keys; aliases can make a small file expand
/// to more (each alias is visited as often as it is used), which is refused.
inline constexpr std::size_t kMaxYamlNodes = std::size_t{1} << 20;

/// The single document of `text`, named `source` in errors (std::invalid_argument
/// "SOURCE:LINE: ..."): malformed YAML, nesting deeper than yaml-cpp's limit, a second document,
/// a key given twice in one mapping, or an alias expansion beyond kMaxYamlNodes are refused. An
/// empty text is a null node.
YAML::Node LoadYamlDocument(const std::string& text, const std::string& source);

}  // namespace keyplace
