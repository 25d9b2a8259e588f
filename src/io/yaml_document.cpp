#include "io/yaml_document.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <set>
#include <sstream>
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

// Where a document's content starts (its first node), the only thing the document count needs.
// yaml-cpp's LoadAll loops without end on some malformed input (" ,a,[ ,\xe8cel": every call of
// the parser returns one more empty document at the same place, until memory runs out; found by
// the config_yaml fuzzer), so documents are counted here, two at most, and a document that
// starts where the previous one did is malformed input.
class DocumentStart : public YAML::EventHandler {
 public:
  const YAML::Mark& mark() const { return mark_; }
  void OnDocumentStart(const YAML::Mark& mark) override { Content(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { Content(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { Content(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                const std::string& /*value*/) override {
    Content(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& /*tag*/,
                       YAML::anchor_t /*anchor*/, YAML::EmitterStyle::value /*style*/) override {
    Content(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                  YAML::EmitterStyle::value /*style*/) override {
    Content(mark);
  }
  void OnMapEnd() override {}

 private:
  // The document start's mark until the first node's replaces it.
  void Content(const YAML::Mark& mark) {
    if (events_++ < 2) mark_ = mark;
  }
  YAML::Mark mark_;
  int events_ = 0;
};

}  // namespace

YAML::Node LoadYamlDocument(const std::string& text, const std::string& source) {
  YAML::Node document;
  try {
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    DocumentStart first;
    if (!parser.HandleNextDocument(first)) return YAML::Node();  // nothing but comments
    DocumentStart second;
    if (parser.HandleNextDocument(second)) {
      if (second.mark().pos <= first.mark().pos) {
        throw std::invalid_argument(Where(source, second.mark()) +
                                    "malformed YAML: the parser makes no progress from here");
      }
      throw std::invalid_argument(Where(source, second.mark()) +
                                  "a second YAML document (after '---'); the file must hold one");
    }
    document = YAML::Load(text);
  } catch (const YAML::DeepRecursion& error) {
    throw std::invalid_argument(Where(source, error.mark) +
                                "YAML nested too deeply (yaml-cpp stops at " +
                                std::to_string(error.depth()) + " levels)");
  } catch (const YAML::Exception& error) {
    throw std::invalid_argument(Where(source, error.mark) + "malformed YAML: " + error.msg);
  }
  std::size_t visited = 0;
  CheckKeys(document, source, visited, 0);
  return document;
}

}  // namespace keyplace
