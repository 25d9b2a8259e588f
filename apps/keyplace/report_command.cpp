// keyplace report --out DIR: every figure and table of the paper, ours beside the paper's, in one
// self-contained HTML page. Missing artefacts are made by running keyplace's own commands.

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/place/place_config.hpp"
#include "paper_parameters.hpp"
#include "paper_tables.hpp"
#include "report_html.hpp"
#include "report_plan.hpp"
#include "stability_figures.hpp"
#include "sweep_figures.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using A = ReportArtefacts;

struct ReportOptions {
  std::string out_dir;
  std::string data_dir;
  std::string work_dir;
  std::string datasets = "fr079,fr101,intel";
  bool no_run = false;
  bool quick = false;
  int threads = 0;
  std::size_t stability_scan = 100;
};

// What the page builder knows: settings, the plan and what happened to each step.
struct ReportContext {
  ReportSettings settings;
  std::vector<ReportStep> steps;
  std::vector<StepOutcome> outcomes;
  std::string figures_dir;  // OUT/figures: figures drawn by the report itself
  std::vector<std::string> warnings;
};

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

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

// --- Tables II and VI: mapping criteria.
const std::vector<ComparedColumn>& MappingColumns() {
  static const std::vector<ComparedColumn> kColumns{
      {"Compress.", Better::kLower, 0.02, false, 3}, {"#Scans", Better::kNone, 0.2, true, 2},
      {"#Keypoints", Better::kNone, 0.2, true, 2},   {"Distrib.", Better::kLower, 0.02, false, 3},
      {"#Submaps", Better::kNone, 0.2, true, 0},     {"Time (s)", Better::kLower, 0.1, true, 4},
  };
  return kColumns;
}

std::vector<std::optional<double>> MappingValues(const std::optional<Json>& json,
                                                 const std::string& path) {
  return {Number(json, "compression", path),
          Number(json, "scans_per_submap", path),
          Number(json, "keypoints_per_submap", path),
          Number(json, "distribution", path),
          Number(json, "submaps", path),
          Number(json, "seconds_per_submap", path)};
}

std::vector<std::optional<double>> PaperMappingValues(const std::string& dataset) {
  const PaperMappingRow* row = PaperMapping(dataset);
  if (row == nullptr) return {};
  return {row->compression,
          row->scans_per_submap,
          row->keypoints_per_submap,
          row->distribution,
          static_cast<double>(row->submaps),
          row->seconds_per_submap};
}

OursRow Row(
    const ReportContext& context, const std::string& label_html, const std::string& path,
    const std::function<std::vector<std::optional<double>>(const std::optional<Json>&)>& values) {
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

std::string TableII(const ReportContext& context) {
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    ComparedGroup group{f.name, PaperMappingValues(f.name), {}};
    const std::string t2 = A::TableIIJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, overlap criterion only (as Table II)", t2,
                             [&](const auto& j) { return MappingValues(j, t2); }));
    const std::string all = A::MapJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, all criteria (the localization map)", all,
                             [&](const auto& j) { return MappingValues(j, all); }));
    groups.push_back(std::move(group));
  }
  return ComparisonTableHtml(
      "table2", "Table II — mapping criteria, corrected logs and poses",
      "Compress. = stable keypoints in the map / FLIRT keypoints of all scans; #Scans, "
      "#Keypoints = mean per submap; Distrib. = mean δ; Time = seconds per submap including "
      "FLIRT extraction and poses (the paper: Intel i3-3217U).",
      MappingColumns(), groups);
}

std::string TableVI(const ReportContext& context) {
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    ComparedGroup group{f.name + "_r", PaperMappingValues(f.name + "_r"), {}};
    const std::string path = A::RawMapJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, ICP poses, all criteria", path,
                             [&](const auto& j) { return MappingValues(j, path); }));
    groups.push_back(std::move(group));
  }
  return ComparisonTableHtml("table6", "Table VI — mapping criteria, raw logs (ICP poses)",
                             "Columns as Table II.", MappingColumns(), groups);
}

// --- Tables III, IV, VII, VIII: global localization.
std::string LocalizationTable(const ReportContext& context, bool raw, double lambda,
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
    if (const PaperLocalizationRow* p = PaperLocalization(name, lambda)) {
      group.paper = {p->precision, p->recall, p->scans, p->seconds, std::nullopt, std::nullopt};
    }
    for (const std::string preset : {"default", "paper"}) {
      const std::string path = A::Localize(context.settings, base, raw, preset, lambda, 10);
      const std::optional<Json> json = LoadJson(path);
      std::string label = "keyplace <code>--preset " + std::string(preset) + "</code>";
      if (json) {
        label += fmt::format(" <span class=\"diff\">{}/{}/{}</span>", json->value("n_cor", 0),
                             json->value("n_acc", 0), json->value("n_pos", 0));
      }
      group.ours.push_back(Row(context, label, path, [&](const auto& j) {
        return std::vector<std::optional<double>>{
            Number(j, "precision", path),  Number(j, "recall", path),
            Number(j, "scans_mean", path), Number(j, "seconds_per_query_mean", path),
            Number(j, "p_gl", path),       Number(j, "p_cl", path)};
      }));
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

// --- Table V: parameters.
std::string TableV() {
  const MappingConfig mapping;
  const PlaceRecognitionConfig place = PlacePreset("default");
  const PlaceRecognitionConfig paper_place = PlacePreset("paper");
  const std::vector<std::optional<double>> ours{
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

// --- Table IX and the loops of Section 6.2.2.
std::string TableIX(const ReportContext& context) {
  std::vector<ComparedGroup> mapping_groups;
  std::vector<ComparedGroup> loop_groups;
  static const std::vector<ComparedColumn> kLoopColumns{
      {"loops detected", Better::kNone, 0.2, true, 0},
      {"loops used", Better::kNone, 0.2, true, 0},
      {"precision @10 %", Better::kHigher, 0.02, false, 3},
      {"precision @30 %", Better::kHigher, 0.02, false, 3},
      {"@30 % in common area", Better::kHigher, 0.02, false, 3},
      {"precision vs truth", Better::kHigher, 0.02, false, 3},
      {"ATE RMSE (m)", Better::kLower, 0.1, true, 3},
  };
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    const std::string name = f.name + "_r";
    const PaperSlamRow* p = PaperSlam(name);
    const std::string path = fs::path(A::SlamDir(context.settings, base)) / "slam.json";
    ComparedGroup mapping{name, {}, {}};
    ComparedGroup loops{name, {}, {}};
    if (p != nullptr) {
      mapping.paper = {p->compression,
                       p->scans_per_submap,
                       p->keypoints_per_submap,
                       p->distribution,
                       static_cast<double>(p->submaps),
                       p->seconds_per_submap};
      loops.paper = {static_cast<double>(p->loops_detected),
                     static_cast<double>(p->loops_used),
                     p->precision_overlap_10,
                     p->precision_overlap_30,
                     std::nullopt,
                     std::nullopt,
                     std::nullopt};
    }
    mapping.ours.push_back(
        Row(context, "keyplace slam", path, [&](const auto& j) { return MappingValues(j, path); }));
    loops.ours.push_back(Row(context, "keyplace slam", path, [&](const auto& j) {
      return std::vector<std::optional<double>>{Number(j, "loops_detected", path),
                                                Number(j, "loops_used", path),
                                                Number(j, "precision_overlap_10", path),
                                                Number(j, "precision_overlap_30", path),
                                                Number(j, "precision_overlap_30_common_area", path),
                                                Number(j, "precision_truth", path),
                                                Number(j, "ate_rmse_m", path)};
    }));
    mapping_groups.push_back(std::move(mapping));
    loop_groups.push_back(std::move(loops));
  }
  std::string html =
      ComparisonTableHtml("table9", "Table IX — mapping criteria of the SLAM maps (raw logs)",
                          "Columns as Table II; time = seconds per submap of the whole SLAM run.",
                          MappingColumns(), mapping_groups);
  html += ComparisonTableHtml(
      "loops", "Loops (Section 6.2.2)",
      "Precision @x % = share of detected loops whose matched submaps overlap by at least x % "
      "(IoU of 0.1 m hit cells); in common area = the same IoU counted only over the cells both "
      "submaps observed (docs/SLAM.md); vs truth = loops within 0.5 m / 10° of the corrected "
      "poses, for the loops whose submap origins lie within 50 scans of a corrected scan (the "
      "paper has neither figure). ATE after SE(2) alignment (the paper gives it as Figure 12 "
      "only).",
      kLoopColumns, loop_groups);
  return html;
}

// --- Table X: P_GL / P_CL.
std::string TableX(const ReportContext& context) {
  static const std::vector<ComparedColumn> kColumns{
      {"P_GL", Better::kHigher, 0.02, false, 2},
      {"P_CL", Better::kHigher, 0.02, false, 2},
      {"data reduc. (%)", Better::kHigher, 2.0, false, 0},
  };
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    if (base == "fr101") continue;  // the paper evaluated FR079 and Intel
    const DatasetFiles f = FilesOf(context.settings, base);
    const std::string map_json = A::MapJson(context.settings, base);
    const std::optional<double> compression = Number(LoadJson(map_json), "compression", map_json);
    const std::optional<double> reduction =
        compression ? std::optional<double>(100.0 * (1.0 - *compression)) : std::nullopt;
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
              Row(context, "keyplace <code>--preset " + std::string(preset) + "</code>", path,
                  [&](const auto& j) {
                    return std::vector<std::optional<double>>{Number(j, "p_gl", path),
                                                              Number(j, "p_cl", path), reduction};
                  }));
        }
        groups.push_back(std::move(group));
      }
    }
    ComparedGroup tip{f.name + " TIP-FLIRT", {}, {}};
    if (const PaperPglPcl* p = PaperTableX(f.name, "tip-flirt", 0, 0.0)) {
      tip.paper = {p->p_gl, p->p_cl, 0.0};
    }
    for (const int mu : {10, 5}) {
      const std::string path = A::TipFlirt(context.settings, base, mu);
      const std::string label =
          mu == 10 ? "keyplace <code>--baseline tip-flirt</code>"
                   : "keyplace <code>--baseline tip-flirt --mu 5 --set min_consensus=5</code>";
      tip.ours.push_back(Row(context, label, path, [&](const auto& j) {
        return std::vector<std::optional<double>>{Number(j, "p_gl", path), Number(j, "p_cl", path),
                                                  0.0};
      }));
    }
    groups.push_back(std::move(tip));
  }
  return ComparisonTableHtml(
      "table10", "Table X — P_GL and P_CL (raw queries against the corrected map)",
      "OURS-μ-λ: raw (ICP) query submaps against the map of the corrected log. TIP-FLIRT: every "
      "corrected scan a place, single-scan queries (our re-implementation of the protocol, "
      "docs/RESULTS.md). Data reduction = 1 − compression of the localization map.",
      kColumns, groups);
}

// --- Figures.
std::string MapFigures(const ReportContext& context) {
  std::string html = "<h2 id=\"maps\">Figures 3–5: maps of the corrected logs</h2>\n";
  int number = 3;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    const std::string png = A::MapPng(context.settings, base);
    html += FigureHtml(png,
                       fmt::format("Figure {} (ours): {} — registered scan points (grey), stable "
                                   "keypoints coloured by submap, submap origins (triangles).",
                                   base == "fr079" ? 3 : (base == "fr101" ? 4 : 5), f.name),
                       "Figure " + std::to_string(number) + ", " + HtmlEscape(f.name) + ": " +
                           HowToMake(context, png));
    ++number;
  }
  return html;
}

std::string StabilityFigures(ReportContext& context, const ReportOptions& options) {
  std::string html = "<h2 id=\"stability\">Figures 6–7: keypoint stability</h2>\n";
  // The first corrected log of the report that exists.
  std::string log;
  for (const std::string& base : context.settings.datasets) {
    const std::string candidate = FilesOf(context.settings, base).corrected_log;
    std::error_code error;
    if (fs::exists(candidate, error)) {
      log = candidate;
      break;
    }
  }
  if (log.empty())
    return html + MissingHtml("no corrected log in " + HtmlEscape(context.settings.data_dir));
  const std::string fig6 = (fs::path(context.figures_dir) / "fig6-stability.png").string();
  const std::string fig7 = (fs::path(context.figures_dir) / "fig7-distribution.png").string();
  try {
    const StabilityFigureSummary s = DrawStabilityFigures(log, options.stability_scan, fig6, fig7);
    html += fmt::format(
        "<p>One submap of {} (scans {}–{}, {} scans, default mapping configuration, corrected "
        "poses), built as <code>keyplace map</code> builds it. Scan i is its first scan, scan j "
        "its last.</p>\n",
        HtmlEscape(s.dataset), s.first_scan, s.last_scan, s.scans);
    html += FigureHtml(
        fig6,
        fmt::format("Figure 6 (ours). (a) scans i and j with their FLIRT keypoints (support "
                    "circles = scale); {} cells of G hold keypoints of both scans in the same "
                    "history cluster (similar descriptors, the paper's region b), {} in different "
                    "clusters (region a). (b) the stability grid G: {} cells with a keypoint "
                    "history, {} stable (s ≥ s_min = {:g}).",
                    s.same_cluster_cells, s.other_cluster_cells, s.history_cells, s.stable,
                    s.min_stability),
        "");
    html += FigureHtml(
        fig7,
        fmt::format("Figure 7 (ours). (a) occupancy grid with the stable keypoints; (b) the "
                    "binary histograms h_lp (all non-black cells) and h_kp (red) on the 0.5 m "
                    "grid D; δ = {:.3f}, overlap ρ at completion {:.3f}.",
                    s.distribution, s.overlap),
        "");
  } catch (const std::exception& error) {
    html += MissingHtml(HtmlEscape(error.what()));
    context.warnings.push_back(std::string("stability figures: ") + error.what());
  }
  return html;
}

std::string SweepFigure(ReportContext& context, const std::string& results, const std::string& png,
                        bool mapping, const std::string& title, const std::string& caption) {
  std::error_code error;
  if (!fs::exists(results, error)) return MissingHtml(title + ": " + HowToMake(context, results));
  try {
    if (mapping) {
      DrawFigure8(results, png, title);
    } else {
      DrawFigure9(results, png, title);
    }
  } catch (const std::exception& e) {
    context.warnings.push_back(e.what());
    return MissingHtml(HtmlEscape(e.what()));
  }
  return FigureHtml(png, caption + " Data: <code>" + HtmlEscape(results) + "</code>.", "");
}

std::string Figure8(ReportContext& context) {
  std::string html = "<h2 id=\"fig8\">Figure 8: mapping criteria vs s_min and l_g</h2>\n";
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    const std::string results =
        (fs::path(A::Fig8Dir(context.settings, base)) / "results.json").string();
    html += SweepFigure(
        context, results, (fs::path(context.figures_dir) / ("fig8-" + base + ".png")).string(),
        true, "Figure 8 (ours), " + f.name,
        "Figure 8 (ours), " + HtmlEscape(f.name) +
            ": the criteria of Section 5.1 over s_min, one line per l_g (keyplace sweep "
            "mapping; other parameters at their defaults). Time = mapping only, this machine.");
  }
  return html;
}

std::string Figure9(ReportContext& context) {
  std::string html =
      "<h2 id=\"fig9\">Figure 9: precision and recall vs μ and γ_min (FR079, λ = 0.05 m)</h2>\n";
  bool any = false;
  for (const std::string& base : context.settings.datasets) {
    if (base != "fr079") continue;
    any = true;
    for (const std::string preset : {"default", "paper"}) {
      const std::string results =
          (fs::path(A::Fig9Dir(context.settings, base, preset)) / "results.json").string();
      html += SweepFigure(
          context, results,
          (fs::path(context.figures_dir) / fmt::format("fig9-{}-{}.png", base, preset)).string(),
          false, "Figure 9 (ours), FR079, --preset " + std::string(preset),
          "Figure 9 (ours), FR079, <code>--preset " + std::string(preset) +
              "</code>: global localization precision and recall over γ_min, one line per μ "
              "(keyplace sweep place). With the default preset γ_min is the threshold in force "
              "for its all-scan query keypoints. No precision point where no query was accepted.");
    }
  }
  if (!any) html += MissingHtml("FR079 is not among the report's data sets");
  return html;
}

std::string SlamFigures(const ReportContext& context) {
  std::string html =
      "<h2 id=\"fig10\">Figures 10–12: SLAM on the raw logs</h2>\n<p>Figure 10: trajectory "
      "(red) over the corrected poses (green), loops used (white), and the overlap histogram of "
      "the matched submaps; Figure 11: RMSE of the RPE vs Δ (scans); Figure 12: ATE vs path "
      "length. From <code>keyplace slam --figures</code>.</p>\n";
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    const fs::path dir = fs::path(A::SlamDir(context.settings, base)) / "figures";
    html += "<h3>" + HtmlEscape(f.name) + "_r</h3>\n";
    const std::string trajectory = (dir / "trajectory.png").string();
    std::error_code error;
    if (!fs::exists(trajectory, error)) {
      html += MissingHtml("Figures 10–12, " + HtmlEscape(f.name) +
                          "_r: " + HowToMake(context, trajectory));
      continue;
    }
    html += "<div class=\"grid2\">";
    html += FigureHtml(trajectory, "Figure 10 (ours, left), " + HtmlEscape(f.name) + "_r", "");
    html += FigureHtml((dir / "overlap_histogram.png").string(),
                       "Figure 10 (ours, right): overlap of matched submaps", "missing");
    html += "</div>\n";
    html += FigureHtml((dir / "overlap_histogram_common_area.png").string(),
                       "Overlap of matched submaps in the area both observed (not in the paper)",
                       "missing (made by keyplace slam since the common-area overlap)");
    html += FigureHtml((dir / "rpe.png").string(), "Figure 11 (ours): RMSE of RPE vs Δ",
                       "rpe.png missing (slam ran without --truth?)");
    html += FigureHtml((dir / "ate.png").string(), "Figure 12 (ours): ATE vs path length",
                       "ate.png missing (slam ran without --truth?)");
  }
  return html;
}

std::string StateText(StepState state) {
  switch (state) {
    case StepState::kDone:
      return "done before";
    case StepState::kRan:
      return "ran";
    case StepState::kFailed:
      return "failed";
    case StepState::kSkipped:
      return "skipped";
  }
  return "";
}

std::string CommandsSection(const ReportContext& context) {
  std::string html =
      "<h2 id=\"commands\">How every number was made</h2>\n<p>Each artefact is the output of an "
      "ordinary keyplace command, run by <code>keyplace report</code> in the work directory "
      "<code>" +
      HtmlEscape(context.settings.work_dir) +
      "</code> (its output in <code>logs/ID.log</code>). Times are of this run; "
      "\"done before\" steps were reused.</p>\n<table><thead><tr><th>step</th><th>for</th>"
      "<th>state</th><th>time (s)</th></tr></thead><tbody>\n";
  for (std::size_t k = 0; k < context.steps.size(); ++k) {
    const ReportStep& step = context.steps[k];
    const StepOutcome& outcome = context.outcomes[k];
    const std::string css = outcome.state == StepState::kFailed    ? " class=\"state-failed\""
                            : outcome.state == StepState::kSkipped ? " class=\"state-skipped\""
                                                                   : "";
    html += fmt::format(
        "<tr><td>{}</td><td>{}</td><td{}>{}{}</td><td>{}</td></tr>\n<tr><td colspan=\"4\">"
        "<code>{}</code></td></tr>\n",
        HtmlEscape(step.id), HtmlEscape(step.what), css, StateText(outcome.state),
        outcome.message.empty() ? "" : ": " + HtmlEscape(outcome.message),
        outcome.state == StepState::kRan || outcome.state == StepState::kFailed
            ? fmt::format("{:.1f}", outcome.seconds)
            : "",
        HtmlEscape(CommandLine(step)));
  }
  html += "</tbody></table>\n";
  return html;
}

std::string Now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char text[64];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S %Z", &tm);
  return text;
}

std::string BuildPage(ReportContext& context, const ReportOptions& options, double run_seconds) {
  std::size_t ran = 0, done = 0, skipped = 0, failed = 0;
  for (const StepOutcome& o : context.outcomes) {
    ran += o.state == StepState::kRan;
    done += o.state == StepState::kDone;
    skipped += o.state == StepState::kSkipped;
    failed += o.state == StepState::kFailed;
  }
  std::string body;
  body += "<h1>keyplace report: the paper's figures and tables, ours beside theirs</h1>\n";
  body += fmt::format(
      "<p>Paper: <i>Stable keypoints selection for 2D LiDAR based place recognition with map data "
      "reduction</i>. Generated {} by <code>keyplace report</code> from the data sets in "
      "<code>{}</code> ({}). Steps: {} ran, {} reused, {} skipped, {} failed; this run took "
      "{:.0f} s.</p>\n",
      HtmlEscape(Now()), HtmlEscape(context.settings.data_dir), HtmlEscape(options.datasets), ran,
      done, skipped, failed, run_seconds);
  if (context.settings.quick) {
    body +=
        "<p class=\"missing\">Quick mode (<code>--quick</code>): 20 queries instead of 500 and "
        "reduced sweep grids. The numbers are not comparable with the paper's.</p>\n";
  }
  body +=
      "<p>Contents: <a href=\"#maps\">Figures 3–5</a> · <a href=\"#stability\">Figures 6–7</a> · "
      "<a href=\"#mapping\">Table II, Figure 8, Table VI</a> · <a href=\"#place\">Tables III–V, "
      "Figure 9, Tables VII–VIII</a> · <a href=\"#slam\">Table IX, loops, Figures 10–12</a> · "
      "<a href=\"#table10\">Table X</a> · <a href=\"#commands\">commands</a></p>\n";
  body += MapFigures(context);
  body += StabilityFigures(context, options);
  body += "<h2 id=\"mapping\">Mapping (Section 5.1 and 6.1)</h2>\n";
  body += TableII(context);
  body += Figure8(context);
  body += TableVI(context);
  body += "<h2 id=\"place\">Global localization (Sections 5.2 and 6.2.1)</h2>\n";
  body += TableV();
  body += Figure9(context);
  body +=
      LocalizationTable(context, false, 0.05, "table3", "Table III — corrected logs, λ = 0.05 m");
  body += LocalizationTable(context, false, 0.1, "table4", "Table IV — corrected logs, λ = 0.1 m");
  body += LocalizationTable(context, true, 0.05, "table7",
                            "Table VII — raw (ICP) queries against the corrected map, λ = 0.05 m");
  body += LocalizationTable(context, true, 0.1, "table8",
                            "Table VIII — raw (ICP) queries against the corrected map, λ = 0.1 m");
  body += "<h2 id=\"slam\">SLAM with loop closure (Section 6.2.2)</h2>\n";
  body += TableIX(context);
  body += SlamFigures(context);
  body += "<h2 id=\"comparison\">Comparison with TIP-FLIRT (Section 6.3)</h2>\n";
  body += TableX(context);
  if (!context.warnings.empty()) {
    body += "<h2>Warnings</h2>\n<ul>\n";
    for (const std::string& w : context.warnings) body += "<li>" + HtmlEscape(w) + "</li>\n";
    body += "</ul>\n";
  }
  body += CommandsSection(context);
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<title>keyplace report</title>\n<style>" +
         std::string(ReportCss()) + "</style>\n</head>\n<body>\n" + body + "</body>\n</html>\n";
}

std::string DefaultDataDir() {
  const char* shared = std::getenv("KEYPLACE_SHARED");
  return shared != nullptr ? (fs::path(shared) / "data").string() : std::string("../shared/data");
}

int RunReport(const ReportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ReportContext context;
  context.settings.data_dir = options.data_dir.empty() ? DefaultDataDir() : options.data_dir;
  context.settings.work_dir =
      options.work_dir.empty() ? (fs::path(options.out_dir) / "work").string() : options.work_dir;
  context.settings.quick = options.quick;
  context.settings.threads = options.threads;
  for (const std::string& base : Split(options.datasets)) {
    if (base != "fr079" && base != "fr101" && base != "intel") {
      throw std::invalid_argument("--datasets: unknown data set '" + base +
                                  "' (known: fr079, fr101, intel)");
    }
    context.settings.datasets.push_back(base);
  }
  if (context.settings.datasets.empty()) throw std::invalid_argument("--datasets is empty");
  fs::create_directories(options.out_dir);
  fs::create_directories(context.settings.work_dir);
  context.figures_dir = (fs::path(options.out_dir) / "figures").string();
  fs::create_directories(context.figures_dir);

  context.steps = PlanReport(context.settings);
  // This very executable, even if its file is replaced by a rebuild while the report runs.
  const std::string program = "/proc/self/exe";
  fmt::print("keyplace report: {} steps, data {}, work {}\n", context.steps.size(),
             context.settings.data_dir, context.settings.work_dir);
  context.outcomes = RunSteps(context.settings, context.steps, program, options.no_run);
  const double run_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string page = BuildPage(context, options, run_seconds);
  const std::string index = (fs::path(options.out_dir) / "index.html").string();
  WriteFileAtomically(index, [&](std::ostream& out) { out << page; });
  std::size_t failed = 0;
  for (const StepOutcome& o : context.outcomes) failed += o.state == StepState::kFailed;
  fmt::print(
      "report written to {} ({:.1f} MB) in {:.0f} s{}\n", index,
      static_cast<double>(page.size()) / 1e6,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
      failed > 0 ? fmt::format("; {} step(s) FAILED, see the page's command list", failed) : "");
  return failed > 0 ? 1 : 0;
}

}  // namespace

void RegisterReportCommand(CLI::App& app) {
  auto options = std::make_shared<ReportOptions>();
  CLI::App* command = app.add_subcommand(
      "report",
      "Write DIR/index.html: one self-contained page with every figure (3-12) and table (II-X) "
      "of the paper, ours beside the paper's with the differences highlighted. Artefacts (maps, "
      "localize/slam JSON, sweeps) are cached in a work directory; missing ones are made by "
      "running keyplace map/localize/sweep/slam, each command listed on the page. Rerun to "
      "resume.");
  command->add_option("--out", options->out_dir, "Output directory (index.html, figures/)")
      ->required();
  command->add_option("--data", options->data_dir,
                      "Data sets directory (default: $KEYPLACE_SHARED/data, else ../shared/data)");
  command->add_option("--work", options->work_dir,
                      "Work directory for artefacts (default OUT/work)");
  command
      ->add_option("--datasets", options->datasets,
                   "Comma-separated data sets: fr079, fr101, intel (each corrected and raw)")
      ->capture_default_str();
  command->add_flag("--no-run", options->no_run,
                    "Run nothing: render what the work directory holds, mark the rest "
                    "\"not computed\"");
  command->add_flag("--quick", options->quick,
                    "20 queries instead of 500 and small sweep grids (tests, a first look)");
  command->add_option("--threads", options->threads, "Threads of the sweeps (0 = all cores)")
      ->capture_default_str();
  command
      ->add_option("--stability-scan", options->stability_scan,
                   "First scan of the submap drawn in Figures 6-7")
      ->capture_default_str();
  command->callback([options] {
    const int status = RunReport(*options);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace keyplace::cli
