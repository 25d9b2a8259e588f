#include "report_page.hpp"

#include <cstddef>
#include <ctime>
#include <string>

#include <fmt/core.h>

#include "report_figures.hpp"
#include "report_hospital.hpp"
#include "report_map_size.hpp"
#include "report_tables.hpp"

namespace keyplace::cli {
namespace {

std::string StateText(StepState state) {
  return state == StepState::kDone ? "done before" : StepStateName(state);
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

// The title, what the page was made from, how the steps went, and the contents.
std::string PageHeader(const ReportContext& context, double run_seconds) {
  std::size_t ran = 0, done = 0, skipped = 0, failed = 0;
  for (const StepOutcome& o : context.outcomes) {
    ran += o.state == StepState::kRan;
    done += o.state == StepState::kDone;
    skipped += o.state == StepState::kSkipped;
    failed += o.state == StepState::kFailed;
  }
  std::string html =
      "<h1>keyplace report: the paper's figures and tables, ours beside theirs</h1>\n";
  html += fmt::format(
      "<p>Paper: <i>Stable keypoints selection for 2D LiDAR based place recognition with map data "
      "reduction</i>. Generated {} by <code>keyplace report</code> from the data sets in "
      "<code>{}</code> ({}). Steps: {} ran, {} reused, {} skipped, {} failed; this run took "
      "{:.0f} s.</p>\n",
      HtmlEscape(Now()), HtmlEscape(context.settings.data_dir), HtmlEscape(context.datasets_text),
      ran, done, skipped, failed, run_seconds);
  if (context.settings.quick) {
    html +=
        "<p class=\"missing\">Quick mode (<code>--quick</code>): 20 queries instead of 500, 6 "
        "kidnapped-robot starts instead of 50 and reduced sweep grids. The numbers are not "
        "comparable with the paper's.</p>\n";
  }
  html +=
      "<p>Contents: <a href=\"#maps\">Figures 3–5</a> · <a href=\"#stability\">Figures 6–7</a> · "
      "<a href=\"#mapping\">Table II, Figure 8, Table VI</a> · <a href=\"#place\">Tables III–V, "
      "Figure 9, Tables VII–VIII</a> · <a href=\"#relocalize\">kidnapped robot</a> · "
      "<a href=\"#slam\">Table IX, loops, Figures 10–12</a> · "
      "<a href=\"#hospital\">hospital bag</a> · "
      "<a href=\"#map-size\">map size</a> · "
      "<a href=\"#table10\">Table X</a> · <a href=\"#commands\">commands</a></p>\n";
  return html;
}

// Global localization: Table V, Figure 9, Tables III, IV, VII and VIII, the kidnapped robot.
std::string PlaceSection(ReportContext& context) {
  std::string html = "<h2 id=\"place\">Global localization (Sections 5.2 and 6.2.1)</h2>\n";
  html += TableV();
  html += Figure9(context);
  html +=
      LocalizationTable(context, false, 0.05, "table3", "Table III — corrected logs, λ = 0.05 m");
  html += LocalizationTable(context, false, 0.1, "table4", "Table IV — corrected logs, λ = 0.1 m");
  html += LocalizationTable(context, true, 0.05, "table7",
                            "Table VII — raw (ICP) queries against the corrected map, λ = 0.05 m");
  html += LocalizationTable(context, true, 0.1, "table8",
                            "Table VIII — raw (ICP) queries against the corrected map, λ = 0.1 m");
  html += RelocalizationTable(context);
  html += RelocalizationFigures(context);
  return html;
}

std::string WarningsSection(const ReportContext& context) {
  if (context.warnings.empty()) return "";
  std::string html = "<h2>Warnings</h2>\n<ul>\n";
  for (const std::string& w : context.warnings) html += "<li>" + HtmlEscape(w) + "</li>\n";
  html += "</ul>\n";
  return html;
}

}  // namespace

std::string BuildPage(ReportContext& context, double run_seconds) {
  std::string body = PageHeader(context, run_seconds);
  body += MapFigures(context);
  body += StabilityFigures(context);
  body += "<h2 id=\"mapping\">Mapping (Section 5.1 and 6.1)</h2>\n";
  body += TableII(context);
  body += Figure8(context);
  body += TableVI(context);
  body += PlaceSection(context);
  body += "<h2 id=\"slam\">SLAM with loop closure (Section 6.2.2)</h2>\n";
  body += TableIX(context);
  body += SlamFigures(context);
  body += HospitalSection(context);
  body += MapSizeSection(context);
  body += "<h2 id=\"comparison\">Comparison with TIP-FLIRT (Section 6.3)</h2>\n";
  body += TableX(context);
  body += WarningsSection(context);
  body += CommandsSection(context);
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<title>keyplace report</title>\n<style>" +
         std::string(ReportCss()) + "</style>\n</head>\n<body>\n" + body + "</body>\n</html>\n";
}

}  // namespace keyplace::cli
