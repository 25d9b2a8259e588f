// The report's place recognition tables: V (parameters), III, IV, VII, VIII (global
// localization), X (P_GL / P_CL beside TIP-FLIRT) and the kidnapped robot (keyplace relocalize).

#include <cmath>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/place/place_config.hpp"
#include "paper_parameters.hpp"
#include "paper_tables.hpp"
#include "report_tables.hpp"

namespace keyplace::cli {
namespace {

using Json = nlohmann::json;
using A = ReportArtefacts;

// Our defaults in the order of PaperParameters().
std::vector<std::optional<double>> OurParameterValues() {
  const MappingConfig mapping;
  const PlaceRecognitionConfig place = PlacePreset("default");
  return {
      mapping.cell_size_m,
      mapping.min_stability,
      static_cast<double>(place.min_pairs),
      place.min_gamma,
      place.double_match_m,
      static_cast<double>(mapping.min_scan_count),
      mapping.descriptor_match_chi2,
      mapping.min_overlap,
      mapping.distribution_cell_m,
      mapping.max_distribution,
      static_cast<double>(mapping.min_stable_keypoints),
      static_cast<double>(place.max_candidates),
      place.ransac.inlier_distance_m,
      static_cast<double>(place.min_consensus),
      500.0,  // keyplace localize --n-pos default, checked below
  };
}

// Our row of a localization table: one localize JSON, labelled with its preset and counts.
OursRow LocalizationRow(const ReportContext& context, const std::string& base, bool raw,
                        const std::string& preset, double lambda_m) {
  const std::string path = A::Localize(context.settings, base, raw, preset, lambda_m, 10);
  const std::optional<Json> json = LoadJson(path);
  std::string label = "keyplace <code>--preset " + preset + "</code>";
  if (json) {
    label += fmt::format(" <span class=\"diff\">{}/{}/{}</span>", json->value("n_cor", 0),
                         json->value("n_acc", 0), json->value("n_pos", 0));
  }
  return Row(context, label, path, [&](const auto& j) {
    return std::vector<std::optional<double>>{
        Number(j, "precision", path),  Number(j, "recall", path),
        Number(j, "scans_mean", path), Number(j, "seconds_per_query_mean", path),
        Number(j, "p_gl", path),       Number(j, "p_cl", path)};
  });
}

// Table X's groups OURS-mu-lambda of one data set.
std::vector<ComparedGroup> OursPglPclGroups(const ReportContext& context, const std::string& base) {
  const DatasetFiles f = FilesOf(context.settings, base);
  const std::string map_json = A::MapJson(context.settings, base);
  const std::optional<double> compression = Number(LoadJson(map_json), "compression", map_json);
  const std::optional<double> reduction =
      compression ? std::optional<double>(100.0 * (1.0 - *compression)) : std::nullopt;
  std::vector<ComparedGroup> groups;
  for (const int mu : {5, 10}) {
    for (const double lambda : {0.05, 0.1}) {
      ComparedGroup group{fmt::format("{} OURS-{}-{:g}", f.name, mu, lambda), {}, {}};
      if (const PaperPglPcl* p = PaperTableX(f.name + "_r", "ours", mu, lambda)) {
        // The paper gives the data reduction once per data set (88 % FR079, 85 % Intel).
        const double paper_reduction = base == "fr079" ? 88.0 : 85.0;
        group.paper = {p->p_gl, p->p_cl, paper_reduction};
      }
      for (const std::string preset : {"default", "paper"}) {
        const std::string path = A::Localize(context.settings, base, true, preset, lambda, mu);
        group.ours.push_back(
            Row(context, "keyplace <code>--preset " + preset + "</code>", path, [&](const auto& j) {
              return std::vector<std::optional<double>>{Number(j, "p_gl", path),
                                                        Number(j, "p_cl", path), reduction};
            }));
      }
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

// Table X's TIP-FLIRT group of one data set.
ComparedGroup TipFlirtGroup(const ReportContext& context, const std::string& base) {
  const DatasetFiles f = FilesOf(context.settings, base);
  ComparedGroup tip{f.name + " TIP-FLIRT", {}, {}};
  if (const PaperPglPcl* p = PaperTableX(f.name, "tip-flirt", 0, 0.0)) {
    tip.paper = {p->p_gl, p->p_cl, 0.0};
  }
  for (const int mu : {10, 5}) {
    const std::string path = A::TipFlirt(context.settings, base, mu);
    const std::string label =
        mu == 10 ? "keyplace <code>--baseline tip-flirt</code>"
                 : "keyplace <code>--baseline tip-flirt --mu 5 --set place.min_consensus=5</code>";
    tip.ours.push_back(Row(context, label, path, [&](const auto& j) {
      return std::vector<std::optional<double>>{Number(j, "p_gl", path), Number(j, "p_cl", path),
                                                0.0};
    }));
  }
  return tip;
}

// The flag `key` of `json` (read from `path`), nullopt when missing or null; throws
// std::invalid_argument when the value is no boolean.
std::optional<bool> Flag(const Json& json, const std::string& key, const std::string& path) {
  if (!json.contains(key) || json[key].is_null()) return std::nullopt;
  if (!json[key].is_boolean()) {
    throw std::invalid_argument(path + ": field '" + key + "' is no boolean");
  }
  return json[key].get<bool>();
}

// A cell's number with `digits` decimals ("–" when not measured), `scale` applied.
std::string Cell(std::optional<double> value, int digits, double scale = 1.0) {
  return value ? fmt::format("{:.{}f}", scale * *value, digits) : std::string("–");
}

// The protocol of a relocalize run, as keyplace relocalize prints it.
std::string ProtocolText(const Json& json, const std::string& path) {
  const std::optional<bool> own_log = Flag(json, "query_log_is_map_log", path);
  const std::optional<bool> excluded = Flag(json, "exclude_shared_scans", path);
  if (!own_log) return "–";
  if (!*own_log) return "another recording";
  if (excluded && *excluded) return "the map's own log, shared-scan exclusion";
  return "the map's own log, nothing excluded";
}

// One row of the kidnapped-robot table from the relocalize JSON at `path`.
std::string RelocalizationRow(const ReportContext& context, const std::string& name,
                              const std::string& path, std::size_t columns) {
  const std::optional<Json> json = LoadJson(path);
  std::string html = "<tr><th>" + HtmlEscape(name) + "</th>";
  if (!json) {
    return html + fmt::format("<td colspan=\"{}\" class=\"missing\">not computed: {}</td></tr>\n",
                              columns - 1, HowToMake(context, path));
  }
  const auto n = [&](const std::string& key) { return Number(json, key, path); };
  html += "<td class=\"text\">" + HtmlEscape(ProtocolText(*json, path)) + "</td>";
  html += fmt::format("<td>{} ({})</td>", Cell(n("starts"), 0), Cell(n("starts_with_revisit"), 0));
  html += "<td>" + Cell(n("fixed_fraction"), 3) + "</td>";
  html += fmt::format("<td>{} / {} ({})</td>", Cell(n("wrong_fixes"), 0), Cell(n("fixes"), 0),
                      Cell(n("wrong_fix_rate"), 4));
  html += "<td>" + Cell(n("distance_to_fix_median_m"), 1) + "</td>";
  html += "<td>" + Cell(n("distance_to_fix_p90_m"), 1) + "</td>";
  html += "<td>" + Cell(n("distance_after_revisit_median_m"), 1) + "</td>";
  html += fmt::format("<td>{} ({} / {})</td>", Cell(n("lost_signals"), 0),
                      Cell(n("lost_on_correct_track"), 0), Cell(n("lost_on_wrong_track"), 0));
  html += "<td>" + Cell(n("update_seconds_mean"), 2, 1e3) + "</td>";
  return html + "</tr>\n";
}

}  // namespace

std::string TableV() {
  const PlaceRecognitionConfig place = PlacePreset("default");
  const PlaceRecognitionConfig paper_place = PlacePreset("paper");
  const std::vector<std::optional<double>> ours = OurParameterValues();
  std::string html =
      "<h3 id=\"table5\">Table V — parameters</h3>\n<table><thead><tr><th>parameter</th>"
      "<th>source</th><th>paper</th><th>keyplace default</th><th>meaning</th></tr></thead>"
      "<tbody>\n";
  const auto& parameters = PaperParameters();
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    const PaperParameter& p = parameters[k];
    const double value = k < ours.size() && ours[k] ? *ours[k] : 0.0;
    const bool same = std::abs(value - p.value) < 1e-9;
    html += fmt::format(
        "<tr><td>{}</td><td class=\"text\">{}</td><td>{:g}</td><td{}>{:g}</td><td "
        "class=\"text\">{}</td></tr>\n",
        HtmlEscape(p.name), HtmlEscape(p.source), p.value, same ? "" : " class=\"differs\"", value,
        HtmlEscape(p.meaning));
  }
  html += "</tbody></table>\n";
  html += fmt::format(
      "<p class=\"caption\">Amber: our default differs from the paper's. The default preset "
      "pairs and verifies all-scan query keypoints and then uses γ_min = {:g} "
      "(min_gamma_all_scans); <code>--preset paper</code> keeps γ_min = {:g}, μ = {}, λ = {:g} m "
      "(docs/PLACE.md). n_pos is the default of <code>keyplace localize --n-pos</code>.</p>\n",
      place.min_gamma_all_scans, paper_place.min_gamma, paper_place.min_pairs,
      paper_place.double_match_m);
  return html;
}

std::string LocalizationTable(const ReportContext& context, bool raw, double lambda_m,
                              const std::string& anchor, const std::string& title) {
  static const std::vector<ComparedColumn> kColumns{
      {"precision", Better::kHigher, 0.01, false, 3}, {"recall", Better::kHigher, 0.02, false, 3},
      {"#scans", Better::kLower, 0.2, true, 2},       {"time (s)", Better::kLower, 0.1, true, 4},
      {"P_GL", Better::kHigher, 0.02, false, 2},      {"P_CL", Better::kHigher, 0.02, false, 2},
  };
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    const std::string name = raw ? f.name + "_r" : f.name;
    ComparedGroup group{name, {}, {}};
    if (const PaperLocalizationRow* p = PaperLocalization(name, lambda_m)) {
      group.paper = {p->precision, p->recall, p->scans, p->seconds, std::nullopt, std::nullopt};
    }
    for (const std::string preset : {"default", "paper"}) {
      group.ours.push_back(LocalizationRow(context, base, raw, preset, lambda_m));
    }
    groups.push_back(std::move(group));
  }
  return ComparisonTableHtml(
      anchor, title,
      "μ = 10, γ_min = 0.4 (default preset: 0.15 for its all-scan query keypoints, see "
      "docs/PLACE.md). #scans = scans per correct localization, time = place recognition per "
      "query. n_cor/n_acc/n_pos after the preset. P_GL / P_CL from our precision–recall curve.",
      kColumns, groups);
}

std::string TableX(const ReportContext& context) {
  static const std::vector<ComparedColumn> kColumns{
      {"P_GL", Better::kHigher, 0.02, false, 2},
      {"P_CL", Better::kHigher, 0.02, false, 2},
      {"data reduc. (%)", Better::kHigher, 2.0, false, 0},
  };
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    if (base == "fr101") continue;  // the paper evaluated FR079 and Intel
    for (ComparedGroup& group : OursPglPclGroups(context, base)) groups.push_back(std::move(group));
    groups.push_back(TipFlirtGroup(context, base));
  }
  return ComparisonTableHtml(
      "table10", "Table X — P_GL and P_CL (raw queries against the corrected map)",
      "OURS-μ-λ: raw (ICP) query submaps against the map of the corrected log. TIP-FLIRT: every "
      "corrected scan a place, single-scan queries (our re-implementation of the protocol, "
      "docs/RESULTS.md). Data reduction = 1 − compression of the localization map.",
      kColumns, groups);
}

std::string RelocalizationTable(const ReportContext& context) {
  static const std::vector<std::string> kHeaders{"data set",
                                                 "protocol",
                                                 "starts (with a revisit)",
                                                 "fixed fraction",
                                                 "wrong fixes / fixes (rate)",
                                                 "to first fix, median (m)",
                                                 "to first fix, 90th pct. (m)",
                                                 "after the first known place, median (m)",
                                                 "lost signals (correct / wrong track)",
                                                 "update, mean (ms)"};
  std::string html =
      "<h3 id=\"relocalize\">Kidnapped robot (keyplace relocalize, strict preset)</h3>\n"
      "<table><thead><tr>";
  for (const std::string& header : kHeaders) html += "<th>" + HtmlEscape(header) + "</th>";
  html += "</tr></thead><tbody>\n";
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    for (const bool raw : {false, true}) {
      html += RelocalizationRow(context, raw ? f.name + "_r" : f.name,
                                A::Relocalize(context.settings, base, raw), kHeaders.size());
    }
  }
  html += "</tbody></table>\n";
  html +=
      "<p class=\"caption\">Not in the paper (docs/LOCALIZATION.md). From each start spread over "
      "the query log the relocalizer, knowing nothing, is fed scans and odometry until it declares "
      "a fix or gives up; every fix it reports over the following distance is checked against the "
      "truth (0.5 m, 10°). FR079: the corrected log against its own map, map submaps sharing a "
      "scan with the query excluded; FR079_r: the raw log with ICP odometry against the corrected "
      "map. A start has a revisit when its true path passes a map scan it may be matched with; "
      "fixed fraction counts those starts only. After the first known place: distance from where "
      "the path first passes such a map scan to the fix. Lost signals: the localizer said it was "
      "lost, on a correct or a wrong track (the rest had no truth to tell). Update: time per scan "
      "with its keypoints given. The "
      "paper has no such figures, so nothing is coloured.</p>\n";
  return html;
}

}  // namespace keyplace::cli
