#pragma once
// Checks of a result struct's figure table (keyplace/common/result_fields.hpp), for the tests of
// the modules that define one.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "keyplace/common/result_fields.hpp"

namespace keyplace {

/// The value of the figure `name`; a test failure when the table has none.
template <typename Result>
ResultValue ValueOf(const ResultFields<Result>& fields, const Result& result,
                    const std::string& name) {
  for (const ResultField<Result>& field : fields.fields()) {
    if (field.name == name) return field.value(result);
  }
  ADD_FAILURE() << "no figure " << name;
  return ResultValue{};
}

/// Names unique; a name ends in "_m" exactly when its unit is m, holds "seconds" exactly when its
/// unit is s; every figure reads a different member (`distinct` holds a different value in each).
template <typename Result>
void ExpectWellFormed(const ResultFields<Result>& fields, const Result& distinct) {
  std::set<std::string> names;
  std::set<ResultValue> values;
  for (const ResultField<Result>& field : fields.fields()) {
    EXPECT_TRUE(names.insert(field.name).second) << field.name << " twice";
    EXPECT_FALSE(field.meaning.empty()) << field.name;
    const auto ends_with = [&](const std::string& suffix) {
      return field.name.size() > suffix.size() &&
             field.name.compare(field.name.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    EXPECT_EQ(field.unit == "m", ends_with("_m")) << field.name;
    EXPECT_EQ(field.unit == "s", field.name.find("seconds") != std::string::npos) << field.name;
    EXPECT_TRUE(values.insert(field.value(distinct)).second)
        << field.name << " reads a member another figure reads too";
  }
}

}  // namespace keyplace
