#pragma once
// Parameter sweeps (keyplace sweep): value lists, grid expansion and the resumable results file.

#include <cstddef>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace keyplace::cli {

/// Parses a value list: "A:B:STEP" (A, A+STEP, ... up to B inclusive, within 1e-9 of a step) or
/// "V1,V2,..." or a single value. Values are rounded to 1e-9 so that 0:1:0.1 gives 0.3, not
/// 0.30000000000000004. Throws std::invalid_argument naming `option` and the bad part for an
/// empty list, a non-number, STEP <= 0, B < A, more than 100000 values or a repeated value.
std::vector<double> ParseValueList(const std::string& text, const std::string& option);

/// One named axis of a grid.
struct GridAxis {
  std::string name;
  std::vector<double> values;
};

/// The Cartesian product of the axes, first axis slowest. Each point holds one value per axis.
std::vector<std::vector<double>> ExpandGrid(const std::vector<GridAxis>& axes);

/// Canonical text of a point ("0.3,0.1"): the identity of a row in the results file.
std::string PointKey(const std::vector<double>& point);

/// The results of a sweep in DIR: `sweep.json` (what identifies the sweep: log, poses, fixed
/// options), `results.csv` (header, then one row per finished point, appended and flushed as
/// each point finishes, rewritten sorted by point when opened and by Sort()) and `results.json`
/// (all rows sorted by point, rewritten atomically after each point). Opening a DIR that already
/// holds the same sweep loads its finished rows (a torn last line of an interrupted run is
/// dropped); opening one that holds a different sweep throws std::invalid_argument naming the first
/// differing field. Add() is thread-safe.
class SweepResults {
 public:
  SweepResults(std::string dir, nlohmann::json identity, std::vector<std::string> parameter_columns,
               std::vector<std::string> value_columns);

  bool Has(const std::vector<double>& point) const;
  std::size_t size() const;
  void Add(const std::vector<double>& point, const std::vector<double>& values);
  /// What results.json holds: {"sweep": identity, "parameters", "columns", "rows": [...]}.
  nlohmann::json Json() const;
  /// All rows (parameters then values), sorted by point.
  std::vector<std::vector<double>> SortedRows() const;
  /// Rewrites results.csv with its rows sorted by point, as results.json is: rows are appended in
  /// the order the points finish, which depends on the thread count, and a finished sweep's
  /// files must not. Add() may follow.
  void Sort();

 private:
  void WriteCsvLocked();
  void WriteJsonLocked() const;
  nlohmann::json JsonLocked() const;

  std::string dir_;
  nlohmann::json identity_;
  std::vector<std::string> parameter_columns_;
  std::vector<std::string> value_columns_;
  std::map<std::vector<double>, std::vector<double>> rows_;  // point -> values
  std::string csv_header_;
  std::ofstream csv_;
  mutable std::mutex mutex_;
};

}  // namespace keyplace::cli
