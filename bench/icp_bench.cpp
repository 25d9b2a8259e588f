// Point-to-line ICP: time per alignment for 180- and 360-beam scans.
//
//  - BM_AlignSynthetic/<beams>: scan-to-scan in a synthetic polygonal room (180 deg FOV), guess
//    off by 5 cm / 2 deg; target prepared once, only AlignPointToLine is timed.
//  - BM_BuildTarget/<beams>: kd-tree + normals for one scan.
//  - BM_AlignLocalMap/<log>: real scans of intel-raw (180 beams) / fr079-raw (360 beams) against
//    a local map of the 10 previous scans (as ScanOdometry does), guess = odometry increment;
//    the source is subsampled like ScanOdometry does (source_min_spacing_m).
//    Needs ../shared/data; skipped with a message when absent.
//  - BM_ScanOdometry/<log>: the whole per-scan step (filter, ICP, key-scan map update).

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "keyplace/io/carmen_log.hpp"
#include "keyplace/registration/icp.hpp"
#include "keyplace/registration/scan_odometry.hpp"

namespace {

using keyplace::IcpConfig;
using keyplace::IcpTarget;
using keyplace::Pose2;

struct Segment {
  Eigen::Vector2d a, b;
};

std::vector<Eigen::Vector2d> CastRoom(const Pose2& T_world_laser, int beams) {
  const std::vector<Eigen::Vector2d> corners = {{-4.0, -3.0}, {5.0, -3.5}, {6.0, 1.0}, {3.0, 1.2},
                                                {3.0, 3.5},   {-2.0, 4.0}, {-5.0, 1.0}};
  std::vector<Segment> world;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    world.push_back({corners[i], corners[(i + 1) % corners.size()]});
  }
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < beams; ++i) {
    const double angle = -M_PI / 2 + i * M_PI / beams;
    const Eigen::Vector2d dir(std::cos(T_world_laser.theta + angle),
                              std::sin(T_world_laser.theta + angle));
    double best = 1e9;
    for (const Segment& s : world) {
      const Eigen::Vector2d e = s.b - s.a;
      const double denom = dir.x() * e.y() - dir.y() * e.x();
      if (std::abs(denom) < 1e-12) continue;
      const Eigen::Vector2d w = s.a - T_world_laser.translation();
      const double t = (w.x() * e.y() - w.y() * e.x()) / denom;
      const double u = (w.x() * dir.y() - w.y() * dir.x()) / denom;
      if (t > 0 && u >= 0 && u <= 1) best = std::min(best, t);
    }
    if (best < 30.0) points.emplace_back(best * std::cos(angle), best * std::sin(angle));
  }
  return points;
}

void BM_AlignSynthetic(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  const Pose2 T_world_target(0.2, -0.3, 0.3);
  const Pose2 T_world_source(0.35, -0.25, 0.33);
  const auto target_points = CastRoom(T_world_target, beams);
  const auto source_points = CastRoom(T_world_source, beams);
  const IcpConfig config;
  const IcpTarget target(target_points, config);
  const Pose2 guess =
      keyplace::Between(T_world_target, T_world_source) * Pose2(0.05, -0.03, 2.0 * M_PI / 180);
  int iterations = 0;
  for (auto _ : state) {
    const auto result = keyplace::AlignPointToLine(target, source_points, guess, config);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result);
  }
  state.counters["icp_iterations"] = iterations;
}
BENCHMARK(BM_AlignSynthetic)->Arg(180)->Arg(360)->Unit(benchmark::kMicrosecond);

void BM_BuildTarget(benchmark::State& state) {
  const auto points = CastRoom(Pose2(0.2, -0.3, 0.3), static_cast<int>(state.range(0)));
  const IcpConfig config;
  for (auto _ : state) {
    IcpTarget target(points, config);
    benchmark::DoNotOptimize(target.CountNormals());
  }
}
BENCHMARK(BM_BuildTarget)->Arg(180)->Arg(360)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// Real scans.

std::string SharedData(const std::string& name) {
  const char* env = std::getenv("KEYPLACE_SHARED");
  const std::string shared = env != nullptr ? env : std::string(KEYPLACE_SOURCE_DIR) + "/../shared";
  return shared + "/data/" + name;
}

const keyplace::CarmenLog* LoadLog(const std::string& name) {
  static std::map<std::string, std::unique_ptr<keyplace::CarmenLog>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    const std::string path = SharedData(name + "-raw.log.gz");
    std::unique_ptr<keyplace::CarmenLog> log;
    if (std::filesystem::exists(path)) {
      log = std::make_unique<keyplace::CarmenLog>(keyplace::ReadCarmenLog(path));
    }
    it = cache.emplace(name, std::move(log)).first;
  }
  return it->second.get();
}

// A sample of alignment problems from a log: source scan, its local map (previous 10 scans in
// world coordinates, from a ScanOdometry pre-pass) and the odometry-predicted guess.
struct Problem {
  std::vector<Eigen::Vector2d> source;
  std::vector<Eigen::Vector2d> map;
  Pose2 guess;
};

const std::vector<Problem>* Problems(const std::string& name) {
  static std::map<std::string, std::vector<Problem>> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return &it->second;
  const keyplace::CarmenLog* log = LoadLog(name);
  if (log == nullptr) return nullptr;
  constexpr std::size_t kFirst = 1000, kCount = 200, kMapScans = 10;
  keyplace::ScanOdometryConfig config;
  keyplace::ScanOdometry odometry(config);
  std::vector<Pose2> T_world_laser;
  std::vector<std::vector<Eigen::Vector2d>> points;
  const std::size_t end = std::min(log->scans.size(), kFirst + kCount);
  for (std::size_t i = 0; i < end; ++i) {
    const auto result = odometry.Add(log->scans[i], log->scans[i].odometry_pose);
    T_world_laser.push_back(result.T_world_laser);
    points.push_back(keyplace::ScanOdometry::FilteredEndpoints(log->scans[i], config));
  }
  std::vector<Problem> problems;
  for (std::size_t i = kFirst; i < end; ++i) {
    Problem problem;
    problem.source =
        keyplace::ScanOdometry::SubsampleBySpacing(points[i], config.source_min_spacing_m);
    for (std::size_t j = i - kMapScans; j < i; ++j) {
      for (const auto& p : points[j]) problem.map.push_back(T_world_laser[j] * p);
    }
    const auto& scan = log->scans[i];
    const auto& previous = log->scans[i - 1];
    const Pose2 increment = keyplace::Between(*previous.odometry_pose * previous.T_robot_laser,
                                              *scan.odometry_pose * scan.T_robot_laser);
    problem.guess = T_world_laser[i - 1] * increment;
    problems.push_back(std::move(problem));
  }
  return &cache.emplace(name, std::move(problems)).first->second;
}

void BM_AlignLocalMap(benchmark::State& state, const std::string& name) {
  const std::vector<Problem>* problems = Problems(name);
  if (problems == nullptr || problems->empty()) {
    state.SkipWithError(("no " + SharedData(name + "-raw.log.gz")).c_str());
    return;
  }
  const IcpConfig config;
  std::vector<std::unique_ptr<IcpTarget>> targets;
  for (const Problem& problem : *problems) {
    targets.push_back(std::make_unique<IcpTarget>(problem.map, config));
  }
  std::size_t k = 0;
  double iterations = 0.0;
  double converged = 0.0;
  std::size_t runs = 0;
  for (auto _ : state) {
    const Problem& problem = (*problems)[k];
    const auto result =
        keyplace::AlignPointToLine(*targets[k], problem.source, problem.guess, config);
    iterations += result.iterations;
    converged += result.converged ? 1.0 : 0.0;
    ++runs;
    k = (k + 1) % problems->size();
  }
  state.counters["icp_iterations"] = iterations / static_cast<double>(runs);
  state.counters["converged"] = converged / static_cast<double>(runs);
  state.counters["source_points"] = static_cast<double>((*problems)[0].source.size());
}
BENCHMARK_CAPTURE(BM_AlignLocalMap, intel_180, std::string("intel"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_AlignLocalMap, fr079_360, std::string("fr079"))->Unit(benchmark::kMicrosecond);

void BM_ScanOdometry(benchmark::State& state, const std::string& name) {
  const keyplace::CarmenLog* log = LoadLog(name);
  if (log == nullptr) {
    state.SkipWithError(("no " + SharedData(name + "-raw.log.gz")).c_str());
    return;
  }
  const std::size_t count = std::min<std::size_t>(log->scans.size(), 2000);
  auto odometry = std::make_unique<keyplace::ScanOdometry>();
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == count) {
      state.PauseTiming();
      odometry = std::make_unique<keyplace::ScanOdometry>();
      k = 0;
      state.ResumeTiming();
    }
    const keyplace::LogScan& scan = log->scans[k++];
    benchmark::DoNotOptimize(odometry->Add(scan, scan.odometry_pose));
  }
}
BENCHMARK_CAPTURE(BM_ScanOdometry, intel_180, std::string("intel"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ScanOdometry, fr079_360, std::string("fr079"))->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
