// The figure tables of the evaluation summaries (keyplace/common/result_fields.hpp): what the
// JSON of `keyplace localize` / `relocalize` and the Python properties are written from.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <variant>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "keyplace/eval/slam_evaluation.hpp"
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
  s.starts_with_room = 11;
  s.fixed_with_room = 12;
  s.fixed_fraction_with_room = 0.125;
  s.map_searches = 13;
  s.map_search_seconds_mean = 0.375;
  s.update_seconds_mean_without_search = 0.625;
  const ResultFields<RelocalizationSummary>& fields = RelocalizationSummaryFields();
  ExpectWellFormed(fields, s);
  EXPECT_EQ(fields.fields().size(), 27u);  // every figure of the struct
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

// A SLAM evaluation with loops, ground truth and an ATE alignment, each figure a different value.
SlamEvaluation DistinctSlamEvaluation() {
  SlamEvaluation e;
  e.loops.overlap = {0.9, 0.1};
  e.loops.used_count = 1;
  e.loops.truth_evaluated = 4;
  e.loops.truth_correct = 3;  // precision_truth 0.75
  e.precision = {0.11, 0.12, 0.13, 0.14, 0.15, 0.16, 0.17, 0.18};
  e.loops_below_1_percent = 2;
  e.seconds_per_submap = 0.5;
  e.has_truth = true;
  e.truth_max_gap_scans = 5;
  SlamAccuracy accuracy;
  accuracy.truth_pairs = 6;
  accuracy.ate.translation_rmse_m = 0.21;
  accuracy.ate.rotation_rmse_deg = 0.22;
  accuracy.ate_icp.translation_rmse_m = 0.23;
  accuracy.ate_icp.rotation_rmse_deg = 0.24;
  e.accuracy = accuracy;
  return e;
}

TEST(ResultFields, SlamEvaluationFiguresReadTheirOwnMembers) {
  const SlamEvaluation e = DistinctSlamEvaluation();
  const ResultFields<SlamEvaluation>& fields = SlamEvaluationFields();
  ExpectWellFormed(fields, e);
  EXPECT_EQ(fields.fields().size(), 20u);
  EXPECT_EQ(ValueOf(fields, e, "precision_overlap_30_used"), ResultValue(0.13));
  EXPECT_EQ(ValueOf(fields, e, "precision_overlap_30_matched_ransac"), ResultValue(0.18));
  EXPECT_EQ(ValueOf(fields, e, "precision_truth"), ResultValue(0.75));
  EXPECT_EQ(ValueOf(fields, e, "ate_icp_rmse_m"), ResultValue(0.23));
  EXPECT_EQ(ValueOf(fields, e, "loops_truth_max_gap_scans"), ResultValue(std::int64_t{5}));
}

// A share of no loops, a figure against absent truth: missing (JSON null, Python None), not 0.
TEST(ResultFields, SlamEvaluationFiguresAreMissingWithoutLoopsOrTruth) {
  SlamEvaluation e = DistinctSlamEvaluation();
  e.loops.overlap.clear();
  e.loops.used_count = 0;
  e.has_truth = false;
  e.accuracy.reset();
  const ResultFields<SlamEvaluation>& fields = SlamEvaluationFields();
  for (const char* name :
       {"precision_overlap_10", "precision_overlap_30_used", "precision_overlap_30_common_area",
        "loops_truth_correct", "precision_truth", "truth_pairs", "ate_rmse_m"}) {
    EXPECT_TRUE(std::holds_alternative<std::monostate>(ValueOf(fields, e, name))) << name;
  }
  EXPECT_EQ(ValueOf(fields, e, "loops_used"), ResultValue(std::int64_t{0}));
  EXPECT_EQ(ValueOf(fields, e, "seconds_per_submap"), ResultValue(0.5));

  e = DistinctSlamEvaluation();
  e.loops.truth_evaluated = 0;  // truth, but no loop near a corrected scan
  EXPECT_TRUE(std::holds_alternative<std::monostate>(ValueOf(fields, e, "precision_truth")));
  EXPECT_EQ(ValueOf(fields, e, "loops_truth_evaluated"), ResultValue(std::int64_t{0}));
}

TEST(ResultFields, StartRecordAndFixEventFiguresReadTheirOwnMembers) {
  StartRecord r;
  r.start_scan = 1;
  r.end_scan = 2;
  r.revisit = true;
  r.distance_to_revisit_m = 0.5;
  r.room_after_revisit_m = 4.5;
  r.scans_to_fix = 3;
  r.distance_to_fix_m = 1.5;
  r.answers = 4;
  r.answers_accepted = 5;
  r.answers_weak = 11;
  r.fixes.resize(6);
  r.wrong_fixes = 7;
  r.lost = 8;
  r.lost_on_correct_track = 9;
  r.lost_on_wrong_track = 10;
  r.update_seconds_mean = 2.5;
  r.update_seconds_max = 3.5;
  r.map_searches = 12;
  r.map_search_seconds = 4.25;
  // The three other switches stay false: ExpectWellFormed needs one value per figure, so they are
  // checked one by one.
  const ResultFields<StartRecord>& fields = StartRecordFields();
  EXPECT_EQ(fields.fields().size(), 22u);
  EXPECT_EQ(ValueOf(fields, r, "fixes_reported"), ResultValue(std::int64_t{6}));
  EXPECT_EQ(ValueOf(fields, r, "room_after_revisit_m"), ResultValue(4.5));
  EXPECT_EQ(ValueOf(fields, r, "answers_weak"), ResultValue(std::int64_t{11}));
  for (bool StartRecord::*member :
       {&StartRecord::fixed, &StartRecord::first_fix_checked, &StartRecord::first_fix_correct}) {
    StartRecord one = r;
    one.revisit = false;
    one.*member = true;
    int true_figures = 0;
    for (const ResultField<StartRecord>& field : fields.fields()) {
      true_figures += field.value(one) == ResultValue(true);
    }
    EXPECT_EQ(true_figures, 1);
  }

  FixEvent f;
  f.scan = 11;
  f.checked_scan = 12;
  f.first = true;
  f.confidence = 0.75;
  f.T_world_robot = Pose2{3.0, 4.0, 0.1};
  f.truth = Pose2{0.0, 0.0, 0.0};
  ExpectWellFormed(FixEventFields(), f);
  EXPECT_EQ(ValueOf(FixEventFields(), f, "error_m"), ResultValue(5.0));
  EXPECT_NEAR(std::get<double>(ValueOf(FixEventFields(), f, "error_deg")), 5.729578, 1e-6);
}

}  // namespace
}  // namespace keyplace
