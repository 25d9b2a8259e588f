#include "sweep_runner.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include "command_output.hpp"
#include "common/seconds_since.hpp"
#include "progress.hpp"

namespace keyplace::cli {

std::vector<std::vector<double>> PendingPoints(const std::vector<std::vector<double>>& grid,
                                               const SweepResults& results) {
  std::vector<std::vector<double>> pending;
  for (const auto& point : grid) {
    if (!results.Has(point)) pending.push_back(point);
  }
  return pending;
}

std::vector<std::vector<std::vector<double>>> GroupPoints(
    const std::vector<std::vector<double>>& pending,
    const std::vector<std::size_t>& shared_columns) {
  std::vector<std::vector<double>> keys;
  std::vector<std::vector<std::vector<double>>> groups;
  for (const auto& point : pending) {
    std::vector<double> key;
    key.reserve(shared_columns.size());
    for (std::size_t column : shared_columns) key.push_back(point.at(column));
    const auto it = std::find(keys.begin(), keys.end(), key);
    if (it == keys.end()) {
      keys.push_back(key);
      groups.push_back({point});
    } else {
      groups[static_cast<std::size_t>(it - keys.begin())].push_back(point);
    }
  }
  return groups;
}

namespace {

// "s_min=0.3 l_g=0.1: n_pos 500 ..." for one point's row.
std::string RowText(const std::vector<double>& point, const std::vector<double>& values,
                    const std::vector<std::string>& parameter_columns,
                    const std::vector<std::string>& value_columns) {
  std::string text;
  for (std::size_t k = 0; k < parameter_columns.size(); ++k) {
    text += fmt::format("{}{}={}", k > 0 ? " " : "", parameter_columns[k], point[k]);
  }
  text += ":";
  for (std::size_t k = 0; k < value_columns.size(); ++k) {
    text += fmt::format(" {} {:.4g}", value_columns[k], values[k]);
  }
  return text;
}

}  // namespace

std::size_t RunSweepGroups(const std::vector<std::vector<std::vector<double>>>& groups,
                           SweepResults& results, const std::vector<std::string>& parameter_columns,
                           const std::vector<std::string>& value_columns, int stop_after,
                           const SweepGroupEvaluation& evaluate) {
  std::size_t total = 0;
  for (const auto& group : groups) total += group.size();
  std::mutex print_mutex;
  std::atomic<std::size_t> started{0};
  std::size_t finished = 0;
  // The progress bar counts points, a group's share of them as its evaluation goes.
  std::vector<double> group_fraction(groups.size(), 0.0);
  Progress progress("sweep", total);
  const auto points_done = [&] {
    double done = 0.0;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      done += group_fraction[g] * static_cast<double>(groups[g].size());
    }
    return static_cast<std::size_t>(done);
  };
  tbb::parallel_for(std::size_t{0}, groups.size(), [&](std::size_t g) {
    const std::vector<std::vector<double>>& points = groups[g];
    if (stop_after > 0 &&
        started.fetch_add(points.size()) >= static_cast<std::size_t>(stop_after)) {
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    const std::vector<std::vector<double>> rows = evaluate(points, [&](double fraction) {
      const std::lock_guard<std::mutex> lock(print_mutex);
      group_fraction[g] = std::min(fraction, 1.0);
      progress.Update(points_done());
    });
    for (std::size_t k = 0; k < points.size(); ++k) results.Add(points[k], rows.at(k));
    const std::lock_guard<std::mutex> lock(print_mutex);
    for (std::size_t k = 0; k < points.size(); ++k) {
      fmt::print("[{}/{}] {} ({:.1f} s{})\n", ++finished, total,
                 RowText(points[k], rows[k], parameter_columns, value_columns), SecondsSince(start),
                 points.size() > 1 ? fmt::format(" for {} points", points.size()) : "");
    }
    std::fflush(stdout);
    group_fraction[g] = 1.0;
    progress.Update(points_done());
  });
  progress.Finish();
  results.Sort();
  return finished;
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
