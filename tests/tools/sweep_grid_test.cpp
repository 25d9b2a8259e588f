// Value lists, grid expansion and the resumable results file of keyplace sweep.

#include "sweep_grid.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace::cli {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParseValueList(text, "--x");
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(ParseValueList, RangeIncludesTheEndAndRoundsValues) {
  const std::vector<double> values = ParseValueList("0:1:0.1", "--x");
  ASSERT_EQ(values.size(), 11u);
  EXPECT_EQ(values[3], 0.3);
  EXPECT_EQ(values[10], 1.0);
  EXPECT_EQ(ParseValueList("0.05:0.15:0.05", "--x"), (std::vector<double>{0.05, 0.1, 0.15}));
  EXPECT_EQ(ParseValueList("5:20:5", "--x"), (std::vector<double>{5, 10, 15, 20}));
  EXPECT_EQ(ParseValueList("2:2:1", "--x"), (std::vector<double>{2}));
}

TEST(ParseValueList, ListsAndSingleValues) {
  EXPECT_EQ(ParseValueList("0.05,0.1,0.15", "--x"), (std::vector<double>{0.05, 0.1, 0.15}));
  EXPECT_EQ(ParseValueList(" 0.4 ", "--x"), (std::vector<double>{0.4}));
  EXPECT_EQ(ParseValueList("-1,2", "--x"), (std::vector<double>{-1, 2}));
}

TEST(ParseValueList, ClearErrors) {
  EXPECT_NE(ErrorOf("").find("--x: empty value list"), std::string::npos);
  EXPECT_NE(ErrorOf("0:1").find("expected A:B:STEP"), std::string::npos);
  EXPECT_NE(ErrorOf("0:1:0").find("STEP must be > 0"), std::string::npos);
  EXPECT_NE(ErrorOf("1:0:0.1").find("B is below A"), std::string::npos);
  EXPECT_NE(ErrorOf("0.1,abc").find("'abc' is not a number"), std::string::npos);
  EXPECT_NE(ErrorOf("0.1,").find("'' is not a number"), std::string::npos);
  EXPECT_NE(ErrorOf("0.1,0.1").find("appears twice"), std::string::npos);
  EXPECT_NE(ErrorOf("0:1:1e-9").find("more than"), std::string::npos);
  EXPECT_NE(ErrorOf("nan").find("not a number"), std::string::npos);
}

TEST(ExpandGrid, FirstAxisSlowest) {
  const auto grid = ExpandGrid({{"a", {1, 2}}, {"b", {10, 20, 30}}});
  ASSERT_EQ(grid.size(), 6u);
  EXPECT_EQ(grid[0], (std::vector<double>{1, 10}));
  EXPECT_EQ(grid[2], (std::vector<double>{1, 30}));
  EXPECT_EQ(grid[3], (std::vector<double>{2, 10}));
  EXPECT_EQ(PointKey({0.3, 0.05, 10}), "0.3,0.05,10");
}

TEST(SweepResults, ResumesDropsTornLineAndRefusesOtherSweeps) {
  const auto dir = std::filesystem::temp_directory_path() / "keyplace_sweep_results_test";
  std::filesystem::remove_all(dir);
  const nlohmann::json identity = {{"sweep", "t"}, {"log", "a.log"}};
  {
    SweepResults results(dir.string(), identity, {"p"}, {"v"});
    results.Add({0.3}, {1.5});
    results.Add({0.1}, {2.5});
  }
  {  // an interrupted write
    std::ofstream csv(dir / "results.csv", std::ios::app);
    csv << "0.2,3";
  }
  {
    SweepResults results(dir.string(), identity, {"p"}, {"v"});
    EXPECT_EQ(results.size(), 2u);
    EXPECT_TRUE(results.Has({0.3}));
    EXPECT_FALSE(results.Has({0.2}));
    results.Add({0.2}, {4});
    const auto rows = results.SortedRows();
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0], (std::vector<double>{0.1, 2.5}));
  }
  std::ifstream csv(dir / "results.csv");
  std::string text((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "p,v\n0.1,2.5\n0.3,1.5\n0.2,4\n");
  try {
    SweepResults other(dir.string(), {{"sweep", "t"}, {"log", "b.log"}}, {"p"}, {"v"});
    ADD_FAILURE() << "a different sweep was opened";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'log' is \"b.log\" here but \"a.log\" there"),
              std::string::npos)
        << error.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(SweepResults, SortLeavesTheRowsInPointOrderWhateverOrderTheyFinishedIn) {
  const auto dir = std::filesystem::temp_directory_path() / "keyplace_sweep_sort_test";
  std::filesystem::remove_all(dir);
  const auto text_of = [&] {
    std::ifstream csv(dir / "results.csv");
    return std::string((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  };
  SweepResults results(dir.string(), {{"sweep", "t"}}, {"p", "q"}, {"v"});
  results.Add({0.3, 1}, {1.5});
  results.Add({0.1, 2}, {2.5});
  results.Add({0.1, 1}, {3.5});
  EXPECT_EQ(text_of(), "p,q,v\n0.3,1,1.5\n0.1,2,2.5\n0.1,1,3.5\n");
  results.Sort();
  EXPECT_EQ(text_of(), "p,q,v\n0.1,1,3.5\n0.1,2,2.5\n0.3,1,1.5\n");
  results.Add({0.2, 1}, {4});  // still appends to the rewritten file
  EXPECT_EQ(text_of(), "p,q,v\n0.1,1,3.5\n0.1,2,2.5\n0.3,1,1.5\n0.2,1,4\n");
  results.Sort();
  EXPECT_EQ(text_of(), "p,q,v\n0.1,1,3.5\n0.1,2,2.5\n0.2,1,4\n0.3,1,1.5\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace keyplace::cli
