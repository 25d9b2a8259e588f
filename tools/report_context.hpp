#pragma once
// What the report's page builders share: the settings, the plan and what happened to each step,
// and reading the artefacts' JSON.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "report_html.hpp"
#include "report_plan.hpp"

namespace keyplace::cli {

/// What the page builder knows: settings, the plan and what happened to each step.
struct ReportContext {
  ReportSettings settings;
  std::string datasets_text;         // --datasets as given (named on the page)
  std::size_t stability_scan = 100;  // first scan of the submap drawn in Figures 6-7
  std::vector<ReportStep> steps;
  std::vector<StepOutcome> outcomes;
  std::string figures_dir;  // OUT/figures: figures drawn by the report itself
  std::vector<std::string> warnings;
};

/// The JSON file at `path`, nullopt when it does not exist; throws std::invalid_argument naming
/// the file when it is no valid JSON.
std::optional<nlohmann::json> LoadJson(const std::string& path);

/// The number `key` of `json` (read from `path`), nullopt when the file or the key is missing or
/// null; throws std::invalid_argument when the value is no number.
std::optional<double> Number(const std::optional<nlohmann::json>& json, const std::string& key,
                             const std::string& path);

/// The step that writes `output`, for "not computed: run ..." notes (HTML).
std::string HowToMake(const ReportContext& context, const std::string& output);

/// Our row of a comparison table from the JSON at `path`: `values` of the file, or, when it is
/// missing, a note saying how to make it.
using RowValues =
    std::function<std::vector<std::optional<double>>(const std::optional<nlohmann::json>&)>;
OursRow Row(const ReportContext& context, const std::string& label_html, const std::string& path,
            const RowValues& values);

}  // namespace keyplace::cli
