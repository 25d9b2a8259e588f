// The report's figure sections: maps (Figures 3-5), stability (6-7, drawn here), the sweeps
// (8-9, drawn here from the sweep results), the kidnapped robot (drawn by keyplace relocalize) and
// SLAM (10-12, drawn by keyplace slam).

#include <exception>
#include <filesystem>
#include <string>
#include <system_error>

#include <fmt/core.h>

#include "report_figures.hpp"
#include "stability_figures.hpp"
#include "sweep_figures.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;
using A = ReportArtefacts;

// The first corrected log of the report that exists ("" if none).
std::string FirstCorrectedLog(const ReportContext& context) {
  for (const std::string& base : context.settings.datasets) {
    std::string candidate = FilesOf(context.settings, base).corrected_log;
    std::error_code error;
    if (fs::exists(candidate, error)) return candidate;
  }
  return "";
}

// Figures 6 and 7 with their captions, from what drawing them found.
std::string StabilityFiguresHtml(const StabilityFigureSummary& s, const std::string& fig6,
                                 const std::string& fig7) {
  std::string html = fmt::format(
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

}  // namespace

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

std::string StabilityFigures(ReportContext& context) {
  std::string html = "<h2 id=\"stability\">Figures 6–7: keypoint stability</h2>\n";
  const std::string log = FirstCorrectedLog(context);
  if (log.empty())
    return html + MissingHtml("no corrected log in " + HtmlEscape(context.settings.data_dir));
  const std::string fig6 = (fs::path(context.figures_dir) / "fig6-stability.png").string();
  const std::string fig7 = (fs::path(context.figures_dir) / "fig7-distribution.png").string();
  try {
    html += StabilityFiguresHtml(DrawStabilityFigures(log, context.stability_scan, fig6, fig7),
                                 fig6, fig7);
  } catch (const std::exception& error) {
    html += MissingHtml(HtmlEscape(error.what()));
    context.warnings.push_back(std::string("stability figures: ") + error.what());
  }
  return html;
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

std::string RelocalizationFigures(const ReportContext& context) {
  std::string html =
      "<p>Kidnapped robot, the map's scan positions (grey) and for every start its true path to "
      "its first fix (blue), the start (black), the first fix where the localizer put the robot "
      "(green when correct) and every wrong fix (red). From <code>keyplace relocalize "
      "--figure</code>.</p>\n";
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    html += "<div class=\"grid2\">";
    for (const bool raw : {false, true}) {
      const std::string name = HtmlEscape(raw ? f.name + "_r" : f.name);
      const std::string png = A::RelocalizePng(context.settings, base, raw);
      html += FigureHtml(png,
                         "Kidnapped robot (ours), " + name +
                             (raw ? ": raw log, ICP odometry, against the corrected map"
                                  : ": corrected log against its own map"),
                         "kidnapped robot, " + name + ": " + HowToMake(context, png));
    }
    html += "</div>\n";
  }
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

}  // namespace keyplace::cli
