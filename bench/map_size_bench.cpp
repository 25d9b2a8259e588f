// Place recognition against map size (docs/BENCHMARKS.md, "Map size"): the bundled FR079 map
// (data/, default mapping) embedded among distractor submaps (EmbedAmongDistractors: real
// submaps moved far away) up to 10^2, 10^3, 10^4 and 10^5 submaps, queried with every 25th of the
// 500 queries of `keyplace localize` (default preset; 10^2 is the map's first 100 submaps), with
// the dense index, the dense index after retrieval (`words`, place.retrieval=words) and
// exhaustively (`none`, the oracle) in the same process. Counters per query:
// s_per_query (CPU time of recognition), pairing_s and verification_s (wall), candidates (places
// with >= mu pairs), correct (fraction of queries answered within 0.5 m / 10 deg),
// places_mib (heap of the places: keypoints, descriptors, occupancy), recognizer_mib (heap the
// recognizer adds to them: descriptor index, and with `words` the vocabulary and word lists),
// build_s (wall time to make the recognizer from the places: index, and with `words` the
// vocabulary learned from the map, what loading a map costs beyond reading it).
//
// Distractors: the maps named in KEYPLACE_DISTRACTOR_MAPS (colon-separated .kpm files; the
// benchmark in docs/ uses the maps of the other buildings), else copies of the bundled map itself
// (times only: a copy of the same building is a duplicate place, so `correct` falls).
//   KEYPLACE_DISTRACTOR_MAPS=intel.kpm:fr101.kpm build/bench/map_size_bench
//       --benchmark_filter='/(100|1000|10000)/'
// (one command line; 10^5 `none` alone takes minutes per iteration).

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <tbb/global_control.h>

#include "keyplace/eval/distractor_map.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"

namespace {

using keyplace::PlaceRecognitionConfig;

struct Bundled {
  keyplace::GlobalMap map;
  std::vector<keyplace::GlobalMap> distractors;
  std::vector<keyplace::LocalizationQuery> queries;
};

std::vector<keyplace::GlobalMap> DistractorMaps(const keyplace::GlobalMap& bundled) {
  const char* paths = std::getenv("KEYPLACE_DISTRACTOR_MAPS");
  if (paths == nullptr || *paths == '\0') return {bundled};
  std::vector<keyplace::GlobalMap> maps;
  std::stringstream list(paths);
  for (std::string path; std::getline(list, path, ':');) {
    if (!path.empty()) maps.push_back(keyplace::LoadMap(path));
  }
  return maps;
}

const Bundled& Load() {
  static const Bundled bundled = [] {
    const keyplace::LogInputs inputs = keyplace::PrepareLogInputs(std::string(KEYPLACE_SOURCE_DIR) +
                                                                  "/data/fr079-corrected.log.gz");
    Bundled b;
    b.map = keyplace::BuildGlobalMap({inputs.log.scans, inputs.poses, inputs.keypoints},
                                     keyplace::MappingConfig{});
    const keyplace::GroundTruth truth = keyplace::TruthFromOwnPoses(inputs.log);
    const std::vector<keyplace::LocalizationQuery> all =
        keyplace::BuildSubmapQueries(inputs, truth, b.map.config, keyplace::QueryStarts(truth, 500),
                                     PlaceRecognitionConfig{}.query_keypoints);
    for (std::size_t i = 0; i < all.size(); i += 25) b.queries.push_back(all[i]);
    b.distractors = DistractorMaps(b.map);
    return b;
  }();
  return bundled;
}

// Heap in use (glibc), not the resident size: freed memory of an earlier, larger map stays
// resident and would be counted again.
double HeapInUseMiB() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd) / (1024.0 * 1024.0);
}

// Below the bundled map's own size (238 submaps), its first submaps.
keyplace::GlobalMap MapOfSize(const Bundled& b, std::size_t submaps) {
  if (submaps <= b.map.submaps.size()) {
    keyplace::GlobalMap cut = b.map;
    cut.submaps.resize(submaps);
    return cut;
  }
  keyplace::DistractorOptions options;
  options.total_submaps = submaps;
  return keyplace::EmbedAmongDistractors(b.map, b.distractors, options);
}

void BM_MapSize(benchmark::State& state, PlaceRecognitionConfig::DescriptorIndex index,
                PlaceRecognitionConfig::Retrieval retrieval) {
  const Bundled& b = Load();
  // One thread: s_per_query is the benchmark thread's CPU time.
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
  PlaceRecognitionConfig config;
  config.descriptor_index = index;
  config.retrieval = retrieval;
  // The map is not needed once its places are made; only the recognizer stays, as in a robot.
  const double heap_start_mib = HeapInUseMiB();
  std::vector<keyplace::Place> places =
      keyplace::PlacesFromMap(MapOfSize(b, static_cast<std::size_t>(state.range(0))));
  const double heap_before_mib = HeapInUseMiB();
  const double places_mib = heap_before_mib - heap_start_mib;
  const auto build_start = std::chrono::steady_clock::now();
  const auto recognizer =
      std::make_unique<const keyplace::PlaceRecognizer>(std::move(places), config);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  const double recognizer_mib = HeapInUseMiB() - heap_before_mib;
  double pairing = 0.0;
  double verification = 0.0;
  double candidates = 0.0;
  std::size_t queries = 0;
  int correct = 0;
  for (auto _ : state) {
    const std::vector<keyplace::LocalizationRecord> records =
        keyplace::EvaluateQueries(b.queries, *recognizer, keyplace::SelfMatchRule::kSameScans);
    for (const keyplace::LocalizationRecord& record : records) {
      pairing += record.match.seconds_pairing;
      verification += record.match.seconds_verification;
      candidates += record.match.candidates;
      correct += record.correct ? 1 : 0;
    }
    queries += records.size();
  }
  const auto n = static_cast<double>(queries);
  state.counters["s_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["pairing_s"] = pairing / n;
  state.counters["verification_s"] = verification / n;
  state.counters["candidates"] = candidates / n;
  state.counters["correct"] = correct / n;
  state.counters["places"] = static_cast<double>(recognizer->places().size());
  state.counters["places_mib"] = places_mib;
  state.counters["recognizer_mib"] = recognizer_mib;
  state.counters["build_s"] = build_s;
}

using Index = PlaceRecognitionConfig::DescriptorIndex;
using Retrieval = PlaceRecognitionConfig::Retrieval;

// 10^2 to 10^5 submaps, one iteration each (10^5 `none` alone takes minutes per iteration).
void MapSizes(benchmark::internal::Benchmark* benchmark) {
  benchmark->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000)->Iterations(1)->Unit(
      benchmark::kMillisecond);
}

BENCHMARK_CAPTURE(BM_MapSize, dense, Index::kDense, Retrieval::kExact)->Apply(MapSizes);
BENCHMARK_CAPTURE(BM_MapSize, words, Index::kDense, Retrieval::kWords)->Apply(MapSizes);
BENCHMARK_CAPTURE(BM_MapSize, none, Index::kNone, Retrieval::kExact)->Apply(MapSizes);

}  // namespace

BENCHMARK_MAIN();
