#include "io/yaml_document.hpp"

#include <yaml-cpp/depthguard.h>

#include <set>
#include <stdexcept>
#include <vector>

#include "common/shown_text.hpp"

namespace keyplace {
namespace {

constexpr std::size_t kMaxYamlCheckDepth = 64;

std::string Where(const std::string& source, const YAML::Mark& mark) {
  return source + ":" + std::to_string(mark.line + 1) + ": ";
}

// Refuses a mapping that has the same scalar key twice under `node`, down to kMaxYamlCheckDepth
// levels: deeper than anything keyplace reads, and an alias of a mapping inside itself nests
// without end (its readers refuse that where they meet it, naming the key).
void CheckKeys(const YAML::Node& node, const std::string& source, std::size_t& visited,
               std::size_t depth) {
  if (depth > kMaxYamlCheckDepth) return;
  if (++visited > kMaxYamlNodes) {
    throw std::invalid_argument(Where(source, node.Mark()) + "more than " +
                                std::to_string(kMaxYamlNodes) +
                                " nodes once aliases are expanded (an alias bomb?)");
  }
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) CheckKeys(item, source, visited, depth + 1);
    return;
  }
  if (!node.IsMap()) return;
  std::set<std::string> keys;
  for (const auto& entry : node) {
    if (entry.first.IsScalar() && !keys.insert(entry.first.Scalar()).second) {
      throw std::invalid_argument(Where(source, entry.first.Mark()) + "the key '" +
                                  ShownText(entry.first.Scalar()) +
                                  "' is given twice in one mapping (YAML allows one)");
    }
    CheckKeys(entry.first, source, visited, depth + 1);
    CheckKeys(entry.second, source, visited, depth + 1);
  }
}

}  // namespace

YAML::Node LoadYamlDocument(const std::string& text, const std::string& source) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::DeepRecursion& error) {
    throw std::invalid_argument(Where(source, error.mark) +
                                "YAML nested too deeply (yaml-cpp stops at " +
                                std::to_string(error.depth()) + " levels)");
  } catch (const YAML::Exception& error) {
    throw std::invalid_argument(Where(source, error.mark) + "malformed YAML: " + error.msg);
  }
  if (documents.empty()) return YAML::Node();
  if (documents.size() > 1) {
    throw std::invalid_argument(Where(source, documents[1].Mark()) +
                                "a second YAML document (after '---'); the file must hold one");
  }
  std::size_t visited = 0;
  CheckKeys(documents[0], source, visited, 0);
  return documents[0];
}

}  // namespace keyplace
