#pragma once
// A result struct's figures as read-only Python properties, from its table
// (keyplace/common/result_fields.hpp): the same names as the command's --json keys.

#include <string>
#include <type_traits>
#include <variant>

#include <pybind11/pybind11.h>

#include "keyplace/common/result_fields.hpp"

namespace keyplace::python {

namespace py = pybind11;

/// One property per figure of `fields`, read from the Result that `result_of` finds in an
/// instance of the bound class (None for a missing figure); the docstring is the figure's meaning
/// and unit.
template <typename Holder, typename Result, typename ResultOf, typename... Options>
void DefResultFieldsOf(py::class_<Holder, Options...>& cls, const ResultFields<Result>& fields,
                       ResultOf result_of) {
  for (const ResultField<Result>& field : fields.fields()) {
    const std::string doc = field.meaning + (field.unit.empty() ? "" : " (" + field.unit + ")");
    const auto read = field.value;
    cls.def_property_readonly(
        field.name.c_str(),
        [read, result_of](const Holder& holder) -> py::object {
          return std::visit(
              [](const auto& value) -> py::object {
                if constexpr (std::is_same_v<std::decay_t<decltype(value)>, std::monostate>) {
                  return py::none();
                } else {
                  return py::cast(value);
                }
              },
              read(result_of(holder)));
        },
        doc.c_str());
  }
}

/// For a bound class holding the Result at `member`.
template <typename Holder, typename Result, typename... Options>
void DefResultFields(py::class_<Holder, Options...>& cls, const ResultFields<Result>& fields,
                     Result Holder::*member) {
  DefResultFieldsOf(cls, fields,
                    [member](const Holder& holder) -> const Result& { return holder.*member; });
}

/// For a bound class that is the Result itself.
template <typename Result, typename... Options>
void DefResultFields(py::class_<Result, Options...>& cls, const ResultFields<Result>& fields) {
  DefResultFieldsOf(cls, fields, [](const Result& result) -> const Result& { return result; });
}

}  // namespace keyplace::python
