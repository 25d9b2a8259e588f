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

/// Points evaluated together because they share their expensive work; `fraction_done` reports
/// the share of it done so far (0 to 1, from any thread, never from two at once). Returns one row
/// per point, in order.
using SweepGroupEvaluation = std::function<std::vector<std::vector<double>>(
    const std::vector<std::vector<double>>& points,
    const std::function<void(double)>& fraction_done)>;

/// The pending points in groups of those with equal values in `shared_columns` (column indices),
/// in first-seen order.
std::vector<std::vector<std::vector<double>>> GroupPoints(
    const std::vector<std::vector<double>>& pending,
    const std::vector<std::size_t>& shared_columns);

/// Evaluates every group in parallel (TBB), adding its rows to `results` when the group finishes
/// and printing one line per point. `stop_after` > 0 (a test hook) starts no new group once that
/// many points have started. Returns the number of points computed.
std::size_t RunSweepGroups(const std::vector<std::vector<std::vector<double>>>& groups,
                           SweepResults& results, const std::vector<std::string>& parameter_columns,
                           const std::vector<std::string>& value_columns, int stop_after,
                           const SweepGroupEvaluation& evaluate);

/// "N rows in DIR/results.csv and results.json (G grid points, C computed now)".
void PrintSweepSummary(const SweepResults& results, std::size_t grid_size, std::size_t computed,
                       const std::string& out_dir);

/// --json FILE: what results.json holds, with the directory, the grid size, the points computed
/// by this run and `seconds_total`. Nothing when `json_path` is empty.
void WriteSweepJson(const std::string& json_path, const SweepResults& results,
                    std::size_t grid_size, std::size_t computed, const std::string& out_dir,
                    double seconds_total);

}  // namespace keyplace::cli
