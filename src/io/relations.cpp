#include "keyplace/io/relations.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string_view>

namespace keyplace {
namespace {

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

[[noreturn]] void Fail(const std::string& path, std::size_t line, const std::string& what) {
  throw std::invalid_argument(path + ":" + std::to_string(line) + ": " + what);
}

double ParseDouble(std::string_view text, const std::string& path, std::size_t line,
                   const char* field) {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (!text.empty() && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) {
    Fail(path, line,
         std::string("field ") + field + ": not a finite number: '" + std::string(text) + "'");
  }
  return value;
}

std::size_t ParseIndex(std::string_view text, const std::string& path, std::size_t line,
                       const char* field) {
  std::size_t value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size()) {
    Fail(path, line,
         std::string("field ") + field + ": not a non-negative integer: '" + std::string(text) +
             "'");
  }
  return value;
}

bool SkipLine(std::string_view line) {
  for (const char c : line) {
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    return c == '#';
  }
  return true;  // blank
}

// Calls `handle(line_number, fields)` for every line of a text table that is neither blank nor a
// '#' comment. Throws std::runtime_error naming the path when it cannot be read.
void ForEachDataLine(
    const std::string& path,
    const std::function<void(std::size_t, const std::vector<std::string_view>&)>& handle) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::string text;
  std::size_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (SkipLine(text)) continue;
    handle(line, SplitFields(text));
  }
  if (in.bad()) throw std::runtime_error("error while reading '" + path + "'");
}

}  // namespace

std::vector<Relation> ReadRelations(const std::string& path) {
  static const char* const kFields[] = {"t_a", "t_b", "dx", "dy", "dz", "droll", "dpitch", "dyaw"};
  std::vector<Relation> relations;
  ForEachDataLine(path, [&](std::size_t line, const std::vector<std::string_view>& fields) {
    if (fields.size() != 8) {
      Fail(path, line,
           "expected 8 fields (t_a t_b dx dy dz droll dpitch dyaw), found " +
               std::to_string(fields.size()));
    }
    double values[8];
    for (int i = 0; i < 8; ++i) values[i] = ParseDouble(fields[i], path, line, kFields[i]);
    Relation relation;
    relation.timestamp_a_s = values[0];
    relation.timestamp_b_s = values[1];
    relation.T_a_b = Pose2(values[2], values[3], values[7]);
    relation.line = line;
    relations.push_back(relation);
  });
  return relations;
}

std::vector<IndexPair> ReadIndexPairs(const std::string& path) {
  std::vector<IndexPair> pairs;
  ForEachDataLine(path, [&](std::size_t line, const std::vector<std::string_view>& fields) {
    if (line == 1 && !fields.empty() && std::isalpha(static_cast<unsigned char>(fields[0][0]))) {
      return;  // header
    }
    if (fields.size() != 2) {
      Fail(path, line,
           "expected 2 fields (raw_index corrected_index), found " + std::to_string(fields.size()));
    }
    pairs.push_back({ParseIndex(fields[0], path, line, "raw_index"),
                     ParseIndex(fields[1], path, line, "corrected_index")});
  });
  return pairs;
}

}  // namespace keyplace
