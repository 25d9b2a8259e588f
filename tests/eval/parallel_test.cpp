// The parallel evaluations (issue 15, item 3): the queries of keyplace localize and the starts of
// keyplace relocalize run on TBB workers, and every figure is the same at 1 and 2 threads, in the
// same order, on the bundled FR079 log. The runs at 2 threads must really use two threads (seen
// through the progress callback, which must count up from one thread at a time).

#include <cstddef>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "support/bundled_map.hpp"
#include "support/same_match.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

constexpr int kQueries = 80;

using Bundled = testing::BundledMap;
const Bundled& BundledLog() { return testing::BundledFr079(); }

// A progress callback that checks it is called one at a time with done = 1, 2, ..., and records
// the threads it was called from.
class ProgressWitness {
 public:
  std::function<void(std::size_t, std::size_t)> Callback() {
    return [this](std::size_t done, std::size_t total) {
      const bool entered = busy_.try_lock();  // fails if another thread is inside
      EXPECT_TRUE(entered) << "progress called from two threads at once";
      EXPECT_EQ(done, calls_ + 1);
      EXPECT_LE(done, total);
      ++calls_;
      threads_.insert(std::this_thread::get_id());
      if (entered) busy_.unlock();
    };
  }
  std::size_t calls() const { return calls_; }
  std::size_t threads() const { return threads_.size(); }

 private:
  std::mutex busy_;
  std::size_t calls_ = 0;
  std::set<std::thread::id> threads_;
};

using testing::ExpectSamePose;

std::vector<LocalizationQuery> QueriesAt(std::size_t threads, const std::vector<int>& starts,
                                         ProgressWitness* witness = nullptr) {
  const Bundled& b = BundledLog();
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
  return BuildSubmapQueries(b.inputs, b.truth, b.map.config, starts,
                            PlaceRecognitionConfig{}.query_keypoints,
                            witness != nullptr ? witness->Callback() : QueryProgress{});
}

const std::vector<LocalizationQuery>& SerialQueries() {
  static const std::vector<LocalizationQuery> queries =
      QueriesAt(1, QueryStarts(BundledLog().truth, kQueries));
  return queries;
}

TEST(ParallelQueries, SubmapQueriesAreTheSameAtOneAndTwoThreads) {
  const std::vector<LocalizationQuery>& serial = SerialQueries();
  ASSERT_GT(serial.size(), static_cast<std::size_t>(kQueries) * 9 / 10);
  ProgressWitness witness;
  const std::vector<LocalizationQuery> parallel =
      QueriesAt(2, QueryStarts(BundledLog().truth, kQueries), &witness);
  EXPECT_GE(witness.threads(), 2u);
  EXPECT_GE(witness.calls(), serial.size());
  ASSERT_EQ(parallel.size(), serial.size());
  for (std::size_t i = 0; i < serial.size(); ++i) {
    const LocalizationQuery& s = serial[i];
    const LocalizationQuery& p = parallel[i];
    const std::string what = "query " + std::to_string(i);
    EXPECT_EQ(p.start_scan, s.start_scan) << what;
    EXPECT_EQ(p.evaluated_scan, s.evaluated_scan) << what;
    EXPECT_EQ(p.scans, s.scans) << what;
    EXPECT_EQ(p.truth_scans, s.truth_scans) << what;
    ExpectSamePose(p.truth, s.truth, what);
    ExpectSamePose(p.query.T_first_evaluated, s.query.T_first_evaluated, what);
    EXPECT_EQ(p.query.positions, s.query.positions) << what;
    EXPECT_EQ(p.query.descriptors, s.query.descriptors) << what;
    EXPECT_EQ(p.query.all_positions, s.query.all_positions) << what;
  }
}

TEST(ParallelQueries, StopAtTheFirstStartTheLogEndsBeforeCompletingAtAnyThreadCount) {
  const Bundled& b = BundledLog();
  const int last = static_cast<int>(b.inputs.log.scans.size()) - 1;
  // The start at the last scan never completes; the starts after it would.
  std::vector<int> starts{0, 400, last};
  for (int s = 100; s <= 1100; s += 100) starts.push_back(s);
  for (const std::size_t threads : {1u, 2u}) {
    const std::vector<LocalizationQuery> queries = QueriesAt(threads, starts);
    ASSERT_EQ(queries.size(), 2u) << threads << " threads";
    EXPECT_EQ(queries[0].start_scan, 0);
    EXPECT_EQ(queries[1].start_scan, 400);
  }
}

std::vector<LocalizationRecord> RecordsAt(std::size_t threads, const PlaceRecognizer& recognizer,
                                          ProgressWitness* witness = nullptr) {
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
  return EvaluateQueries(SerialQueries(), recognizer, SelfMatchRule::kSameScans,
                         witness != nullptr ? witness->Callback() : QueryProgress{});
}

void ExpectSameRecord(const LocalizationRecord& p, const LocalizationRecord& s,
                      const std::string& what) {
  EXPECT_EQ(p.start_scan, s.start_scan) << what;
  EXPECT_EQ(p.evaluated_scan, s.evaluated_scan) << what;
  EXPECT_EQ(p.correct, s.correct) << what;
  EXPECT_EQ(p.verified_correct, s.verified_correct) << what;
  testing::ExpectSameMatch(p.match, s.match, what);
}

TEST(ParallelQueries, RecordsAndSummaryAreTheSameAtOneAndTwoThreads) {
  const Bundled& b = BundledLog();
  const std::vector<LocalizationQuery>& queries = SerialQueries();
  const PlaceRecognizer recognizer(PlacesFromMap(b.map), PlaceRecognitionConfig{});
  const std::vector<LocalizationRecord> serial = RecordsAt(1, recognizer);
  ProgressWitness witness;
  const std::vector<LocalizationRecord> parallel = RecordsAt(2, recognizer, &witness);
  EXPECT_GE(witness.threads(), 2u);
  EXPECT_EQ(witness.calls(), queries.size());
  ASSERT_EQ(serial.size(), queries.size());
  ASSERT_EQ(parallel.size(), queries.size());
  std::size_t found = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const std::string what = "query " + std::to_string(i);
    EXPECT_EQ(serial[i].start_scan, queries[i].start_scan) << what;  // the order of the queries
    ExpectSameRecord(parallel[i], serial[i], what);
    found += serial[i].match.found ? 1 : 0;
  }
  // The oracle: one query recognised on its own gives the record's answer.
  const std::size_t probe = queries.size() / 2;
  const PlaceMatch alone = recognizer.Recognize(queries[probe].query, [&](const Place& place) {
    return IsSelfMatch(SelfMatchRule::kSameScans, queries[probe].truth_scans, place.scan_indices);
  });
  EXPECT_EQ(alone.place_id, parallel[probe].match.place_id);
  ExpectSamePose(alone.estimated_pose, parallel[probe].match.estimated_pose, "alone");
  EXPECT_GT(found, queries.size() * 9 / 10);  // answers worth comparing

  const LocalizationSummary s = Summarize(serial, RankBy::kConfidence);
  const LocalizationSummary p = Summarize(parallel, RankBy::kConfidence);
  EXPECT_EQ(p.n_pos, s.n_pos);
  EXPECT_EQ(p.n_acc, s.n_acc);
  EXPECT_EQ(p.n_cor, s.n_cor);
  EXPECT_EQ(p.n_verified, s.n_verified);
  EXPECT_EQ(p.n_ambiguous, s.n_ambiguous);
  EXPECT_EQ(p.precision, s.precision);
  EXPECT_EQ(p.recall, s.recall);
  EXPECT_EQ(p.scans_mean, s.scans_mean);
  EXPECT_EQ(p.p_gl, s.p_gl);
  EXPECT_EQ(p.p_cl, s.p_cl);
  ASSERT_EQ(p.curve.size(), s.curve.size());
  for (std::size_t k = 0; k < s.curve.size(); ++k) {
    EXPECT_EQ(p.curve[k].threshold, s.curve[k].threshold) << k;
    EXPECT_EQ(p.curve[k].accepted, s.curve[k].accepted) << k;
    EXPECT_EQ(p.curve[k].correct, s.curve[k].correct) << k;
  }
  ASSERT_EQ(p.reliability.size(), s.reliability.size());
  for (std::size_t k = 0; k < s.reliability.size(); ++k) {
    EXPECT_EQ(p.reliability[k].count, s.reliability[k].count) << k;
    EXPECT_EQ(p.reliability[k].confidence_mean, s.reliability[k].confidence_mean) << k;
  }
}

std::vector<StartRecord> StartsAt(std::size_t threads, const RelocalizationOptions& options,
                                  ProgressWitness* witness = nullptr) {
  const Bundled& b = BundledLog();
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
  return RunRelocalization(b.map, b.inputs, b.truth, LocalizerConfig{}, options,
                           witness != nullptr ? witness->Callback() : StartProgress{});
}

TEST(ParallelRelocalization, StartsAreTheSameAtOneAndTwoThreadsExceptTheirTimes) {
  RelocalizationOptions options;
  options.starts = 8;
  options.give_up_m = 30.0;
  options.follow_m = 10.0;
  const std::vector<StartRecord> serial = StartsAt(1, options);
  ProgressWitness witness;
  const std::vector<StartRecord> parallel = StartsAt(2, options, &witness);
  EXPECT_GE(witness.threads(), 2u);
  EXPECT_EQ(witness.calls(), serial.size());
  ASSERT_EQ(serial.size(), 8u);
  ASSERT_EQ(parallel.size(), serial.size());
  const std::vector<int> starts = QueryStarts(BundledLog().truth, options.starts);
  std::size_t fixed = 0;
  std::size_t fixes = 0;
  std::size_t searches = 0;
  for (std::size_t i = 0; i < serial.size(); ++i) {
    const StartRecord& s = serial[i];
    const StartRecord& p = parallel[i];
    const std::string what = "start " + std::to_string(i);
    EXPECT_EQ(s.start_scan, starts[i]) << what;  // the order of the starts
    EXPECT_EQ(p.start_scan, s.start_scan) << what;
    EXPECT_EQ(p.end_scan, s.end_scan) << what;
    EXPECT_EQ(p.revisit, s.revisit) << what;
    EXPECT_EQ(p.distance_to_revisit_m, s.distance_to_revisit_m) << what;
    EXPECT_EQ(p.room_after_revisit_m, s.room_after_revisit_m) << what;
    EXPECT_EQ(p.fixed, s.fixed) << what;
    EXPECT_EQ(p.scans_to_fix, s.scans_to_fix) << what;
    EXPECT_EQ(p.distance_to_fix_m, s.distance_to_fix_m) << what;
    EXPECT_EQ(p.first_fix_checked, s.first_fix_checked) << what;
    EXPECT_EQ(p.first_fix_correct, s.first_fix_correct) << what;
    EXPECT_EQ(p.answers, s.answers) << what;
    EXPECT_EQ(p.answers_accepted, s.answers_accepted) << what;
    EXPECT_EQ(p.answers_weak, s.answers_weak) << what;
    EXPECT_EQ(p.wrong_fixes, s.wrong_fixes) << what;
    EXPECT_EQ(p.lost, s.lost) << what;
    EXPECT_EQ(p.lost_on_correct_track, s.lost_on_correct_track) << what;
    EXPECT_EQ(p.lost_on_wrong_track, s.lost_on_wrong_track) << what;
    EXPECT_EQ(p.map_searches, s.map_searches) << what;
    ASSERT_EQ(p.fixes.size(), s.fixes.size()) << what;
    for (std::size_t f = 0; f < s.fixes.size(); ++f) {
      EXPECT_EQ(p.fixes[f].scan, s.fixes[f].scan) << what;
      EXPECT_EQ(p.fixes[f].checked_scan, s.fixes[f].checked_scan) << what;
      ExpectSamePose(p.fixes[f].T_world_robot, s.fixes[f].T_world_robot, what);
      EXPECT_EQ(p.fixes[f].confidence, s.fixes[f].confidence) << what;
      EXPECT_EQ(p.fixes[f].correct, s.fixes[f].correct) << what;
      EXPECT_EQ(p.fixes[f].first, s.fixes[f].first) << what;
    }
    fixed += s.fixed ? 1 : 0;
    fixes += s.fixes.size();
    searches += static_cast<std::size_t>(s.map_searches);
  }
  EXPECT_GE(fixed, 4u);  // starts worth comparing
  EXPECT_GT(fixes, fixed);
  const RelocalizationSummary s = SummarizeRelocalization(serial, options);
  const RelocalizationSummary p = SummarizeRelocalization(parallel, options);
  EXPECT_EQ(p.fixed, s.fixed);
  EXPECT_EQ(p.fixes, s.fixes);
  EXPECT_EQ(p.wrong_fixes, s.wrong_fixes);
  EXPECT_EQ(p.distance_to_fix_median_m, s.distance_to_fix_median_m);
  EXPECT_EQ(p.distance_after_revisit_median_m, s.distance_after_revisit_median_m);
  EXPECT_EQ(p.wrong_fix_confidence_max, s.wrong_fix_confidence_max);
  EXPECT_EQ(s.map_searches, searches);
  EXPECT_EQ(p.map_searches, s.map_searches);
}

}  // namespace
}  // namespace keyplace
