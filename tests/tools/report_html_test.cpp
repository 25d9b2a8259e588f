// Unit tests of the report's building blocks: Base64, HTML escaping, the verdict of a compared
// cell, the comparison table, chart ticks and the PNG chart writer.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "plot_chart.hpp"
#include "report_html.hpp"

namespace keyplace::cli {
namespace {

TEST(ReportHtmlTest, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(ReportHtmlTest, EscapesMarkup) {
  EXPECT_EQ(HtmlEscape("a<b>&\"c\""), "a&lt;b&gt;&amp;&quot;c&quot;");
}

TEST(ReportHtmlTest, VerdictFollowsDirectionAndTolerance) {
  const ComparedColumn higher{"recall", Better::kHigher, 0.02, false, 3};
  EXPECT_EQ(CompareClass(higher, 0.75, 0.71), "better");
  EXPECT_EQ(CompareClass(higher, 0.60, 0.71), "worse");
  EXPECT_EQ(CompareClass(higher, 0.72, 0.71), "");  // within 0.02
  EXPECT_EQ(CompareClass(higher, std::nullopt, 0.71), "");
  EXPECT_EQ(CompareClass(higher, 0.7, std::nullopt), "");
  const ComparedColumn lower{"time", Better::kLower, 0.1, true, 3};
  EXPECT_EQ(CompareClass(lower, 0.05, 0.1), "better");
  EXPECT_EQ(CompareClass(lower, 0.2, 0.1), "worse");
  EXPECT_EQ(CompareClass(lower, 0.105, 0.1), "");  // within 10 %
  const ComparedColumn neutral{"#submaps", Better::kNone, 0.2, true, 0};
  EXPECT_EQ(CompareClass(neutral, 130, 100), "differs");
  EXPECT_EQ(CompareClass(neutral, 70, 100), "differs");
  EXPECT_EQ(CompareClass(neutral, 110, 100), "");
}

TEST(ReportHtmlTest, TablePutsOursBesidePaperWithDifference) {
  const std::vector<ComparedColumn> columns{{"recall", Better::kHigher, 0.02, false, 2}};
  OursRow ours{"keyplace", {0.98}, ""};
  OursRow missing{"other", {}, "run <code>x</code>"};
  const std::string html =
      ComparisonTableHtml("t", "T", "caption.", columns, {{"FR079", {0.71}, {ours, missing}}});
  EXPECT_NE(html.find("<td>paper</td><td>0.71</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<td class=\"better\">0.98<br><span class=\"diff\">+0.27 (+38 %)"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("not computed: run <code>x</code>"), std::string::npos) << html;
  EXPECT_NE(html.find("higher is better, ± 0.02"), std::string::npos) << html;
}

TEST(ReportHtmlTest, MissingFigureIsANote) {
  const std::string html = FigureHtml("/nonexistent/figure.png", "caption", "run <code>y</code>");
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_NE(html.find("not computed: run <code>y</code>"), std::string::npos);
}

TEST(PlotChartTest, NiceTicksCoverTheRange) {
  const std::vector<double> unit = NiceTicks(0.0, 1.0, 5);
  const std::vector<double> expected{0.0, 0.2, 0.4, 0.6, 0.8, 1.0};
  ASSERT_EQ(unit.size(), expected.size());
  for (std::size_t i = 0; i < unit.size(); ++i) EXPECT_NEAR(unit[i], expected[i], 1e-12);
  const std::vector<double> ticks = NiceTicks(3.0, 487.0, 5);
  ASSERT_GE(ticks.size(), 2u);
  EXPECT_LE(ticks.front(), 3.0);
  EXPECT_GE(ticks.back(), 487.0);
  EXPECT_DOUBLE_EQ(ticks[1] - ticks[0], 100.0);
  EXPECT_EQ(NiceTicks(2.0, 2.0, 5), (std::vector<double>{2.0}));
}

TEST(PlotChartTest, WritesAPngAndRejectsMismatchedSeries) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "keyplace_plot_chart_test.png").string();
  Chart chart{"t", "x", "y", {{"a", {0, 1, 2}, {1, NAN, 3}}}, std::nullopt, std::nullopt};
  DrawCharts(path, "title", {chart, chart}, 2);
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::filesystem::remove(path);
  chart.series[0].y.pop_back();
  EXPECT_THROW(DrawCharts(path, "title", {chart}, 1), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace keyplace::cli
