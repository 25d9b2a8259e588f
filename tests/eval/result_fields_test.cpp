// The figure tables of the evaluation summaries (keyplace/common/result_fields.hpp): what the
// JSON of `keyplace localize` / `relocalize` and the Python properties are written from.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <variant>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "support/result_fields_checks.hpp"

namespace keyplace {
namespace {

TEST(ResultFields, RelocalizationSummaryFiguresReadTheirOwnMembers) {
  RelocalizationSummary s;
  s.starts = 1;
  s.starts_with_revisit = 2;
  s.fixed = 3;
  s.fixed_with_revisit = 4;
  s.fixed_fraction = 0.5;
  s.fixes = 5;
  s.wrong_fixes = 6;
  s.wrong_fix_rate = 0.25;
  s.wrong_first_fixes = 7;
  s.wrong_fix_confident = true;
  s.wrong_fix_confidence_max = 0.75;
  s.distance_to_fix_median_m = 1.5;
  s.distance_to_fix_p90_m = 2.5;
  s.scans_to_fix_median = 3.5;
  s.distance_after_revisit_median_m = 4.5;
  s.distance_after_revisit_p90_m = 5.5;
  s.update_seconds_mean = 6.5;
  s.update_seconds_max = 7.5;
  s.lost_signals = 8;
  s.lost_on_correct_track = 9;
  s.lost_on_wrong_track = 10;
  const ResultFields<RelocalizationSummary>& fields = RelocalizationSummaryFields();
  ExpectWellFormed(fields, s);
  EXPECT_EQ(fields.fields().size(), 21u);  // every figure of the struct
  EXPECT_EQ(ValueOf(fields, s, "wrong_fixes"), ResultValue(std::int64_t{6}));
  EXPECT_EQ(ValueOf(fields, s, "distance_to_fix_p90_m"), ResultValue(2.5));
  EXPECT_EQ(ValueOf(fields, s, "wrong_fix_confident"), ResultValue(true));
}

TEST(ResultFields, LocalizationSummaryFiguresReadTheirOwnMembers) {
  LocalizationSummary s;
  s.n_pos = 1;
  s.n_acc = 2;
  s.n_cor = 3;
  s.n_verified = 4;
  s.n_ambiguous = 5;
  s.n_ambiguous_wrong = 6;
  s.precision = 0.5;
  s.recall = 0.25;
  s.n_revisitable = 7;
  s.n_cor_revisitable = 8;
  s.recall_revisitable = 0.125;
  s.scans_mean = 1.5;
  s.scans_mean_all_queries = 2.5;
  s.seconds_per_query_mean = 3.5;
  s.seconds_submap_building_mean = 4.5;
  s.rank_by = RankBy::kGamma;
  s.p_gl = 0.75;
  s.p_cl = 0.375;
  const ResultFields<LocalizationSummary>& fields = LocalizationSummaryFields();
  ExpectWellFormed(fields, s);
  EXPECT_EQ(fields.fields().size(), 18u);
  EXPECT_EQ(ValueOf(fields, s, "n_cor"), ResultValue(std::int64_t{3}));
  EXPECT_EQ(ValueOf(fields, s, "p_cl"), ResultValue(0.375));
  EXPECT_EQ(ValueOf(fields, s, "rank_by"), ResultValue(std::string("gamma")));
}

}  // namespace
}  // namespace keyplace
