#include "keyplace/io/relations.hpp"

#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string WriteTemp(const std::string& name, const std::string& content) {
  const std::string path = keyplace::testing::MakeTempDir("relations") + "/" + name;
  std::ofstream(path) << content;
  return path;
}

TEST(RelationsTest, ParsesLinesAndSkipsCommentsAndBlanks) {
  const std::string path = WriteTemp("a.relations",
                                     "# comment\n"
                                     "976052905.167303 976052911.885496 -0.056990 -0.128430 "
                                     "0.000000 0.000000 0.000000 -1.682210\n"
                                     "\n"
                                     "10.5 12.25 1 2 0 0 0 3.5\r\n");
  const std::vector<Relation> relations = ReadRelations(path);
  ASSERT_EQ(relations.size(), 2u);
  EXPECT_DOUBLE_EQ(relations[0].timestamp_a_s, 976052905.167303);
  EXPECT_DOUBLE_EQ(relations[0].timestamp_b_s, 976052911.885496);
  EXPECT_DOUBLE_EQ(relations[0].T_a_b.x, -0.056990);
  EXPECT_DOUBLE_EQ(relations[0].T_a_b.y, -0.128430);
  EXPECT_DOUBLE_EQ(relations[0].T_a_b.theta, -1.682210);
  EXPECT_EQ(relations[0].line, 2u);
  EXPECT_EQ(relations[1].line, 4u);
  EXPECT_NEAR(relations[1].T_a_b.theta, 3.5 - 2 * M_PI, 1e-12);  // wrapped
}

TEST(RelationsTest, MalformedLinesNameFileLineAndField) {
  const std::string few = WriteTemp("few.relations", "1 2 3 4 5 6 7 8\n1 2 3\n");
  try {
    ReadRelations(few);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find(few + ":2"), std::string::npos) << what;
    EXPECT_NE(what.find("8 fields"), std::string::npos) << what;
  }
  const std::string bad = WriteTemp("bad.relations", "1 2 3 4 5 6 7 x8\n");
  try {
    ReadRelations(bad);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find(bad + ":1"), std::string::npos) << what;
    EXPECT_NE(what.find("dyaw"), std::string::npos) << what;
  }
  EXPECT_THROW(ReadRelations("/nonexistent/file.relations"), std::runtime_error);
}

TEST(RelationsTest, IndexPairsWithHeader) {
  const std::string path = WriteTemp("map.tsv", "raw_index\tcorrected_index\n3541\t0\n3544\t1\n");
  const std::vector<IndexPair> pairs = ReadIndexPairs(path);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[1].raw_index, 3544u);
  EXPECT_EQ(pairs[1].corrected_index, 1u);
  const std::string bad = WriteTemp("bad.tsv", "raw_index\tcorrected_index\n3541\t-1\n");
  try {
    ReadIndexPairs(bad);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("corrected_index"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find(":2"), std::string::npos);
  }
}

TEST(RelationsTest, SharedRelationFilesParse) {
  const std::vector<Relation> intel =
      ReadRelations(keyplace::testing::SharedFile("data/intel.relations"));
  const std::vector<Relation> fr079 =
      ReadRelations(keyplace::testing::SharedFile("data/fr079.relations"));
  EXPECT_EQ(intel.size(), 2984u);
  EXPECT_EQ(fr079.size(), 1685u);
  const std::vector<IndexPair> pairs =
      ReadIndexPairs(keyplace::testing::SharedFile("data/intel-raw-to-corrected.tsv"));
  EXPECT_EQ(pairs.size(), 2672u);
  EXPECT_EQ(pairs.front().raw_index, 3541u);
}

}  // namespace
}  // namespace keyplace
