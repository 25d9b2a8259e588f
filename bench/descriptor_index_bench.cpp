// Place recognition on the bundled FR079 map (data/, default mapping and place presets) with each
// descriptor index: none (exhaustive chi2, the oracle), kdtree, dense. The queries are those of
// `keyplace localize` (Algorithm 4, 500 equally spaced starts; every 5th is timed here so that
// one repetition of `none` stays near 10 s); all indexes give the same answers
// (tests/place/descriptor_index_test.cpp). Counters per query, in seconds: s_per_query
// (recognition), pairing_s (descriptor pairs and candidates), verification_s (RANSAC and checks).
// Run pinned, interleaved, in one process so that the ratios share the machine's state:
//   taskset -c 0 build/bench/descriptor_index_bench --benchmark_repetitions=5
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
// (one command line).

#include <cstddef>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bundled_fr079_queries.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace {

using keyplace::PlaceRecognitionConfig;

using Bundled = keyplace_bench::BundledFr079;
const Bundled& Load() { return keyplace_bench::LoadBundledFr079(); }

void BM_Localize(benchmark::State& state, PlaceRecognitionConfig::DescriptorIndex index,
                 double chi2_threshold) {
  const Bundled& b = Load();
  PlaceRecognitionConfig config;
  config.descriptor_index = index;
  config.descriptor_match_chi2 = chi2_threshold;
  const keyplace::PlaceRecognizer recognizer(b.places, config);
  double pairing = 0.0;
  double verification = 0.0;
  std::size_t queries = 0;
  int found = 0;
  for (auto _ : state) {
    const std::vector<keyplace::LocalizationRecord> records =
        keyplace::EvaluateQueries(b.queries, recognizer, keyplace::SelfMatchRule::kSameScans);
    for (const keyplace::LocalizationRecord& record : records) {
      pairing += record.match.seconds_pairing;
      verification += record.match.seconds_verification;
      found += record.match.found ? 1 : 0;
    }
    queries += records.size();
  }
  const auto n = static_cast<double>(queries);
  state.counters["s_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["pairing_s"] = pairing / n;
  state.counters["verification_s"] = verification / n;
  state.counters["found"] = found / n;  // the same for every index
}

using Index = PlaceRecognitionConfig::DescriptorIndex;
// The default threshold 0.4 (a quarter of all keypoint pairs are below it on FR079) ...
BENCHMARK_CAPTURE(BM_Localize, none, Index::kNone, 0.4)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Localize, kdtree, Index::kKdTree, 0.4)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Localize, dense, Index::kDense, 0.4)->Unit(benchmark::kMillisecond);
// ... and a tight one, where the search radius excludes most keypoints.
BENCHMARK_CAPTURE(BM_Localize, none_tight, Index::kNone, 0.1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Localize, kdtree_tight, Index::kKdTree, 0.1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Localize, dense_tight, Index::kDense, 0.1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
