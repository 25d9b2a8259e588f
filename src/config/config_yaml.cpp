// The configuration as YAML (yaml-cpp reads it; we write it ourselves so that every field keeps
// its comment and the table's order).

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <ostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/bounded_read.hpp"
#include "io/yaml_document.hpp"
#include "keyplace/config/config.hpp"
#include "keyplace/config/essential_settings.hpp"

namespace keyplace {
namespace {

std::vector<std::string> SplitKey(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t dot = key.find('.'); dot != std::string::npos; dot = key.find('.', start)) {
    parts.push_back(key.substr(start, dot - start));
    start = dot + 1;
  }
  parts.push_back(key.substr(start));
  return parts;
}

// A value as a YAML scalar: plain when it reads back as the same text (numbers, names, topics),
// double-quoted otherwise (an empty text field would read back as nothing).
std::string YamlScalar(const std::string& value) {
  const bool plain = !value.empty() && value.front() != '-' &&
                     value.find_first_not_of(
                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                         "0123456789_./,+") == std::string::npos;
  const bool number =
      !value.empty() && value.find_first_not_of("0123456789.-+eE,") == std::string::npos;
  if (plain || (number && value.find(',') == std::string::npos)) return value;
  std::string quoted = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string Comment(const ConfigFieldInfo& field) {
  std::string text = field.unit.empty() ? "" : "[" + field.unit + "] ";
  return text + field.doc;
}

// Whether `key` names a section ("place", "place.ransac"), i.e. a mapping may stand there. A
// mapping anywhere else is refused at once: through an alias to itself (`place: &a {x: *a}`) a
// mapping nests without end.
bool IsSection(const std::string& key) {
  static const std::set<std::string> sections = [] {
    std::set<std::string> names;
    for (const auto& field : ConfigKeyValues(Config{})) {
      for (std::size_t dot = field.first.find('.'); dot != std::string::npos;
           dot = field.first.find('.', dot + 1)) {
        names.insert(field.first.substr(0, dot));
      }
    }
    return names;
  }();
  return sections.count(key) > 0;
}

const char* KindOf(const YAML::Node& node) {
  if (node.IsMap()) return "a mapping";
  if (node.IsSequence()) return "a list";
  return node.IsNull() ? "nothing" : "a value";
}

void ApplyNode(const YAML::Node& node, const std::string& prefix, const std::string& source,
               ConfigBuilder& config) {
  const auto where = [&](const YAML::Node& at) {
    return source + ":" + std::to_string(at.Mark().line + 1) + ": ";
  };
  if (!node.IsMap()) {
    throw std::invalid_argument(where(node) + (prefix.empty() ? "the configuration" : prefix) +
                                ": expected a mapping of keys");
  }
  for (const auto& entry : node) {
    if (!entry.first.IsScalar()) {
      throw std::invalid_argument(where(entry.first) +
                                  (prefix.empty() ? "the configuration" : prefix) +
                                  ": a key must be a name, found " + KindOf(entry.first));
    }
    const std::string key = (prefix.empty() ? "" : prefix + ".") + entry.first.Scalar();
    const YAML::Node& value = entry.second;
    if (value.IsMap()) {
      if (!IsSection(key)) {
        throw std::invalid_argument(where(entry.first) + key +
                                    ": expected a value, found a mapping (not a section of "
                                    "keyplace dump-config)");
      }
      ApplyNode(value, key, source, config);
    } else if (value.IsScalar()) {
      config.Set(key, value.Scalar(), source + ":" + std::to_string(entry.first.Mark().line + 1));
    } else {
      throw std::invalid_argument(where(entry.first) + key + ": expected a value, found " +
                                  KindOf(value));
    }
  }
}

}  // namespace

namespace {

// The fields as YAML, nested sections as nested mappings, each with its unit and doc.
void WriteYamlFields(const std::vector<ConfigFieldInfo>& fields, std::ostream& out) {
  std::vector<std::string> open;  // path of the mapping being written
  for (const ConfigFieldInfo& field : fields) {
    std::vector<std::string> parts = SplitKey(field.key);
    const std::string name = parts.back();
    parts.pop_back();
    std::size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) {
      ++common;
    }
    open.resize(common);
    for (std::size_t depth = common; depth < parts.size(); ++depth) {
      if (depth == 0) out << '\n';
      out << std::string(2 * depth, ' ') << parts[depth] << ":\n";
      open.push_back(parts[depth]);
    }
    out << std::string(2 * parts.size(), ' ') << name << ": " << YamlScalar(field.value) << "  # "
        << Comment(field) << '\n';
  }
}

}  // namespace

std::string ConfigToYaml(const Config& config) {
  std::ostringstream out;
  out << "# keyplace configuration: every field with [unit] and meaning.\n"
         "# Use with --config FILE.yaml; override one field with --set section.key=value.\n";
  WriteYamlFields(DescribeConfig(config), out);
  return out.str();
}

std::string EssentialConfigToYaml(const Config& config) {
  std::vector<ConfigFieldInfo> shown;
  std::size_t left_out = 0;
  for (ConfigFieldInfo& field : DescribeConfig(config)) {
    if (IsEssentialConfigKey(field.key) || field.value != field.default_value) {
      shown.push_back(std::move(field));
    } else {
      ++left_out;
    }
  }
  std::ostringstream out;
  out << "# keyplace configuration: the essential settings and those that differ from the\n"
         "# defaults, each with [unit] and meaning. Use with --config FILE.yaml; override one\n"
         "# field with --set section.key=value.\n";
  WriteYamlFields(shown, out);
  out << "\n# " << left_out
      << " more settings at their defaults: keyplace dump-config --all shows every one.\n";
  return out.str();
}

ConfigBuilder& ConfigBuilder::Yaml(const std::string& yaml, const std::string& source) {
  const YAML::Node root = LoadYamlDocument(yaml, source);
  if (!root.IsNull()) ApplyNode(root, "", source, *this);  // an empty file changes nothing
  return *this;
}

ConfigBuilder& ConfigBuilder::File(const std::string& path) {
  return Yaml(ReadWholeFile(path, kMaxConfigFileBytes, "configuration file"), path);
}

void ApplyConfigYaml(const std::string& yaml, const std::string& source, Config& config) {
  config = ConfigBuilder(config).Yaml(yaml, source).Build();
}

void ApplyConfigFile(const std::string& path, Config& config) {
  config = ConfigBuilder(config).File(path).Build();
}

}  // namespace keyplace
