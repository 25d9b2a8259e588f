// MappingStats' figure table: what the JSON of `keyplace map`, `info` and `slam` and Python's
// MappingStats are written from.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "keyplace/mapping/global_map.hpp"
#include "support/result_fields_checks.hpp"

namespace keyplace {
namespace {

TEST(MappingStatsFields, EachFigureReadsItsOwnMember) {
  MappingStats s;
  s.compression = 0.5;
  s.scans_per_submap = 1.5;
  s.keypoints_per_submap = 2.5;
  s.distribution = 0.25;
  s.submaps = 1;
  s.forced_submaps = 2;
  s.median_path_m = 3.5;
  s.median_extent_m = 4.5;
  s.max_path_m = 5.5;
  s.max_extent_m = 6.5;
  s.path_bound_submaps = 3;
  s.stable_keypoints = 4;
  s.source_keypoints = 5;
  s.configuration = "not a figure";
  const ResultFields<MappingStats>& fields = MappingStatsFields();
  ExpectWellFormed(fields, s);
  EXPECT_EQ(fields.fields().size(), 13u);  // every member but the configuration
  EXPECT_EQ(ValueOf(fields, s, "median_extent_m"), ResultValue(4.5));
  EXPECT_EQ(ValueOf(fields, s, "forced_submaps"), ResultValue(std::int64_t{2}));
  EXPECT_EQ(ValueOf(fields, s, "compression"), ResultValue(0.5));
}

}  // namespace
}  // namespace keyplace
