#pragma once
// Building blocks of the report's HTML page: escaping, embedded images, and tables that put our
// figures beside the paper's with the difference highlighted.

#include <optional>
#include <string>
#include <vector>

namespace keyplace::cli {

std::string HtmlEscape(const std::string& text);
std::string Base64(const std::string& bytes);

/// A <figure> with the PNG at `png_path` embedded as a data: URI (the page stays one file), or,
/// when the file does not exist, a "not computed" note with `missing_note` (HTML).
std::string FigureHtml(const std::string& png_path, const std::string& caption_html,
                       const std::string& missing_note_html);

/// A "not computed" box.
std::string MissingHtml(const std::string& note_html);

/// How a column is judged. kHigher / kLower: ours is "better" (green) or "worse" (red) when it is
/// beyond the paper by more than the tolerance in that direction. kNone: descriptive figures
/// (scans, keypoints, submaps); "differs" (amber) beyond the tolerance.
enum class Better { kHigher, kLower, kNone };

struct ComparedColumn {
  std::string header;
  Better better = Better::kNone;
  double tolerance = 0.0;  // absolute, or a fraction of the paper's value when `relative`
  bool relative = false;
  int digits = 3;  // decimals shown
};

struct OursRow {
  std::string label_html;
  std::vector<std::optional<double>> values;  // one per column; nullopt = not measured
  std::string missing_html;                   // when not empty, the row is this note instead
};

struct ComparedGroup {
  std::string name;                          // data set
  std::vector<std::optional<double>> paper;  // one per column; nullopt = the paper has none
  std::vector<OursRow> ours;
};

/// A table with, per group, the paper's row then ours, each of our cells showing the value and
/// its difference to the paper's (ours - paper, and in % of the paper's), coloured by the
/// column's rule. The caption states the tolerances.
std::string ComparisonTableHtml(const std::string& anchor, const std::string& title_html,
                                const std::string& caption_html,
                                const std::vector<ComparedColumn>& columns,
                                const std::vector<ComparedGroup>& groups);

/// The verdict of one cell (exposed for tests): "better", "worse", "differs" or "" (within the
/// tolerance, or nothing to compare).
std::string CompareClass(const ComparedColumn& column, std::optional<double> ours,
                         std::optional<double> paper);

/// The page's style sheet (hand-written CSS).
const char* ReportCss();

}  // namespace keyplace::cli
