#include "report_map_size.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "plot_chart.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;
using A = ReportArtefacts;

const char* const kRetrievals[] = {"exact", "words"};

// The other data sets' corrected maps: copies of real submaps of other buildings, so that an
// answer from one is a wrong place (docs/BENCHMARKS.md, "Map size").
std::vector<std::string> DistractorMaps(const ReportSettings& settings) {
  std::vector<std::string> maps;
  for (const std::string& base : settings.datasets) {
    if (base != "fr079") maps.push_back(A::Map(settings, base));
  }
  return maps;
}

bool HasFr079(const ReportSettings& settings) {
  for (const std::string& base : settings.datasets) {
    if (base == "fr079") return true;
  }
  return false;
}

std::string Cell(const std::optional<double>& value, const char* format) {
  return value ? fmt::format(fmt::runtime(format), *value) : "–";
}

struct SizeRow {
  int submaps = 0;
  std::string retrieval;
  std::string path;
  std::optional<nlohmann::json> json;
};

// Query time (ms, log10) and recall against log10 of the submaps, one line per retrieval.
void DrawMapSizeFigure(const std::vector<SizeRow>& rows, const std::string& png) {
  Chart time{"Query time", "log10 submaps", "log10 ms per query (one core)", {}, {}, {}};
  Chart recall{"Recall", "log10 submaps", "recall", {}, 0.0, 1.0};
  for (const char* retrieval : kRetrievals) {
    ChartSeries t{retrieval, {}, {}};
    ChartSeries r{retrieval, {}, {}};
    for (const SizeRow& row : rows) {
      if (row.retrieval != retrieval || !row.json) continue;
      const std::optional<double> seconds = Number(row.json, "seconds_per_query_mean", row.path);
      const std::optional<double> row_recall = Number(row.json, "recall", row.path);
      const double x = std::log10(static_cast<double>(row.submaps));
      t.x.push_back(x);
      t.y.push_back(seconds && *seconds > 0.0 ? std::log10(1e3 * *seconds)
                                              : std::numeric_limits<double>::quiet_NaN());
      r.x.push_back(x);
      r.y.push_back(row_recall.value_or(std::numeric_limits<double>::quiet_NaN()));
    }
    time.series.push_back(std::move(t));
    recall.series.push_back(std::move(r));
  }
  DrawCharts(png, "FR079 among distractor submaps", {time, recall}, 2);
}

}  // namespace

std::string MapSizeJson(const ReportSettings& settings, const std::string& retrieval, int submaps) {
  return (fs::path(settings.work_dir) /
          fmt::format("map-size/fr079-{}-{}.json", retrieval, submaps))
      .string();
}

std::vector<int> MapSizes(const ReportSettings& settings) {
  if (settings.quick) return {1000};
  return {1000, 10000, 100000};
}

std::vector<ReportStep> PlanMapSizeSteps(const ReportSettings& s) {
  const std::vector<std::string> distractors = DistractorMaps(s);
  if (!HasFr079(s) || distractors.empty()) return {};
  std::string distractor_list;
  for (const std::string& map : distractors) {
    distractor_list += (distractor_list.empty() ? "" : ",") + map;
  }
  const DatasetFiles f = FilesOf(s, "fr079");
  std::vector<std::string> needs{A::Map(s, "fr079"), f.corrected_log};
  needs.insert(needs.end(), distractors.begin(), distractors.end());
  std::vector<ReportStep> steps;
  for (const int submaps : MapSizes(s)) {
    for (const char* retrieval : kRetrievals) {
      const std::string json = MapSizeJson(s, retrieval, submaps);
      // One thread: the query time is per core.
      steps.push_back(
          {fmt::format("map-size-{}-{}", retrieval, submaps),
           fmt::format("Map size, FR079 among {} submaps, retrieval {}", submaps, retrieval),
           {"localize", "--map", A::Map(s, "fr079"), "--log", f.corrected_log, "--distractors",
            distractor_list, "--distractor-submaps", std::to_string(submaps), "--n-pos",
            s.quick ? "5" : "20", "--threads", "1", "--cache", A::PreparationCache(s), "--set",
            std::string("place.retrieval=") + retrieval, "--json", json},
           needs,
           {json}});
    }
  }
  return steps;
}

std::string MapSizeSection(ReportContext& context) {
  std::string html =
      "<h2 id=\"map-size\">Map size: FR079 among distractor submaps (not in the paper)</h2>\n"
      "<p>The FR079 map among copies of the other buildings' submaps, moved far away, up to the "
      "number of submaps given (an answer from a copy is a wrong place); <code>keyplace "
      "localize</code> on one thread, the exact path (every place paired) against retrieval "
      "(<code>place.retrieval=words</code>: a bag of words over the descriptors ranks the places "
      "and only the best 50 are paired and verified). Preparation: loading, embedding the "
      "distractors and building the recognizer. Memory per submap: docs/BENCHMARKS.md, \"Map "
      "size\".</p>\n";
  if (!HasFr079(context.settings) || DistractorMaps(context.settings).empty()) {
    return html + MissingHtml("needs FR079 and at least one other data set in --datasets");
  }
  std::vector<SizeRow> rows;
  html +=
      "<table><tr><th>submaps</th><th>retrieval</th><th>ms per query</th><th>exact / words</th>"
      "<th>precision</th><th>recall</th><th>preparation (s)</th></tr>\n";
  for (const int submaps : MapSizes(context.settings)) {
    std::optional<double> exact_seconds;
    for (const char* retrieval : kRetrievals) {
      SizeRow row{submaps, retrieval, MapSizeJson(context.settings, retrieval, submaps), {}};
      row.json = LoadJson(row.path);
      if (!row.json) {
        html += fmt::format(
            "<tr><td>{}</td><td>{}</td><td colspan=\"5\" class=\"missing\">not computed: "
            "{}</td></tr>\n",
            submaps, retrieval, HowToMake(context, row.path));
        rows.push_back(std::move(row));
        continue;
      }
      const std::optional<double> seconds = Number(row.json, "seconds_per_query_mean", row.path);
      if (row.retrieval == "exact") exact_seconds = seconds;
      std::string ratio = "–";
      if (row.retrieval == "words" && exact_seconds && seconds && *seconds > 0.0) {
        ratio = fmt::format("{:.1f}", *exact_seconds / *seconds);
      }
      html += fmt::format(
          "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></"
          "tr>\n",
          submaps, retrieval, seconds ? fmt::format("{:.1f}", 1e3 * *seconds) : "–", ratio,
          Cell(Number(row.json, "precision", row.path), "{:.3f}"),
          Cell(Number(row.json, "recall", row.path), "{:.3f}"),
          Cell(Number(row.json, "seconds_preparation", row.path), "{:.1f}"));
      rows.push_back(std::move(row));
    }
  }
  html += "</table>\n";
  bool any_json = false;
  for (const SizeRow& row : rows) any_json = any_json || row.json.has_value();
  if (!any_json) return html + MissingHtml("figure: no map-size step has run yet");
  const std::string png = (fs::path(context.figures_dir) / "map-size.png").string();
  try {
    DrawMapSizeFigure(rows, png);
  } catch (const std::exception& error) {
    context.warnings.push_back(std::string("map size figure: ") + error.what());
    return html + MissingHtml(HtmlEscape(error.what()));
  }
  return html + FigureHtml(png,
                           "Query time (log-log) and recall against the number of submaps, exact "
                           "path and retrieval.",
                           "");
}

}  // namespace keyplace::cli
