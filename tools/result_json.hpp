#pragma once
// A result struct's figures as JSON keys, from its table (keyplace/common/result_fields.hpp).

#include <variant>

#include <nlohmann/json.hpp>

#include "keyplace/common/result_fields.hpp"

namespace keyplace::cli {

/// Sets json[name] for every figure of `fields` (a count as an integer, a non-finite number as
/// null, as nlohmann writes it).
template <typename Result>
void AddResultFields(const Result& result, const ResultFields<Result>& fields,
                     nlohmann::json& json) {
  for (const ResultField<Result>& field : fields.fields()) {
    json[field.name] =
        std::visit([](const auto& value) { return nlohmann::json(value); }, field.value(result));
  }
}

}  // namespace keyplace::cli
