#pragma once
// A result struct's figures as JSON keys, from its table (keyplace/common/result_fields.hpp).

#include <type_traits>
#include <variant>

#include <nlohmann/json.hpp>

#include "keyplace/common/result_fields.hpp"

namespace keyplace::cli {

/// Sets json[name] for every figure of `fields` (a count as an integer; a missing figure, and a
/// non-finite number as nlohmann writes it, as null).
template <typename Result>
void AddResultFields(const Result& result, const ResultFields<Result>& fields,
                     nlohmann::json& json) {
  for (const ResultField<Result>& field : fields.fields()) {
    json[field.name] = std::visit(
        [](const auto& value) -> nlohmann::json {
          if constexpr (std::is_same_v<std::decay_t<decltype(value)>, std::monostate>) {
            return nullptr;
          } else {
            return value;
          }
        },
        field.value(result));
  }
}

}  // namespace keyplace::cli
