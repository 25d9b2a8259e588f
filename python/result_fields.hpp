#pragma once
// A result struct's figures as read-only Python properties, from its table
// (keyplace/common/result_fields.hpp): the same names as the command's --json keys.

#include <string>
#include <variant>

#include <pybind11/pybind11.h>

#include "keyplace/common/result_fields.hpp"

namespace keyplace::python {

namespace py = pybind11;

/// One property per figure of `fields`, read from the Result held at `member` of the bound
/// class; the docstring is the figure's meaning and unit.
template <typename Holder, typename Result, typename... Options>
void DefResultFields(py::class_<Holder, Options...>& cls, const ResultFields<Result>& fields,
                     Result Holder::*member) {
  for (const ResultField<Result>& field : fields.fields()) {
    const std::string doc = field.meaning + (field.unit.empty() ? "" : " (" + field.unit + ")");
    const auto read = field.value;
    cls.def_property_readonly(
        field.name.c_str(),
        [read, member](const Holder& holder) -> py::object {
          return std::visit([](const auto& value) -> py::object { return py::cast(value); },
                            read(holder.*member));
        },
        doc.c_str());
  }
}

/// The same for a bound class that is the result itself.
template <typename Result, typename... Options>
void DefResultFields(py::class_<Result, Options...>& cls, const ResultFields<Result>& fields) {
  for (const ResultField<Result>& field : fields.fields()) {
    const std::string doc = field.meaning + (field.unit.empty() ? "" : " (" + field.unit + ")");
    const auto read = field.value;
    cls.def_property_readonly(
        field.name.c_str(),
        [read](const Result& result) -> py::object {
          return std::visit([](const auto& value) -> py::object { return py::cast(value); },
                            read(result));
        },
        doc.c_str());
  }
}

}  // namespace keyplace::python
