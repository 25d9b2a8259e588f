#include "sweep_figures.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "plot_chart.hpp"

namespace keyplace::cli {
namespace {

nlohmann::json ReadResults(const std::string& path, const std::string& kind) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot open");
  nlohmann::json json;
  try {
    in >> json;
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(path + ": not valid JSON: " + error.what());
  }
  if (!json.contains("sweep") || !json["sweep"].contains("sweep") ||
      json["sweep"]["sweep"] != kind) {
    throw std::invalid_argument(path + ": field 'sweep.sweep' is not \"" + kind +
                                "\": not the results of keyplace sweep " + kind);
  }
  if (!json.contains("rows") || !json["rows"].is_array()) {
    throw std::invalid_argument(path + ": no 'rows' array");
  }
  return json;
}

double Field(const nlohmann::json& row, const std::string& name, const std::string& path,
             std::size_t index) {
  if (!row.contains(name) || !row[name].is_number()) {
    throw std::invalid_argument(fmt::format("{}: rows[{}] has no number '{}'", path, index, name));
  }
  return row[name].get<double>();
}

// One series per value of `line_field`, x = `x_field`, y = `y_field`, over the selected rows.
std::vector<ChartSeries> Series(const nlohmann::json& rows, const std::vector<std::size_t>& pick,
                                const std::string& line_field, const std::string& line_label,
                                const std::string& x_field, const std::string& y_field,
                                const std::string& path, double y_scale = 1.0,
                                const std::string& undefined_when_zero = "") {
  std::map<double, std::vector<std::pair<double, double>>> lines;
  for (const std::size_t i : pick) {
    const nlohmann::json& row = rows[i];
    const bool undefined =
        !undefined_when_zero.empty() && Field(row, undefined_when_zero, path, i) == 0.0;
    lines[Field(row, line_field, path, i)].emplace_back(
        Field(row, x_field, path, i),
        undefined ? std::nan("") : y_scale * Field(row, y_field, path, i));
  }
  std::vector<ChartSeries> series;
  for (auto& [value, points] : lines) {
    std::sort(points.begin(), points.end());
    ChartSeries s;
    s.label = fmt::format("{} = {:g}", line_label, value);
    for (const auto& [x, y] : points) {
      s.x.push_back(x);
      s.y.push_back(y);
    }
    series.push_back(std::move(s));
  }
  return series;
}

}  // namespace

void DrawFigure8(const std::string& results_json, const std::string& png_path,
                 const std::string& title) {
  const nlohmann::json json = ReadResults(results_json, "mapping");
  const nlohmann::json& rows = json["rows"];
  std::vector<std::size_t> all(rows.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  struct Criterion {
    const char* field;
    const char* title;
    const char* y_label;
    double scale;
  };
  const Criterion criteria[] = {
      {"compression", "Compression ratio", "stable / all keypoints", 1.0},
      {"scans_per_submap", "Scans per submap", "scans", 1.0},
      {"keypoints_per_submap", "Keypoints per submap", "stable keypoints", 1.0},
      {"distribution", "Spatial distribution distance", "mean delta", 1.0},
      {"submaps", "Submaps in the global map", "submaps", 1.0},
      {"seconds_per_submap", "Time per submap (mapping only)", "ms", 1000.0},
  };
  std::vector<Chart> charts;
  for (const Criterion& c : criteria) {
    Chart chart;
    chart.title = c.title;
    chart.x_label = "s_min";
    chart.y_label = c.y_label;
    chart.series = Series(rows, all, "l_g", "l_g", "s_min", c.field, results_json, c.scale);
    for (ChartSeries& s : chart.series) s.label += " m";
    charts.push_back(std::move(chart));
  }
  DrawCharts(png_path, title, charts, 3);
}

void DrawFigure9(const std::string& results_json, const std::string& png_path,
                 const std::string& title) {
  const nlohmann::json json = ReadResults(results_json, "place");
  const nlohmann::json& rows = json["rows"];
  if (rows.empty()) throw std::invalid_argument(results_json + ": 'rows' is empty");
  // The first (s_min, l_g, lambda) in the file; the paper's figure has one lambda.
  const double s_min = Field(rows[0], "s_min", results_json, 0);
  const double l_g = Field(rows[0], "l_g", results_json, 0);
  const double lambda = Field(rows[0], "lambda", results_json, 0);
  std::vector<std::size_t> pick;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (Field(rows[i], "s_min", results_json, i) == s_min &&
        Field(rows[i], "l_g", results_json, i) == l_g &&
        Field(rows[i], "lambda", results_json, i) == lambda) {
      pick.push_back(i);
    }
  }
  const std::string setting =
      fmt::format("lambda = {:g} m, s_min = {:g}, l_g = {:g} m", lambda, s_min, l_g);
  Chart precision{"Precision", "gamma_min", "precision", {}, 0.0, 1.0};
  // Precision is undefined where nothing was accepted (n_acc = 0): no point there.
  precision.series =
      Series(rows, pick, "mu", "mu", "gamma_min", "precision", results_json, 1.0, "n_acc");
  Chart recall{"Recall", "gamma_min", "recall", {}, 0.0, 1.0};
  recall.series = Series(rows, pick, "mu", "mu", "gamma_min", "recall", results_json);
  DrawCharts(png_path, title + " (" + setting + ")", {precision, recall}, 2);
}

}  // namespace keyplace::cli
