#pragma once
// The figures of a result struct, described once beside it: each figure's name (the JSON key of
// the command that prints it and the attribute of the Python object that holds it), its unit,
// its meaning and how to read it from the struct. The JSON writers (tools/) and the Python
// bindings (python/) both walk the same list, so a figure added to the table appears in both,
// under the same name.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace keyplace {

/// A figure's value: a switch, a count, a measurement or a text; std::monostate where the result
/// has no such figure (no loops, so no loop precision; no ground truth, so no ATE): JSON null,
/// Python None. A share of nothing is missing, not 0.
using ResultValue = std::variant<std::monostate, bool, std::int64_t, double, std::string>;

/// A count (a std::size_t: a member, a container's size) as a figure's value.
inline ResultValue CountValue(std::size_t count) { return static_cast<std::int64_t>(count); }

template <typename Result>
struct ResultField {
  std::string name;     // snake_case with the unit in it where it has one: "distance_m"
  std::string unit;     // "m", "s", "deg", "" for counts, fractions and switches
  std::string meaning;  // one line
  std::function<ResultValue(const Result&)> value;
};

template <typename Result>
class ResultFields {
 public:
  ResultFields& Count(const char* name, std::size_t Result::*member, const char* meaning) {
    return Add(name, "", meaning,
               [member](const Result& result) { return CountValue(result.*member); });
  }
  ResultFields& Integer(const char* name, int Result::*member, const char* meaning) {
    return Add(name, "", meaning, [member](const Result& result) -> ResultValue {
      return static_cast<std::int64_t>(result.*member);
    });
  }
  ResultFields& Number(const char* name, double Result::*member, const char* unit,
                       const char* meaning) {
    return Add(name, unit, meaning,
               [member](const Result& result) -> ResultValue { return result.*member; });
  }
  ResultFields& Switch(const char* name, bool Result::*member, const char* meaning) {
    return Add(name, "", meaning,
               [member](const Result& result) -> ResultValue { return result.*member; });
  }
  /// A figure computed from the struct rather than stored in it (ResultValue{} when missing).
  ResultFields& Add(const char* name, const char* unit, const char* meaning,
                    std::function<ResultValue(const Result&)> value) {
    fields_.push_back({name, unit, meaning, std::move(value)});
    return *this;
  }

  const std::vector<ResultField<Result>>& fields() const { return fields_; }

 private:
  std::vector<ResultField<Result>> fields_;
};

}  // namespace keyplace
