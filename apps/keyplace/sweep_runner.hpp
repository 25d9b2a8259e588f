#pragma once
// Runs the pending points of a sweep in parallel, each row written to the results as it finishes
// and reported on stdout (keyplace sweep).

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "sweep_grid.hpp"

namespace keyplace::cli {

/// The points of `grid` that `results` does not hold yet.
std::vector<std::vector<double>> PendingPoints(const std::vector<std::vector<double>>& grid,
                                               const SweepResults& results);

/// Evaluates every pending point in parallel (TBB), adding each row to `results` as it finishes.
/// `stop_after` > 0 (a test hook) starts no new point once that many have started. Returns the
/// number of points computed.
std::size_t RunSweepPoints(
    const std::vector<std::vector<double>>& pending, SweepResults& results,
    const std::vector<std::string>& parameter_columns,
    const std::vector<std::string>& value_columns, int stop_after,
    const std::function<std::vector<double>(const std::vector<double>&)>& evaluate);

/// "N rows in DIR/results.csv and results.json (G grid points, C computed now)".
void PrintSweepSummary(const SweepResults& results, std::size_t grid_size, std::size_t computed,
                       const std::string& out_dir);

/// --json FILE: what results.json holds, with the directory, the grid size, the points computed
/// by this run and `seconds_total`. Nothing when `json_path` is empty.
void WriteSweepJson(const std::string& json_path, const SweepResults& results,
                    std::size_t grid_size, std::size_t computed, const std::string& out_dir,
                    double seconds_total);

}  // namespace keyplace::cli
