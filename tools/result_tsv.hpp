#pragma once
// A result struct's figures as TSV columns, from its table (keyplace/common/result_fields.hpp):
// the header is the figures' names, so a column is named as the JSON key and Python property.

#include <string>
#include <type_traits>
#include <variant>

#include <fmt/core.h>

#include "keyplace/common/result_fields.hpp"

namespace keyplace::cli {

/// The figures' names, tab-separated.
template <typename Result>
std::string ResultTsvHeader(const ResultFields<Result>& fields) {
  std::string header;
  for (const ResultField<Result>& field : fields.fields()) {
    if (!header.empty()) header += '\t';
    header += field.name;
  }
  return header;
}

/// One cell: a switch as 0 / 1, a number in the shortest form that reads back exactly, a
/// missing figure empty (as pandas and numpy read a missing value).
inline std::string ResultTsvCell(const ResultValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::monostate>) {
          return "";
        } else if constexpr (std::is_same_v<T, bool>) {
          return v ? "1" : "0";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return v;
        } else {
          return fmt::format("{}", v);
        }
      },
      value);
}

/// `result`'s figures in the order of ResultTsvHeader, tab-separated.
template <typename Result>
std::string ResultTsvRow(const Result& result, const ResultFields<Result>& fields) {
  std::string row;
  for (const ResultField<Result>& field : fields.fields()) {
    if (!row.empty()) row += '\t';
    row += ResultTsvCell(field.value(result));
  }
  return row;
}

}  // namespace keyplace::cli
