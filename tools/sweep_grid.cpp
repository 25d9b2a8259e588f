#include "sweep_grid.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

constexpr std::size_t kMaxValues = 100000;

double Round9(double value) {
  const double rounded = std::round(value * 1e9) / 1e9;
  return rounded == 0.0 ? 0.0 : rounded;  // no -0
}

std::string Trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

double ParseNumber(const std::string& part, const std::string& text, const std::string& option) {
  const std::string trimmed = Trim(part);
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(trimmed, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (trimmed.empty() || used != trimmed.size() || !std::isfinite(value)) {
    throw std::invalid_argument(option + " '" + text + "': '" + part +
                                "' is not a number (expected A:B:STEP or V1,V2,...)");
  }
  return value;
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.emplace_back();
  return parts;
}

std::string FormatValue(double value) { return fmt::format("{}", value); }

}  // namespace

std::vector<double> ParseValueList(const std::string& text, const std::string& option) {
  if (Trim(text).empty()) throw std::invalid_argument(option + ": empty value list");
  std::vector<double> values;
  if (text.find(':') != std::string::npos) {
    const std::vector<std::string> parts = Split(text, ':');
    if (parts.size() != 3) {
      throw std::invalid_argument(option + " '" + text + "': expected A:B:STEP (e.g. 0:1:0.1)");
    }
    const double first = ParseNumber(parts[0], text, option);
    const double last = ParseNumber(parts[1], text, option);
    const double step = ParseNumber(parts[2], text, option);
    if (step <= 0.0) throw std::invalid_argument(option + " '" + text + "': STEP must be > 0");
    if (last < first) throw std::invalid_argument(option + " '" + text + "': B is below A");
    const double steps = std::floor((last - first) / step + 1e-9);
    if (steps + 1.0 > static_cast<double>(kMaxValues)) {
      throw std::invalid_argument(option + " '" + text + "': more than " +
                                  std::to_string(kMaxValues) + " values");
    }
    for (int i = 0; i <= static_cast<int>(steps); ++i) values.push_back(Round9(first + i * step));
  } else {
    for (const std::string& part : Split(text, ',')) {
      values.push_back(Round9(ParseNumber(part, text, option)));
    }
    if (values.size() > kMaxValues) {
      throw std::invalid_argument(option + " '" + text + "': more than " +
                                  std::to_string(kMaxValues) + " values");
    }
  }
  std::set<double> seen;
  for (double value : values) {
    if (!seen.insert(value).second) {
      throw std::invalid_argument(fmt::format("{} '{}': {} appears twice", option, text, value));
    }
  }
  return values;
}

std::vector<std::vector<double>> ExpandGrid(const std::vector<GridAxis>& axes) {
  std::vector<std::vector<double>> points{{}};
  for (const GridAxis& axis : axes) {
    std::vector<std::vector<double>> next;
    next.reserve(points.size() * axis.values.size());
    for (const std::vector<double>& point : points) {
      for (double value : axis.values) {
        next.push_back(point);
        next.back().push_back(value);
      }
    }
    points = std::move(next);
  }
  return points;
}

std::string PointKey(const std::vector<double>& point) {
  std::string key;
  for (std::size_t i = 0; i < point.size(); ++i) {
    if (i > 0) key += ',';
    key += FormatValue(point[i]);
  }
  return key;
}

SweepResults::SweepResults(std::string dir, nlohmann::json identity,
                           std::vector<std::string> parameter_columns,
                           std::vector<std::string> value_columns)
    : dir_(std::move(dir)),
      identity_(std::move(identity)),
      parameter_columns_(std::move(parameter_columns)),
      value_columns_(std::move(value_columns)) {
  namespace fs = std::filesystem;
  fs::create_directories(dir_);
  const fs::path sidecar = fs::path(dir_) / "sweep.json";
  const fs::path csv_path = fs::path(dir_) / "results.csv";
  std::string header;
  for (const auto* columns : {&parameter_columns_, &value_columns_}) {
    for (const std::string& column : *columns) header += (header.empty() ? "" : ",") + column;
  }

  if (fs::exists(sidecar)) {
    nlohmann::json stored;
    try {
      std::ifstream in(sidecar);
      in >> stored;
    } catch (const std::exception& error) {
      throw std::invalid_argument(sidecar.string() + ": unreadable (" + error.what() +
                                  "); delete the directory or choose another --out");
    }
    if (stored != identity_) {
      std::string difference = "the sweep description differs";
      for (const auto& [key, value] : identity_.items()) {
        if (!stored.contains(key)) {
          difference = "'" + key + "' is missing there";
          break;
        }
        if (stored[key] != value) {
          difference =
              "'" + key + "' is " + value.dump() + " here but " + stored[key].dump() + " there";
          break;
        }
      }
      if (difference == "the sweep description differs") {
        for (const auto& [key, value] : stored.items()) {
          if (!identity_.contains(key)) {
            difference = "'" + key + "' is set there (" + value.dump() + ") but not here";
            break;
          }
        }
      }
      throw std::invalid_argument(dir_ + " holds a different sweep (" + difference +
                                  "): refusing to resume it; choose another --out or delete " +
                                  dir_);
    }
    if (fs::exists(csv_path)) {
      std::ifstream in(csv_path);
      std::string line;
      std::getline(in, line);
      if (line != header) {
        throw std::invalid_argument(csv_path.string() + ": header '" + line +
                                    "' is not this sweep's '" + header + "'");
      }
      const std::size_t columns = parameter_columns_.size() + value_columns_.size();
      while (std::getline(in, line)) {
        if (in.eof()) break;  // no newline: torn last line of an interrupted run
        const std::vector<std::string> fields = Split(line, ',');
        if (fields.size() != columns) continue;
        std::vector<double> row;
        try {
          for (const std::string& field : fields) row.push_back(std::stod(field));
        } catch (const std::exception&) {
          continue;
        }
        std::vector<double> point(row.begin(), row.begin() + parameter_columns_.size());
        std::vector<double> values(row.begin() + parameter_columns_.size(), row.end());
        rows_[point] = values;
      }
    }
  } else {
    WriteFileAtomically(sidecar.string(),
                        [&](std::ostream& out) { out << identity_.dump(2) << '\n'; });
  }

  csv_header_ = header;
  // Rewrite the CSV with the valid rows only (drops a torn line), then append to it.
  std::lock_guard<std::mutex> lock(mutex_);
  WriteCsvLocked();
  WriteJsonLocked();
}

void SweepResults::Sort() {
  std::lock_guard<std::mutex> lock(mutex_);
  WriteCsvLocked();
}

void SweepResults::WriteCsvLocked() {
  const std::filesystem::path csv_path = std::filesystem::path(dir_) / "results.csv";
  // The stream would go on appending to the file the rename replaces.
  if (csv_.is_open()) csv_.close();
  WriteFileAtomically(csv_path.string(), [&](std::ostream& out) {
    out << csv_header_ << '\n';
    for (const auto& [point, values] : rows_) {
      std::vector<double> row = point;
      row.insert(row.end(), values.begin(), values.end());
      out << PointKey(row) << '\n';
    }
  });
  csv_.open(csv_path, std::ios::app);
  if (!csv_) throw std::runtime_error(csv_path.string() + ": cannot open for appending");
}

bool SweepResults::Has(const std::vector<double>& point) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rows_.count(point) > 0;
}

std::size_t SweepResults::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rows_.size();
}

void SweepResults::Add(const std::vector<double>& point, const std::vector<double>& values) {
  if (point.size() != parameter_columns_.size() || values.size() != value_columns_.size()) {
    throw std::invalid_argument("SweepResults::Add: wrong number of columns");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  rows_[point] = values;
  std::vector<double> row = point;
  row.insert(row.end(), values.begin(), values.end());
  csv_ << PointKey(row) << '\n';
  csv_.flush();
  if (!csv_) throw std::runtime_error(dir_ + "/results.csv: write failed");
  WriteJsonLocked();
}

std::vector<std::vector<double>> SweepResults::SortedRows() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::vector<double>> rows;
  for (const auto& [point, values] : rows_) {
    rows.push_back(point);
    rows.back().insert(rows.back().end(), values.begin(), values.end());
  }
  return rows;
}

nlohmann::json SweepResults::Json() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return JsonLocked();
}

void SweepResults::WriteJsonLocked() const {
  const nlohmann::json json = JsonLocked();
  WriteFileAtomically((std::filesystem::path(dir_) / "results.json").string(),
                      [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

nlohmann::json SweepResults::JsonLocked() const {
  nlohmann::json json;
  json["sweep"] = identity_;
  json["parameters"] = parameter_columns_;
  json["columns"] = value_columns_;
  const auto number = [](double value) -> nlohmann::json {
    if (std::floor(value) == value && std::abs(value) < 1e15) {
      return static_cast<std::int64_t>(value);
    }
    return value;
  };
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [point, values] : rows_) {  // std::map: sorted by point
    nlohmann::json row;
    for (std::size_t i = 0; i < point.size(); ++i) row[parameter_columns_[i]] = number(point[i]);
    for (std::size_t i = 0; i < values.size(); ++i) row[value_columns_[i]] = number(values[i]);
    rows.push_back(row);
  }
  json["rows"] = rows;
  return json;
}

}  // namespace keyplace::cli
