// FLIRT detect + describe per scan on the first 200 scans of FR079 (360 beams) and Intel (180
// beams), detect-only and describe-only, and detect + describe over the whole logs ("_all", the
// set FLIRTLib was timed on). Compare with FLIRTLib's 27.48 ms (FR079) and 7.01 ms (Intel) per
// scan on the same machine kind (../shared/reference/flirtlib/README.md). Run pinned:
//   taskset -c 0 build/bench/flirt_bench --benchmark_repetitions=10
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
// (one command line).
// time_per_scan is in seconds (SI prefixes: 2.5m = 2.5 ms).

#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace {

constexpr std::size_t kFirstScans = 200;
constexpr std::size_t kAllScans = static_cast<std::size_t>(-1);

std::string SharedDir() {
  const char* env = std::getenv("KEYPLACE_SHARED");
  if (env != nullptr && *env != '\0') return env;
  return std::string(KEYPLACE_SOURCE_DIR) + "/../shared";
}

struct Dataset {
  std::vector<keyplace::LaserScan> scans;
  std::vector<keyplace::Pose2> laser_poses;
};

const Dataset& Load(const std::string& name, std::size_t max_scans = kFirstScans) {
  static std::map<std::pair<std::string, std::size_t>, Dataset> cache;
  auto it = cache.find({name, max_scans});
  if (it != cache.end()) return it->second;
  const std::string path = SharedDir() + "/data/" + name + "-corrected.log.gz";
  if (!std::filesystem::exists(path)) throw std::runtime_error("missing data file " + path);
  keyplace::CarmenLog log = keyplace::ReadCarmenLog(path);
  Dataset dataset;
  for (std::size_t i = 0; i < log.scans.size() && i < max_scans; ++i) {
    dataset.laser_poses.push_back(*log.scans[i].corrected_pose * log.scans[i].T_robot_laser);
    dataset.scans.push_back(std::move(log.scans[i]));
  }
  return cache.emplace(std::make_pair(name, max_scans), std::move(dataset)).first->second;
}

void SetCounters(benchmark::State& state, std::size_t scans, std::size_t keypoints) {
  state.counters["time_per_scan"] = benchmark::Counter(
      static_cast<double>(scans), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["keypoints_per_scan"] =
      static_cast<double>(keypoints) / static_cast<double>(scans);
}

void BM_FlirtExtract(benchmark::State& state, const std::string& name, std::size_t max_scans) {
  const Dataset& data = Load(name, max_scans);
  const keyplace::FlirtExtractor extractor;
  std::size_t scans = 0, keypoints = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < data.scans.size(); ++i) {
      const auto result = extractor.Extract(data.scans[i], data.laser_poses[i]);
      keypoints += result.size();
      benchmark::DoNotOptimize(result.data());
    }
    scans += data.scans.size();
  }
  SetCounters(state, scans, keypoints);
}

void BM_FlirtDetect(benchmark::State& state, const std::string& name) {
  const Dataset& data = Load(name);
  const keyplace::FlirtExtractor extractor;
  std::size_t scans = 0, keypoints = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < data.scans.size(); ++i) {
      const auto result = extractor.Detect(data.scans[i], data.laser_poses[i]);
      keypoints += result.size();
      benchmark::DoNotOptimize(result.data());
    }
    scans += data.scans.size();
  }
  SetCounters(state, scans, keypoints);
}

void BM_FlirtDescribe(benchmark::State& state, const std::string& name) {
  const Dataset& data = Load(name);
  const keyplace::FlirtExtractor extractor;
  std::vector<std::vector<keyplace::Keypoint>> detected;
  for (std::size_t i = 0; i < data.scans.size(); ++i) {
    detected.push_back(extractor.Detect(data.scans[i], data.laser_poses[i]));
  }
  std::size_t scans = 0, keypoints = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < data.scans.size(); ++i) {
      extractor.Describe(data.scans[i], detected[i]);
      keypoints += detected[i].size();
      benchmark::DoNotOptimize(detected[i].data());
    }
    scans += data.scans.size();
  }
  SetCounters(state, scans, keypoints);
}

BENCHMARK_CAPTURE(BM_FlirtExtract, fr079, std::string("fr079"), kFirstScans)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtExtract, intel, std::string("intel"), kFirstScans)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtExtract, fr079_all, std::string("fr079"), kAllScans)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtExtract, intel_all, std::string("intel"), kAllScans)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtDetect, fr079, std::string("fr079"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtDetect, intel, std::string("intel"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtDescribe, fr079, std::string("fr079"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FlirtDescribe, intel, std::string("intel"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
