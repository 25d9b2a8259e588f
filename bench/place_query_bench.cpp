// The latency of one place-recognition query at 1 and 2 threads (the parallelism inside
// PlaceRecognizer::Recognize, issue 15): the queries of `keyplace localize` on the bundled FR079
// map (default mapping and place presets; Algorithm 4, 500 equally spaced starts, every 5th
// timed), recognised one after the other, each on an arena of N threads. Counters per query, in
// seconds: s_per_query (wall time of the loop / queries), pairing_s and verification_s (the
// match's own timings). Interleaved repetitions share the machine's state:
//   build/bench/place_query_bench --benchmark_repetitions=5
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
// (one command line).

#include <cstddef>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "bundled_fr079_queries.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace {

using keyplace::PlaceRecognitionConfig;

using Bundled = keyplace_bench::BundledFr079;
const Bundled& Load() { return keyplace_bench::LoadBundledFr079(); }

void BM_Query(benchmark::State& state, const std::string& preset) {
  const Bundled& b = Load();
  const keyplace::PlaceRecognizer recognizer(b.places, keyplace::PlacePreset(preset));
  const auto threads = static_cast<int>(state.range(0));
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));
  tbb::task_arena arena(threads);
  double pairing = 0.0;
  double verification = 0.0;
  std::size_t queries = 0;
  int found = 0;
  while (state.KeepRunning()) {
    arena.execute([&] {
      for (const keyplace::LocalizationQuery& query : b.queries) {
        const auto exclude = [&query](const keyplace::Place& place) {
          return keyplace::IsSelfMatch(keyplace::SelfMatchRule::kSameScans, query.truth_scans,
                                       place.scan_indices);
        };
        const keyplace::PlaceMatch match = recognizer.Recognize(query.query, exclude);
        pairing += match.seconds_pairing;
        verification += match.seconds_verification;
        found += match.found ? 1 : 0;
      }
    });
    queries += b.queries.size();
  }
  const auto n = static_cast<double>(queries);
  state.counters["s_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["pairing_s"] = pairing / n;
  state.counters["verification_s"] = verification / n;
  state.counters["found"] = found / n;  // the same at any thread count
}

BENCHMARK_CAPTURE(BM_Query, default, std::string("default"))
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Query, paper, std::string("paper"))
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
