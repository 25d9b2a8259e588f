// The kidnapped-robot benchmark of `keyplace relocalize` (eval/relocalization.hpp): its records per
// start and fix, its summary figures (the keys of `keyplace relocalize --json`) and its first fix
// as the /initialpose message.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "result_fields.hpp"

namespace keyplace::python {
namespace {

// One benchmark run: what it was run on, its options, records and summary.
struct PyRelocalization {
  PyConfig config;  // the whole configuration of the run
  std::size_t first_scan = 0;
  std::size_t end_scan = 0;
  PoseSource pose_source = PoseSource::kCorrected;
  bool query_log_is_map_log = false;
  RelocalizationOptions options;
  std::vector<StartRecord> records;
  RelocalizationSummary summary;
  double keypoint_seconds_per_scan = 0.0;
};

std::string TextOrEmpty(const py::object& value) {
  return value.is_none() ? std::string() : py::str(value).cast<std::string>();
}

PyRelocalization Relocalize(const std::string& log_path, const py::object& map,
                            const py::object& config, const py::object& overrides,
                            const std::string& poses, const py::object& truth,
                            const py::object& index, const py::object& scans, int starts,
                            const std::string& self_match, bool skip_bad_lines,
                            const py::object& progress) {
  // `keyplace relocalize`: a robot acts on a fix, so the strict preset unless told otherwise.
  const PyConfig resolved_config =
      ResolveConfig(config.is_none() ? py::str("strict") : config, overrides);
  const Config& resolved = resolved_config.config;
  if (self_match != "shared-scan" && self_match != "none") {
    throw py::value_error("self_match is '" + self_match + "': 'shared-scan' or 'none'");
  }
  LogInputOptions input_options = LogInputOptionsFor(resolved);
  input_options.reading.skip_bad_lines = skip_bad_lines;
  input_options.poses = ParsePoseSource(poses);
  ApplyScans(scans, input_options);
  const std::string truth_path = TextOrEmpty(truth);
  const std::string index_path = TextOrEmpty(index);
  const GlobalMap global_map = ToMap(map);
  const StartProgress callback = ToProgress(progress);

  py::gil_scoped_release release;
  const LogInputs inputs = PrepareLogInputs(log_path, input_options);
  const GroundTruth ground_truth = LoadGroundTruth(inputs.log, inputs.first_scan, inputs.file_scans,
                                                   truth_path, index_path, inputs.source_hash);
  PyRelocalization run;
  run.config = resolved_config;
  run.first_scan = inputs.first_scan;
  run.end_scan = inputs.first_scan + inputs.log.scans.size();
  run.pose_source = inputs.pose_source;
  run.query_log_is_map_log = TruthIsMapLog(global_map, ground_truth);
  run.options = RelocalizationOptionsFor(resolved.evaluation, starts, self_match == "shared-scan",
                                         run.query_log_is_map_log);
  run.keypoint_seconds_per_scan =
      inputs.seconds_keypoints / static_cast<double>(inputs.log.scans.size());
  run.records = RunRelocalization(global_map, inputs, ground_truth, ToLocalizerConfig(resolved),
                                  run.options, callback);
  run.summary = SummarizeRelocalization(run.records, run.options);
  return run;
}

void BindRecords(py::module_& module) {
  py::class_<FixEvent> fix(module, "FixEvent", "One fix the relocalizer reported, checked.");
  DefResultFields(fix, FixEventFields());
  fix.def_property_readonly(
         "pose", [](const FixEvent& f) { return PoseArray(f.T_world_robot); },
         "T_world_robot (map frame) at checked_scan.")
      .def_property_readonly(
          "truth", [](const FixEvent& f) { return PoseArray(f.truth); },
          "True T_world_robot at checked_scan.")
      .def_property_readonly(
          "pose_at_fix", [](const FixEvent& f) { return PoseArray(f.initial_pose.T_map_robot); },
          "T_world_robot as reported at `scan` (what a robot publishes).")
      .def(
          "initial_pose",
          [](const FixEvent& f, const std::string& frame_id) {
            InitialPose pose = f.initial_pose;
            pose.frame_id = frame_id;
            return pose;
          },
          py::arg("frame_id") = "map",
          "The fix as the /initialpose message (InitialPose), as reported at `scan`.");

  py::class_<StartRecord> record(module, "StartRecord", "One start of the benchmark.");
  DefResultFields(record, StartRecordFields());
  record.def_readonly("fixes", &StartRecord::fixes, "The fixes reported (list of FixEvent).");
}

void BindRelocalizationEvaluation(py::module_& module) {
  py::class_<PyRelocalization> cls(
      module, "RelocalizationEvaluation",
      "What `keyplace relocalize` measures: the summary figures (named as in its --json), one "
      "StartRecord per start, and the first fix.");
  DefResultFields(cls, RelocalizationSummaryFields(), &PyRelocalization::summary);
  cls.def_readonly("config", &PyRelocalization::config,
                   "The keyplace.Config of the run (the CLI's JSON 'config').")
      .def_readonly("keypoint_seconds_per_scan", &PyRelocalization::keypoint_seconds_per_scan)
      .def_readonly("query_log_is_map_log", &PyRelocalization::query_log_is_map_log)
      .def_property_readonly(
          "scans",
          [](const PyRelocalization& r) { return std::make_pair(r.first_scan, r.end_scan); },
          "(first, end) scans of the query log the starts were spread over.")
      .def_property_readonly("pose_source",
                             [](const PyRelocalization& r) { return ToString(r.pose_source); })
      .def_property_readonly(
          "exclude_shared_scans",
          [](const PyRelocalization& r) { return r.options.exclude_shared_scans; },
          "Map submaps sharing a scan with the query were skipped (the map's own log).")
      .def_property_readonly("give_up_m",
                             [](const PyRelocalization& r) { return r.options.give_up_m; })
      .def_property_readonly("follow_m",
                             [](const PyRelocalization& r) { return r.options.follow_m; })
      .def_property_readonly("revisit_room_m",
                             [](const PyRelocalization& r) { return r.options.revisit_room_m; })
      .def_readonly("records", &PyRelocalization::records, "One StartRecord per start.")
      .def(
          "first_fix",
          [](const PyRelocalization& r) -> py::object {
            const std::optional<FirstFix> first = FirstFixOf(r.records);
            if (!first) return py::none();
            return py::make_tuple(first->start_scan, first->fix);
          },
          "(start_scan, FixEvent) of the first fix of the first start that got one, or None.")
      .def(
          "initial_pose",
          [](const PyRelocalization& r, const std::string& frame_id) -> py::object {
            const std::optional<FirstFix> first = FirstFixOf(r.records);
            if (!first) return py::none();
            InitialPose pose = first->fix.initial_pose;
            pose.frame_id = frame_id;
            return py::cast(pose);
          },
          py::arg("frame_id") = "map",
          "The first fix as the /initialpose message (what `--initialpose` writes), or None.");
}

}  // namespace

void BindRelocalization(py::module_& module) {
  BindRecords(module);
  BindRelocalizationEvaluation(module);
  module.def("relocalize", &Relocalize, py::arg("log"), py::arg("map"),
             py::arg("config") = py::none(), py::arg("overrides") = py::none(),
             py::arg("poses") = "corrected", py::arg("truth") = py::none(),
             py::arg("index") = py::none(), py::arg("scans") = py::none(), py::arg("starts") = 50,
             py::arg("self_match") = "shared-scan", py::arg("skip_bad_lines") = false,
             py::arg("progress") = py::none(),
             "relocalize(log, map, config=None, overrides=None, poses='corrected', truth=None, "
             "index=None, scans=None, starts=50, self_match='shared-scan', "
             "skip_bad_lines=False, progress=None) -> RelocalizationEvaluation: the "
             "kidnapped-robot benchmark `keyplace relocalize` runs: from `starts` starts over the "
             "log a Relocalizer knowing nothing is fed scans and odometry (poses) until it fixes "
             "or gives up; every fix is checked against the truth (the log's corrected poses, or "
             "truth + index for a raw log). map: a Map or a .kpm path; config None is the strict "
             "preset, as in the CLI; progress(done, total) after each start. The starts run in "
             "parallel on all cores.");
}

}  // namespace keyplace::python
