#include "report_html.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

namespace keyplace::cli {
namespace {

std::string FormatValue(double value, int digits) { return fmt::format("{:.{}f}", value, digits); }

std::string ToleranceText(const ComparedColumn& column) {
  if (column.relative) return fmt::format("{:g} %", 100.0 * column.tolerance);
  return fmt::format("{:g}", column.tolerance);
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string MissingHtml(const std::string& note_html) {
  return "<div class=\"missing\">not computed: " + note_html + "</div>\n";
}

std::string FigureHtml(const std::string& png_path, const std::string& caption_html,
                       const std::string& missing_note_html) {
  std::error_code error;
  if (!std::filesystem::exists(png_path, error)) return MissingHtml(missing_note_html);
  std::ifstream in(png_path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return fmt::format(
      "<figure><img src=\"data:image/png;base64,{}\" alt=\"{}\"><figcaption>{}</figcaption>"
      "</figure>\n",
      Base64(bytes.str()), HtmlEscape(std::filesystem::path(png_path).filename().string()),
      caption_html);
}

std::string CompareClass(const ComparedColumn& column, std::optional<double> ours,
                         std::optional<double> paper) {
  if (!ours || !paper) return "";
  const double diff = *ours - *paper;
  const double tolerance = column.relative ? column.tolerance * std::abs(*paper) : column.tolerance;
  if (std::abs(diff) <= tolerance + 1e-12) return "";
  switch (column.better) {
    case Better::kHigher:
      return diff > 0 ? "better" : "worse";
    case Better::kLower:
      return diff < 0 ? "better" : "worse";
    case Better::kNone:
      return "differs";
  }
  return "";
}

std::string ComparisonTableHtml(const std::string& anchor, const std::string& title_html,
                                const std::string& caption_html,
                                const std::vector<ComparedColumn>& columns,
                                const std::vector<ComparedGroup>& groups) {
  std::string html = fmt::format("<h3 id=\"{}\">{}</h3>\n", anchor, title_html);
  html += "<table class=\"compare\">\n<thead><tr><th>data set</th><th></th>";
  for (const ComparedColumn& column : columns) html += "<th>" + HtmlEscape(column.header) + "</th>";
  html += "</tr></thead>\n<tbody>\n";
  for (const ComparedGroup& group : groups) {
    const std::size_t rows = 1 + group.ours.size();
    html += fmt::format("<tr class=\"paper\"><th rowspan=\"{}\">{}</th><td>paper</td>", rows,
                        HtmlEscape(group.name));
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const auto value = c < group.paper.size() ? group.paper[c] : std::nullopt;
      html +=
          "<td>" + (value ? FormatValue(*value, columns[c].digits) : std::string("–")) + "</td>";
    }
    html += "</tr>\n";
    for (const OursRow& row : group.ours) {
      html += "<tr class=\"ours\"><td>" + row.label_html + "</td>";
      if (!row.missing_html.empty()) {
        html += fmt::format("<td colspan=\"{}\" class=\"missing\">not computed: {}</td></tr>\n",
                            columns.size(), row.missing_html);
        continue;
      }
      for (std::size_t c = 0; c < columns.size(); ++c) {
        const auto ours = c < row.values.size() ? row.values[c] : std::nullopt;
        const auto paper = c < group.paper.size() ? group.paper[c] : std::nullopt;
        const std::string verdict = CompareClass(columns[c], ours, paper);
        html += verdict.empty() ? "<td>" : "<td class=\"" + verdict + "\">";
        if (!ours) {
          html += "–</td>";
          continue;
        }
        html += FormatValue(*ours, columns[c].digits);
        if (paper) {
          const double diff = *ours - *paper;
          html += fmt::format("<br><span class=\"diff\">{}{}", diff >= 0 ? "+" : "−",
                              FormatValue(std::abs(diff), columns[c].digits));
          if (std::abs(*paper) > 1e-12) {
            const double percent = 100.0 * diff / std::abs(*paper);
            html += fmt::format(" ({}{:.0f} %)", percent < -0.5 ? "−" : "+", std::abs(percent));
          }
          html += "</span>";
        }
        html += "</td>";
      }
      html += "</tr>\n";
    }
  }
  html += "</tbody>\n</table>\n";
  std::string rules;
  for (const ComparedColumn& column : columns) {
    if (!rules.empty()) rules += "; ";
    rules += HtmlEscape(column.header) + ": ";
    switch (column.better) {
      case Better::kHigher:
        rules += "higher is better, ± " + ToleranceText(column);
        break;
      case Better::kLower:
        rules += "lower is better, ± " + ToleranceText(column);
        break;
      case Better::kNone:
        rules += "differs beyond ± " + ToleranceText(column);
        break;
    }
  }
  html += "<p class=\"caption\">" + caption_html +
          " Under each of our values: ours − paper (and in % of the paper's). Colours: "
          "<span class=\"better\">better</span>, <span class=\"worse\">worse</span>, "
          "<span class=\"differs\">differs</span> than the paper beyond the tolerance (" +
          rules + ").</p>\n";
  return html;
}

const char* ReportCss() {
  return R"css(
body { font-family: sans-serif; max-width: 1250px; margin: 1em auto; padding: 0 1em;
       color: #222; line-height: 1.4; }
h1 { border-bottom: 2px solid #444; }
h2 { border-bottom: 1px solid #aaa; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: right; vertical-align: top; }
th { background: #eee; }
td:first-child, th:first-child, td.text { text-align: left; }
table.compare td:nth-child(2) { text-align: left; }
tr.paper td { background: #f6f6f6; color: #444; }
tr.ours td:first-child { text-align: left; }
.diff { font-size: 0.8em; color: #555; }
.better { background: #d4f4d4; }
.worse { background: #f8d0d0; }
.differs { background: #fbe9b7; }
.missing { background: #fff3f3; border: 1px dashed #c66; padding: 4px 8px; color: #933;
           text-align: left; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #ccc; }
figcaption, p.caption { font-size: 0.9em; color: #444; }
code, pre { background: #f4f4f4; font-size: 0.85em; }
pre { padding: 0.5em; overflow-x: auto; white-space: pre-wrap; }
.grid3 { display: grid; grid-template-columns: repeat(3, 1fr); gap: 8px; }
.grid2 { display: grid; grid-template-columns: repeat(2, 1fr); gap: 8px; }
.state-failed { color: #b00; font-weight: bold; }
.state-skipped { color: #a60; }
)css";
}

}  // namespace keyplace::cli
