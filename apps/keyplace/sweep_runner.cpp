#include "sweep_runner.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include "cli_support.hpp"

namespace keyplace::cli {

std::vector<std::vector<double>> PendingPoints(const std::vector<std::vector<double>>& grid,
                                               const SweepResults& results) {
  std::vector<std::vector<double>> pending;
  for (const auto& point : grid) {
    if (!results.Has(point)) pending.push_back(point);
  }
  return pending;
}

std::size_t RunSweepPoints(
    const std::vector<std::vector<double>>& pending, SweepResults& results,
    const std::vector<std::string>& parameter_columns,
    const std::vector<std::string>& value_columns, int stop_after,
    const std::function<std::vector<double>(const std::vector<double>&)>& evaluate) {
  std::mutex print_mutex;
  std::atomic<int> started{0};
  std::atomic<std::size_t> finished{0};
  Progress progress("sweep", pending.size());
  tbb::parallel_for(std::size_t{0}, pending.size(), [&](std::size_t i) {
    if (stop_after > 0 && started.fetch_add(1) >= stop_after) return;
    const auto start = std::chrono::steady_clock::now();
    const std::vector<double> values = evaluate(pending[i]);
    results.Add(pending[i], values);
    const std::size_t done = finished.fetch_add(1) + 1;
    std::lock_guard<std::mutex> lock(print_mutex);
    std::string text;
    for (std::size_t k = 0; k < parameter_columns.size(); ++k) {
      text += fmt::format("{}{}={}", k > 0 ? " " : "", parameter_columns[k], pending[i][k]);
    }
    text += ":";
    for (std::size_t k = 0; k < value_columns.size(); ++k) {
      text += fmt::format(" {} {:.4g}", value_columns[k], values[k]);
    }
    fmt::print("[{}/{}] {} ({:.1f} s)\n", done, pending.size(), text, SecondsSince(start));
    std::fflush(stdout);
    progress.Update(done);
  });
  progress.Finish();
  results.Sort();
  return finished.load();
}

void WriteSweepJson(const std::string& json_path, const SweepResults& results,
                    std::size_t grid_size, std::size_t computed, const std::string& out_dir,
                    double seconds_total) {
  if (json_path.empty()) return;
  nlohmann::json json = results.Json();
  json["out"] = out_dir;
  json["grid_points"] = grid_size;
  json["computed_now"] = computed;
  json["seconds_total"] = seconds_total;
  WriteJson(json_path, json);
}

void PrintSweepSummary(const SweepResults& results, std::size_t grid_size, std::size_t computed,
                       const std::string& out_dir) {
  fmt::print("{} rows in {}/results.csv and results.json ({} grid points, {} computed now)\n",
             results.size(), out_dir, grid_size, computed);
}

}  // namespace keyplace::cli
