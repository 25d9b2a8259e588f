// The evaluations of `keyplace localize` and `keyplace slam` (eval/map_localization.hpp,
// eval/slam_evaluation.hpp), their results as attributes and numpy arrays.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/map_localization.hpp"
#include "keyplace/eval/slam_evaluation.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"
#include "result_fields.hpp"

namespace keyplace::python {
namespace {

// How the evaluated log is read: the config's input, features and odometry sections, a pose
// source and a scan range (first, end) as `--scans`.
LogInputOptions InputOptions(const Config& config, const py::object& scans) {
  LogInputOptions options = LogInputOptionsFor(config);
  ApplyScans(scans, options);
  return options;
}

std::string TextOrEmpty(const py::object& value) {
  return value.is_none() ? std::string() : py::str(value).cast<std::string>();
}

template <typename T, typename Field>
py::array_t<T> RecordColumn(const MapLocalization& result, Field field) {
  std::vector<T> values;
  values.reserve(result.records.size());
  for (const LocalizationRecord& record : result.records) values.push_back(field(record));
  return VectorArray(values);
}

MapLocalization Localize(const std::string& log_path, const py::object& map,
                         const py::object& config, const py::object& overrides,
                         const std::string& poses, const py::object& truth, const py::object& index,
                         const py::object& scans, int n_pos, bool exclude_shared_scans,
                         const py::object& rank_by) {
  const PyConfig resolved = ResolveConfig(config, overrides);
  LogInputOptions input_options = InputOptions(resolved.config, scans);
  input_options.poses = ParsePoseSource(poses);
  MapLocalizationOptions options;
  options.n_pos = n_pos;
  options.self_match =
      exclude_shared_scans ? SelfMatchRule::kSharedScan : SelfMatchRule::kSameScans;
  // The CLI's default ranking: gamma for the paper preset, confidence otherwise.
  options.rank_by = ParseRankBy(!rank_by.is_none()           ? rank_by.cast<std::string>()
                                : resolved.preset == "paper" ? "gamma"
                                                             : "confidence");
  const std::string truth_path = TextOrEmpty(truth);
  const std::string index_path = TextOrEmpty(index);
  std::optional<GlobalMap> given_map;
  if (py::isinstance<GlobalMap>(map)) given_map = map.cast<const GlobalMap&>();
  const std::string map_path = given_map ? std::string() : py::str(map).cast<std::string>();

  py::gil_scoped_release release;
  const GlobalMap global_map = given_map ? std::move(*given_map) : LoadMap(map_path);
  const LogInputs inputs = PrepareLogInputs(log_path, input_options);
  const GroundTruth ground_truth = LoadGroundTruth(inputs.log, inputs.first_scan, inputs.file_scans,
                                                   truth_path, index_path, inputs.source_hash);
  return LocalizeLogAgainstMap(inputs, ground_truth, global_map, resolved.config.place,
                               resolved.config.evaluation, options);
}

void BindLocalizationEvaluation(py::module_& module) {
  py::class_<MapLocalization> cls(module, "LocalizationEvaluation",
                                  "What `keyplace localize` measures: one record per query "
                                  "(arrays in query order) and the summary figures.");
  DefResultFields(cls, LocalizationSummaryFields(), &MapLocalization::summary);
  cls.def_property_readonly(
         "curve",
         [](const MapLocalization& r) {
           py::array_t<double> array(
               {static_cast<py::ssize_t>(r.summary.curve.size()), py::ssize_t{3}});
           auto view = array.mutable_unchecked<2>();
           for (py::ssize_t i = 0; i < view.shape(0); ++i) {
             const PrPoint& point = r.summary.curve[static_cast<std::size_t>(i)];
             view(i, 0) = point.threshold;
             view(i, 1) = point.precision;
             view(i, 2) = point.recall;
           }
           return array;
         },
         "N x 3 precision-recall curve rows [threshold, precision, recall].")
      .def_readonly("truth_is_map_log", &MapLocalization::truth_is_map_log)
      .def_readonly("places", &MapLocalization::places)
      .def_readonly("seconds_queries", &MapLocalization::seconds_queries)
      .def_readonly("seconds_recognition", &MapLocalization::seconds_recognition)
      .def_property_readonly(
          "start_scans",
          [](const MapLocalization& r) {
            return RecordColumn<int>(r, [](const LocalizationRecord& x) { return x.start_scan; });
          },
          "Query-log scan each query started at.")
      .def_property_readonly(
          "evaluated_scans",
          [](const MapLocalization& r) {
            return RecordColumn<int>(r,
                                     [](const LocalizationRecord& x) { return x.evaluated_scan; });
          },
          "The scan whose pose each query estimated.")
      .def_property_readonly("accepted",
                             [](const MapLocalization& r) {
                               return RecordColumn<bool>(
                                   r, [](const LocalizationRecord& x) { return x.match.found; });
                             })
      .def_property_readonly(
          "correct",
          [](const MapLocalization& r) {
            return RecordColumn<bool>(r, [](const LocalizationRecord& x) { return x.correct; });
          },
          "Accepted and within evaluation.max_translation_m / max_rotation_deg of the truth.")
      .def_property_readonly("confidences",
                             [](const MapLocalization& r) {
                               return RecordColumn<double>(r, [](const LocalizationRecord& x) {
                                 return x.match.confidence;
                               });
                             })
      .def_property_readonly(
          "estimated_poses",
          [](const MapLocalization& r) {
            std::vector<Pose2> poses;
            for (const LocalizationRecord& x : r.records) poses.push_back(x.match.estimated_pose);
            return PosesArray(poses);
          },
          "N x 3 estimated T_world_robot (map frame; meaningful where a match was verified).")
      .def_property_readonly(
          "truth_poses",
          [](const MapLocalization& r) {
            std::vector<Pose2> poses;
            for (const LocalizationRecord& x : r.records) poses.push_back(x.truth);
            return PosesArray(poses);
          },
          "N x 3 true T_world_robot of the evaluated scans.");

  module.def("localize", &Localize, py::arg("log"), py::arg("map"), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(), py::arg("poses") = "corrected",
             py::arg("truth") = py::none(), py::arg("index") = py::none(),
             py::arg("scans") = py::none(), py::arg("n_pos") = 500,
             py::arg("exclude_shared_scans") = false, py::arg("rank_by") = py::none(),
             "localize(log, map, config=None, overrides=None, poses='corrected', truth=None, "
             "index=None, scans=None, n_pos=500, exclude_shared_scans=False, rank_by=None) -> "
             "LocalizationEvaluation: the evaluation `keyplace localize` runs (paper Algorithm "
             "4): n_pos query submaps of the log against the map (a Map or a .kpm path), "
             "checked against the log's corrected poses (or truth + index for a raw log).");
}

void BindSlam(py::module_& module) {
  py::class_<SlamRun> slam_run(module, "SlamRun", "A finished SLAM run on a log.");
  slam_run.def_readonly("map", &SlamRun::map, "The SLAM map (pose_source 'slam').")
      .def_property_readonly(
          "poses",
          [](const SlamRun& run) {
            std::vector<Pose2> poses;
            for (const auto& pose : run.trajectory) poses.push_back(pose.T_world_robot);
            return PosesArray(poses);
          },
          "N x 3 optimised T_world_robot of every scan, in processing order.")
      .def_property_readonly(
          "icp_poses",
          [](const SlamRun& run) {
            std::vector<Pose2> poses;
            for (const auto& pose : run.trajectory) poses.push_back(pose.T_world_robot_icp);
            return PosesArray(poses);
          },
          "N x 3 ICP odometry poses (before any loop correction).")
      .def_property_readonly(
          "scan_indices",
          [](const SlamRun& run) {
            std::vector<int> indices;
            for (const auto& pose : run.trajectory) indices.push_back(pose.scan_index);
            return VectorArray(indices);
          },
          "Log scan (index of the scans given) of each trajectory row.");
  DefResultFields(slam_run, SlamRunFields());

  py::class_<SlamEvaluation> evaluation(module, "SlamEvaluation", "The evaluation of a SLAM run.");
  DefResultFields(evaluation, SlamEvaluationFields());
  evaluation.def_readonly("has_truth", &SlamEvaluation::has_truth)
      .def_readonly("mapping", &SlamEvaluation::mapping, "MappingStats of the SLAM map.")
      .def_property_readonly(
          "rpe",
          [](const SlamEvaluation& e) -> py::object {
            if (!e.accuracy) return py::none();
            const auto& rpe = e.accuracy->rpe;
            py::array_t<double> array({static_cast<py::ssize_t>(rpe.size()), py::ssize_t{4}});
            auto view = array.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < view.shape(0); ++i) {
              const RpePoint& point = rpe[static_cast<std::size_t>(i)];
              view(i, 0) = static_cast<double>(point.delta);
              view(i, 1) = static_cast<double>(point.count);
              view(i, 2) = point.translation_rmse_m;
              view(i, 3) = point.rotation_rmse_deg;
            }
            return array;
          },
          "N x 4 RPE rows [delta (scans), pairs, translation RMSE (m), rotation RMSE (deg)]; "
          "None without truth.")
      .def_property_readonly(
          "truth_positions", [](const SlamEvaluation& e) { return PointsArray(e.figure.truth); },
          "N x 2 true positions of the paired scans (empty without truth).")
      .def_property_readonly(
          "aligned_positions",
          [](const SlamEvaluation& e) { return PointsArray(e.figure.estimated); },
          "N x 2 SLAM positions, aligned to the truth by the ATE alignment when there is one.");
}

py::tuple Slam(const std::string& log_path, const py::object& config, const py::object& overrides,
               const py::object& truth, const py::object& index, const py::object& relations,
               const std::string& order, const py::object& scans) {
  const Config resolved = ResolveConfig(config, overrides).config;
  LogInputOptions input_options = InputOptions(resolved, scans);
  input_options.compute_poses = false;  // SLAM estimates them
  const std::string truth_path = TextOrEmpty(truth);
  const std::string index_path = TextOrEmpty(index);
  const std::string relations_path = TextOrEmpty(relations);
  const ProcessingOrder processing_order = ParseProcessingOrder(order);
  auto run = std::make_unique<SlamRun>();
  auto evaluation = std::make_unique<SlamEvaluation>();
  {
    py::gil_scoped_release release;
    const LogInputs inputs = PrepareLogInputs(log_path, input_options);
    // A corrected log is its own truth; a raw one needs truth + index (TruthFromIndex).
    std::optional<GroundTruth> ground_truth;
    if (!truth_path.empty() || !index_path.empty() || inputs.log.corrected) {
      ground_truth = LoadGroundTruth(inputs.log, inputs.first_scan, inputs.file_scans, truth_path,
                                     index_path, inputs.source_hash);
    }
    std::optional<std::vector<Relation>> relation_list;
    if (!relations_path.empty()) relation_list = ReadRelations(relations_path);
    *run = RunSlamOnLog(inputs, ToSlamConfig(resolved), resolved.features, processing_order);
    run->map.configuration = ConfigToYaml(resolved);
    *evaluation = EvaluateSlam(*run, ground_truth ? &*ground_truth : nullptr,
                               relation_list ? &*relation_list : nullptr, resolved.evaluation);
  }
  return py::make_tuple(py::cast(std::move(run)), py::cast(std::move(evaluation)));
}

}  // namespace

void BindEvaluation(py::module_& module) {
  BindLocalizationEvaluation(module);
  BindSlam(module);
  module.def("slam", &Slam, py::arg("log"), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(), py::arg("truth") = py::none(),
             py::arg("index") = py::none(), py::arg("relations") = py::none(),
             py::arg("order") = "logger", py::arg("scans") = py::none(),
             "slam(log, config=None, overrides=None, truth=None, index=None, relations=None, "
             "order='logger', scans=None) -> (SlamRun, SlamEvaluation): what `keyplace slam` "
             "runs (paper Section 6.2.2): ICP odometry, submaps, loop closure by place "
             "recognition, pose graph; evaluated against the log's own corrected poses (a "
             "corrected log) or truth + index (a raw log), and relations when given.");
}

}  // namespace keyplace::python
