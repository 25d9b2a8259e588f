#include "keyplace/mapping/stability_grid.hpp"

#include <cstdint>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/features/descriptor.hpp"

namespace keyplace {
namespace {

MappingConfig UnitCells(
    MappingConfig::DensityCounting counting = MappingConfig::DensityCounting::kBeams) {
  MappingConfig config;
  config.cell_size_m = 1.0;  // easy hand computation
  config.density_counting = counting;
  return config;
}

BetaGridDescriptor Uniform() {
  BetaGridDescriptor d;
  d.fill(1.0f / kBetaGridBins);
  return d;
}

// Mass w in bin 0 and 1 - w in bin 1: chi2(Mix(1), Mix(0.5)) = 1/3 < 0.4 but chi2(Mix(1),
// Mix(0)) = 1, and chi2(Mix(1), Uniform()) is about 0.96.
BetaGridDescriptor Mix(float w) {
  BetaGridDescriptor d{};
  d[0] = w;
  d[1] = 1.0f - w;
  return d;
}
BetaGridDescriptor Peaked(float tweak = 0.0f) { return Mix(1.0f - tweak); }

GridKeypoint At(double x, double y, int scan, const BetaGridDescriptor& descriptor) {
  GridKeypoint keypoint;
  keypoint.position_m = {x, y};
  keypoint.scan_index = scan;
  keypoint.descriptor = descriptor;
  return keypoint;
}

TEST(StabilityGrid, StraightRayCountsMissesThenHit) {
  StabilityGrid grid(UnitCells());
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}}, 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(grid.Counts({i, 0}).misses, 1) << i;
    EXPECT_EQ(grid.Counts({i, 0}).hits, 0) << i;
  }
  EXPECT_EQ(grid.Counts({3, 0}).hits, 1);
  EXPECT_EQ(grid.Counts({3, 0}).misses, 0);
  EXPECT_EQ(grid.Counts({3, 0}).scans_hit, 1);
  EXPECT_EQ(grid.Counts({4, 0}).hits + grid.Counts({4, 0}).misses, 0);
  EXPECT_EQ(grid.hit_cell_count(), 1);
  EXPECT_EQ(grid.observed_cell_count(), 4);
}

TEST(StabilityGrid, ObservedCellsAreTheCrossedAndHitCells) {
  StabilityGrid grid(UnitCells());
  grid.InsertRays({0.5, 0.5}, {{2.5, 1.5}, {0.5, -1.5}}, 0);
  const std::vector<CellIndex> observed = grid.ObservedCells();
  // Row by row: (0,-2) hit, (0,-1) crossed; (0,0) (1,0) crossed; (1,1) crossed, (2,1) hit.
  const std::vector<CellIndex> expected{{0, -2}, {0, -1}, {0, 0}, {1, 0}, {1, 1}, {2, 1}};
  ASSERT_EQ(observed.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(observed[k].i, expected[k].i) << k;
    EXPECT_EQ(observed[k].j, expected[k].j) << k;
  }
  EXPECT_EQ(static_cast<std::int64_t>(observed.size()), grid.observed_cell_count());
  EXPECT_EQ(grid.HitCells().size(), 2u);
}

// The counters are allocated in tiles where beams pass; each cell keeps its own, on both sides of
// zero, across the grid's growth (beams of 150 cells outgrow its margin of 64), and the observed
// cells come row by row whatever the tiles.
TEST(StabilityGrid, EveryCellKeepsItsOwnCountersAcrossTilesAndGrowth) {
  StabilityGrid grid(UnitCells());
  grid.InsertRays({0.5, 0.5}, {{150.5, 0.5}}, 0);   // cells 1 .. 149 crossed, 150 hit
  grid.InsertRays({0.5, 0.5}, {{-149.5, 0.5}}, 1);  // cells -1 .. -149 crossed, -150 hit
  grid.InsertRays({0.5, 0.5}, {{0.5, -99.5}, {0.5, 120.5}}, 2);
  EXPECT_GE(grid.allocated_cell_count(), 300 * 220);
  for (const int i : {-150, 150}) EXPECT_EQ(grid.Counts({i, 0}).hits, 1) << i;
  for (const int i : {-149, -17, -16, -15, -1, 1, 15, 16, 17, 149}) {
    EXPECT_EQ(grid.Counts({i, 0}).misses, 1) << i;
    EXPECT_EQ(grid.Counts({i, 0}).hits, 0) << i;
  }
  EXPECT_EQ(grid.Counts({0, 0}).misses, 4);  // every beam leaves from it
  for (const int j : {-100, 120}) EXPECT_EQ(grid.Counts({0, j}).hits, 1) << j;
  for (const int j : {-99, -16, -1, 1, 16, 119}) EXPECT_EQ(grid.Counts({0, j}).misses, 1) << j;
  EXPECT_EQ(grid.Counts({1, 1}).misses + grid.Counts({-1, -1}).misses, 0);
  EXPECT_EQ(grid.Counts({-150, 1}).hits + grid.Counts({1, 120}).hits, 0);

  const std::vector<CellIndex> observed = grid.ObservedCells();
  EXPECT_EQ(static_cast<std::int64_t>(observed.size()), grid.observed_cell_count());
  EXPECT_EQ(observed.size(), std::size_t{301 + 100 + 120});
  for (std::size_t k = 1; k < observed.size(); ++k) {
    const bool row_by_row =
        observed[k - 1].j < observed[k].j ||
        (observed[k - 1].j == observed[k].j && observed[k - 1].i < observed[k].i);
    EXPECT_TRUE(row_by_row) << k;
  }
  const std::vector<CellIndex> hits = grid.HitCells();
  ASSERT_EQ(hits.size(), 4u);
  EXPECT_EQ(hits[0].j, -100);
  EXPECT_EQ(hits[1].i, -150);
  EXPECT_EQ(hits[2].i, 150);
  EXPECT_EQ(hits[3].j, 120);
}

TEST(StabilityGrid, DiagonalRayVisitsCellsInCrossingOrder) {
  StabilityGrid grid(UnitCells());
  // From (0.5, 0.5) to (2.5, 1.5): crosses x = 1 at t = 0.25, y = 1 at t = 0.5, x = 2 at 0.75.
  grid.InsertRays({0.5, 0.5}, {{2.5, 1.5}}, 0);
  EXPECT_EQ(grid.Counts({0, 0}).misses, 1);
  EXPECT_EQ(grid.Counts({1, 0}).misses, 1);
  EXPECT_EQ(grid.Counts({1, 1}).misses, 1);
  EXPECT_EQ(grid.Counts({2, 1}).hits, 1);
  EXPECT_EQ(grid.Counts({0, 1}).misses, 0);
  EXPECT_EQ(grid.Counts({2, 0}).misses, 0);
}

TEST(StabilityGrid, ScansHitCountsEachScanOnce) {
  StabilityGrid grid(UnitCells());
  grid.InsertRays({0.5, 0.5}, {{3.2, 0.5}, {3.8, 0.7}}, 0);  // two beams of one scan
  EXPECT_EQ(grid.Counts({3, 0}).hits, 2);
  EXPECT_EQ(grid.Counts({3, 0}).scans_hit, 1);
  grid.InsertRays({-5.5, 0.5}, {{3.5, 0.5}}, 1);  // grows the grid to negative cells
  EXPECT_EQ(grid.Counts({3, 0}).hits, 3);
  EXPECT_EQ(grid.Counts({3, 0}).scans_hit, 2);
  EXPECT_EQ(grid.Counts({-6, 0}).misses, 1);
  EXPECT_EQ(grid.Counts({0, 0}).misses, 3);  // two beams of scan 0, one of scan 1
}

TEST(StabilityGrid, PerScanCountingCountsEachCellOncePerScan) {
  StabilityGrid grid(UnitCells(MappingConfig::DensityCounting::kScans));
  grid.InsertRays({0.5, 0.5}, {{3.2, 0.5}, {3.8, 0.7}, {5.5, 0.5}}, 0);
  // Two beams end in (3, 0) and a third crosses it: one hit, no miss for this scan.
  EXPECT_EQ(grid.Counts({3, 0}).hits, 1);
  EXPECT_EQ(grid.Counts({3, 0}).misses, 0);
  EXPECT_EQ(grid.Counts({0, 0}).misses, 1);  // crossed by three beams of one scan
  grid.InsertRays({0.5, 0.5}, {{5.5, 0.5}}, 1);
  EXPECT_EQ(grid.Counts({3, 0}).hits, 1);
  EXPECT_EQ(grid.Counts({3, 0}).misses, 1);  // scan 1 only crosses it
  EXPECT_EQ(grid.Counts({5, 0}).hits, 2);
  EXPECT_EQ(grid.Counts({5, 0}).scans_hit, 2);
  EXPECT_EQ(grid.Counts({0, 0}).misses, 2);
}

TEST(StabilityGrid, ClustersGroupSimilarDescriptorsLargestFirst) {
  StabilityGrid grid(UnitCells());
  ASSERT_GT(SymmetricChi2(Uniform(), Peaked()), 0.4);
  ASSERT_LT(SymmetricChi2(Peaked(), Peaked(0.01f)), 0.4);
  grid.InsertKeypoint(At(3.5, 0.5, 0, Uniform()));
  grid.InsertKeypoint(At(3.4, 0.6, 1, Peaked()));
  auto clusters = grid.Clusters({3, 0});
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0][0].scan_index, 0);  // equal sizes keep their order
  grid.InsertKeypoint(At(3.6, 0.4, 2, Peaked(0.01f)));
  clusters = grid.Clusters({3, 0});
  ASSERT_EQ(clusters.size(), 2u);
  ASSERT_EQ(clusters[0].size(), 2u);  // the peaked cluster grew and moved first
  EXPECT_EQ(clusters[0][0].scan_index, 1);
  EXPECT_EQ(clusters[0][1].scan_index, 2);
  EXPECT_EQ(clusters[1][0].scan_index, 0);
  EXPECT_TRUE(grid.Clusters({0, 0}).empty());
}

TEST(StabilityGrid, StabilityAndSelectionMatchHandComputation) {
  StabilityGrid grid(UnitCells());
  // Cell (3, 0): 3 hits in 3 scans and 1 miss (a ray to (5.5, 0.5) crosses it).
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}}, 0);
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}}, 1);
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}, {5.5, 0.5}}, 2);
  ASSERT_EQ(grid.Counts({3, 0}).hits, 3);
  ASSERT_EQ(grid.Counts({3, 0}).misses, 1);
  ASSERT_EQ(grid.Counts({3, 0}).scans_hit, 3);
  grid.InsertKeypoint(At(3.5, 0.5, 0, Peaked()));
  grid.InsertKeypoint(At(3.5, 0.5, 1, Uniform()));
  grid.InsertKeypoint(At(3.5, 0.5, 2, Peaked(0.01f)));
  // d = 3/4, occ = 2, ns = max(3, ns_min = 4) = 4: s = 0.75 * 2 / 4 = 0.375.
  EXPECT_DOUBLE_EQ(grid.Stability({3, 0}), 0.375);
  // Cell (5, 0): 1 hit, 0 misses, 1 keypoint: s = 1 * 1 / 4 = 0.25 < s_min = 0.3.
  grid.InsertKeypoint(At(5.5, 0.5, 2, Uniform()));
  EXPECT_DOUBLE_EQ(grid.Stability({5, 0}), 0.25);
  const auto selected = grid.SelectStable();
  ASSERT_EQ(selected.size(), 1u);
  EXPECT_EQ(selected[0].keypoint.scan_index, 2);  // most recent of the largest cluster
  EXPECT_EQ(selected[0].occurrences, 2);
  EXPECT_DOUBLE_EQ(selected[0].stability, 0.375);
}

TEST(StabilityGrid, PerScanDensityIgnoresMissesFromTheScanThatHits) {
  StabilityGrid grid(UnitCells(MappingConfig::DensityCounting::kScans));
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}}, 0);
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}}, 1);
  grid.InsertRays({0.5, 0.5}, {{3.5, 0.5}, {5.5, 0.5}}, 2);
  grid.InsertKeypoint(At(3.5, 0.5, 0, Peaked()));
  grid.InsertKeypoint(At(3.5, 0.5, 2, Peaked(0.01f)));
  // h = 3 (one per scan), m = 0: d = 1, occ = 2, ns = max(3, 4): s = 0.5.
  EXPECT_DOUBLE_EQ(grid.Stability({3, 0}), 0.5);
}

TEST(StabilityGrid, LatestMemberMatchingComparesOnlyTheNewestKeypoint) {
  MappingConfig config = UnitCells();
  config.cluster_match = MappingConfig::ClusterMatch::kLatestMember;
  StabilityGrid latest(config);
  StabilityGrid any(UnitCells());
  // A chain a -> b -> c where a~b, b~c, but a and c are far apart: with kLatestMember, c joins
  // (newest b); with kAnyMember it joins as well (b is a member). Then d ~ a only: joins with
  // kAnyMember (a is a member) but not with kLatestMember (newest is c).
  const BetaGridDescriptor a = Mix(1.0f), b = Mix(0.5f), c = Mix(0.0f);
  ASSERT_LT(SymmetricChi2(a, b), 0.4);
  ASSERT_LT(SymmetricChi2(b, c), 0.4);
  for (auto* grid : {&latest, &any}) {
    grid->InsertKeypoint(At(0.5, 0.5, 0, a));
    grid->InsertKeypoint(At(0.5, 0.5, 1, b));
    grid->InsertKeypoint(At(0.5, 0.5, 2, c));
  }
  const BetaGridDescriptor d = Mix(1.0f);
  ASSERT_LT(SymmetricChi2(a, d), 0.4);
  ASSERT_GT(SymmetricChi2(c, d), 0.4);
  latest.InsertKeypoint(At(0.5, 0.5, 3, d));
  any.InsertKeypoint(At(0.5, 0.5, 3, d));
  EXPECT_EQ(latest.Clusters({0, 0}).size(), 2u);
  EXPECT_EQ(any.Clusters({0, 0}).size(), 1u);
}

// Evaluated by the compiler: undefined behaviour is a compile error in a constant expression, so
// the former `(std::int64_t{i} << 32) ^ std::uint32_t(j)` (a left shift of a negative value)
// does not compile here. The values are those of the former key (maps stay byte-identical).
static_assert(CellKey(0, 0) == 0);
static_assert(CellKey(3, 5) == (std::int64_t{3} << 32) + 5);
static_assert(CellKey(0, -1) == 0xFFFFFFFFLL);
static_assert(CellKey(-1, 0) == static_cast<std::int64_t>(0xFFFFFFFF00000000ULL));
static_assert(CellKey(-1, -1) == -1);
static_assert(CellKey(-2, 7) == static_cast<std::int64_t>(0xFFFFFFFE00000007ULL));
static_assert(CellKey(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()) ==
              static_cast<std::int64_t>(0x800000007FFFFFFFULL));

TEST(StabilityGrid, NegativeCellsHaveDistinctKeysAndHistories) {
  std::set<std::int64_t> keys;
  for (int i = -40; i <= 40; ++i) {
    for (int j = -40; j <= 40; ++j) keys.insert(CellKey(i, j));
  }
  EXPECT_EQ(keys.size(), 81u * 81u);
  // Keypoints in the four quadrants around the origin land in four histories.
  StabilityGrid grid(UnitCells());
  grid.InsertKeypoint(At(-0.5, -0.5, 0, Uniform()));
  grid.InsertKeypoint(At(-0.5, 0.5, 0, Uniform()));
  grid.InsertKeypoint(At(0.5, -0.5, 0, Uniform()));
  grid.InsertKeypoint(At(0.5, 0.5, 0, Uniform()));
  grid.InsertKeypoint(At(-0.4, -0.6, 1, Uniform()));
  EXPECT_EQ(grid.Clusters({-1, -1}).front().size(), 2u);
  EXPECT_EQ(grid.Clusters({-1, 0}).front().size(), 1u);
  EXPECT_EQ(grid.Clusters({0, -1}).front().size(), 1u);
  EXPECT_EQ(grid.Clusters({0, 0}).front().size(), 1u);
}

TEST(MappingConfig, RejectsInvalidFieldsByName) {
  MappingConfig config;
  config.cell_size_m = 0.0;
  try {
    StabilityGrid grid(config);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("cell_size_m"), std::string::npos);
  }
  MappingConfig parsed;
  EXPECT_THROW(ApplyKeyValues({{"no_such_key", "1"}}, parsed), std::invalid_argument);
  EXPECT_THROW(ApplyKeyValues({{"min_stability", "abc"}}, parsed), std::invalid_argument);
  ApplyKeyValues({{"min_stability", "0.5"}, {"overlap_cells", "observed"}}, parsed);
  EXPECT_DOUBLE_EQ(parsed.min_stability, 0.5);
  EXPECT_EQ(parsed.overlap_cells, MappingConfig::OverlapCells::kObserved);
}

// A cell side of 0.001 m or inf used to pass "positive" (and came back from a map file's config
// table), then exhausted memory in localize; every real field must now be finite.
TEST(MappingConfig, CellSidesAreBoundedAndRealFieldsFinite) {
  const auto rejected = [](const std::string& key, const std::string& value) {
    MappingConfig config;
    try {
      ApplyKeyValues({{key, value}}, config);
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("MappingConfig." + key), std::string::npos)
          << error.what();
      return true;
    }
    return false;
  };
  for (const char* value : {"0.001", "0.0099", "10.01", "inf", "-inf", "nan", "0", "-0.1"}) {
    EXPECT_TRUE(rejected("cell_size_m", value)) << value;
  }
  for (const char* value : {"0.001", "100.5", "inf", "nan"}) {
    EXPECT_TRUE(rejected("distribution_cell_m", value)) << value;
  }
  for (const char* key : {"min_stability", "descriptor_match_chi2", "max_distribution"}) {
    EXPECT_TRUE(rejected(key, "inf")) << key;
    EXPECT_TRUE(rejected(key, "nan")) << key;
  }
  EXPECT_TRUE(rejected("max_grid_cells", "268435457"));  // 2^28 + 1
  EXPECT_TRUE(rejected("max_grid_cells", "0"));
  // The bounds themselves are valid, as are the paper's values and the sweep's l_g.
  for (const char* value : {"0.01", "0.05", "0.1", "0.15", "10"}) {
    EXPECT_FALSE(rejected("cell_size_m", value)) << value;
  }
  EXPECT_FALSE(rejected("distribution_cell_m", "100"));
  EXPECT_FALSE(rejected("max_grid_cells", "268435456"));
}

}  // namespace
}  // namespace keyplace
