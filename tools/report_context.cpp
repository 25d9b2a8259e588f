#include "report_context.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace keyplace::cli {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::optional<Json> LoadJson(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::nullopt;
  std::ifstream in(path);
  Json json;
  try {
    in >> json;
  } catch (const Json::exception& e) {
    throw std::invalid_argument(path + ": not valid JSON: " + e.what());
  }
  return json;
}

std::optional<double> Number(const std::optional<Json>& json, const std::string& key,
                             const std::string& path) {
  if (!json) return std::nullopt;
  if (!json->contains(key)) return std::nullopt;
  const Json& value = (*json)[key];
  if (value.is_null()) return std::nullopt;
  if (!value.is_number()) throw std::invalid_argument(path + ": field '" + key + "' is no number");
  return value.get<double>();
}

// The step that writes `output`, for "not computed: run ..." notes.
std::string HowToMake(const ReportContext& context, const std::string& output) {
  for (std::size_t k = 0; k < context.steps.size(); ++k) {
    const ReportStep& step = context.steps[k];
    for (const std::string& o : step.outputs) {
      if (o != output) continue;
      std::string note = "run <code>" + HtmlEscape(CommandLine(step)) + "</code>";
      if (k < context.outcomes.size() && !context.outcomes[k].message.empty()) {
        note += " (" + HtmlEscape(context.outcomes[k].message) + ")";
      }
      return note;
    }
  }
  return HtmlEscape(output) + " is missing";
}

OursRow Row(const ReportContext& context, const std::string& label_html, const std::string& path,
            const RowValues& values) {
  const std::optional<Json> json = LoadJson(path);
  OursRow row;
  row.label_html = label_html;
  if (!json) {
    row.missing_html = HowToMake(context, path);
  } else {
    row.values = values(json);
  }
  return row;
}

}  // namespace keyplace::cli
