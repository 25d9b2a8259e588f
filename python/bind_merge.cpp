// Multi-session maps (localization/map_merge.hpp): merge_maps finds where map B lies in map A and
// joins them, as `keyplace merge` does.

#include <string>
#include <utility>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/localization/map_merge.hpp"
#include "result_fields.hpp"

namespace keyplace::python {
namespace {

py::object MergeMapsOf(const py::object& a, const py::object& b, const py::object& config,
                       const py::object& overrides, const py::object& progress) {
  // `keyplace merge` acts on the answer as a robot would: the strict preset unless told otherwise.
  const PyConfig resolved = ResolveConfig(config.is_none() ? py::str("strict") : config, overrides);
  const GlobalMap map_a = ToMap(a);
  const GlobalMap map_b = ToMap(b);
  const MergeProgress callback = ToProgress(progress);
  MergeResult result;
  {
    py::gil_scoped_release release;
    result = MergeMaps(map_a, map_b, resolved.config.place, resolved.config.merge, callback);
  }
  py::object merged = py::cast(std::move(result));
  merged.attr("config") = py::cast(resolved);
  return merged;
}

void BindRecognition(py::module_& module) {
  py::class_<SubmapRecognition> recognition(
      module, "SubmapRecognition", "One submap of B recognised in A (an accepted answer).");
  DefResultFields(recognition, SubmapRecognitionFields());
  recognition
      .def_property_readonly(
          "T_a_b", [](const SubmapRecognition& r) { return PoseArray(r.T_a_b); },
          "B's frame in A's frame [x_m, y_m, theta_rad] as this recognition alone says.")
      .def("__repr__", [](const SubmapRecognition& r) {
        return "<keyplace.SubmapRecognition B " + std::to_string(r.submap_b) + " in A " +
               std::to_string(r.submap_a) + (r.agrees ? ", agrees>" : ", disagrees>");
      });
}

void BindMergeResult(py::module_& module) {
  // dynamic_attr: merge_maps sets `config`, the keyplace.Config it merged with.
  py::class_<MergeResult> result(module, "MergeResult", py::dynamic_attr(),
                                 "Where map B lies in map A, and the two joined; `config` is the "
                                 "keyplace.Config used (the CLI JSON's 'config').");
  DefResultFields(result, MergeResultFields());
  result
      .def_property_readonly(
          "T_a_b", [](const MergeResult& r) { return PoseArray(r.T_a_b); },
          "B's frame in A's frame [x_m, y_m, theta_rad]: a point p_b of B is T_a_b * p_b in A; "
          "fitted to the agreeing recognitions (mean heading, then least-squares translation).")
      .def_readonly("merged", &MergeResult::merged,
                    "The merged Map in A's frame: A's submaps, then B's moved by T_a_b (ids from "
                    "the second thousand after A's last, scan numbers after A's).")
      .def_readonly("recognitions", &MergeResult::recognitions,
                    "The accepted recognitions (list of SubmapRecognition), in B's map order.")
      .def("__repr__", [](const MergeResult& r) {
        return "<keyplace.MergeResult " + std::to_string(r.agreeing) + " of " +
               std::to_string(r.recognitions.size()) + " recognitions agree, " +
               std::to_string(r.merged.submaps.size()) + " submaps merged>";
      });
}

}  // namespace

void BindMerge(py::module_& module) {
  BindRecognition(module);
  BindMergeResult(module);
  module.def("merge_maps", &MergeMapsOf, py::arg("a"), py::arg("b"), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(), py::arg("progress") = py::none(),
             "merge_maps(a, b, config=None, overrides=None, progress=None) -> MergeResult: what "
             "`keyplace merge` does (docs/MERGE.md). a and b are Maps or .kpm paths, made with "
             "the same mapping settings; every submap of B is recognised in A and the largest "
             "group of recognitions agreeing on where B lies (at least merge.min_agreeing, "
             "within merge.agree_m / agree_deg) gives T_a_b. config: None is the strict preset, "
             "as in the CLI. progress: None or progress(done, total) after each B submap. Raises "
             "ValueError with the library's reason for different mapping settings or no reliable "
             "overlap, RuntimeError for a map file that cannot be read.");
}

}  // namespace keyplace::python
