// keyplace.Map and keyplace.Submap (mapping/global_map.hpp), build_map (the map of a log as
// `keyplace map` builds it: mapping/scan_sources.hpp) and map files (store/map_file.hpp).

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/store/map_file.hpp"
#include "result_fields.hpp"

namespace keyplace::python {
namespace {

template <typename T, typename Field>
py::array_t<T> KeypointColumn(const Submap& submap, Field field) {
  std::vector<T> values;
  values.reserve(submap.keypoints.size());
  for (const StableKeypoint& keypoint : submap.keypoints) values.push_back(field(keypoint));
  return VectorArray(values);
}

GlobalMap BuildMap(const std::string& path, const py::object& config, const py::object& overrides,
                   const py::object& poses, const py::object& scans, bool start_at_origin,
                   bool skip_bad_lines) {
  const Config resolved = ResolveConfig(config, overrides).config;
  LogInputOptions options = LogInputOptionsFor(resolved);
  options.reading.skip_bad_lines = skip_bad_lines;
  if (!poses.is_none()) options.poses = ParsePoseSource(poses.cast<std::string>());
  options.start_at_origin = start_at_origin;
  ApplyScans(scans, options);
  py::gil_scoped_release release;
  const LogInputs inputs = PrepareLogInputs(path, options);
  LogMap result = MapLog(inputs, resolved.mapping);
  result.map.configuration = ConfigToYaml(resolved);
  return std::move(result.map);
}

void BindSubmap(py::module_& module) {
  py::class_<Submap>(module, "Submap",
                     "A submap {P, F}: the poses of its scans and its stable keypoints, in the "
                     "submap frame (the robot frame of its first scan). Arrays are copies.")
      .def_readonly("id", &Submap::id)
      .def_property_readonly(
          "scan_indices", [](const Submap& s) { return VectorArray(s.scan_indices); },
          "Log scans of the submap (file indices), in insertion order.")
      .def_property_readonly(
          "poses", [](const Submap& s) { return PosesArray(s.poses); },
          "N x 3 T_world_robot of its scans; poses[0] is the submap frame.")
      .def_property_readonly(
          "origin", [](const Submap& s) { return PoseArray(s.origin()); },
          "T_world_submap [x_m, y_m, theta_rad] (= poses[0]).")
      .def_property_readonly(
          "keypoint_positions_m",
          [](const Submap& s) {
            std::vector<Eigen::Vector2d> points;
            for (const StableKeypoint& keypoint : s.keypoints)
              points.push_back(keypoint.position_m);
            return PointsArray(points);
          },
          "N x 2 stable keypoint positions in the submap frame (m).")
      .def_property_readonly(
          "keypoint_orientations_rad",
          [](const Submap& s) {
            return KeypointColumn<double>(
                s, [](const StableKeypoint& k) { return k.orientation_rad; });
          },
          "Orientations in the submap frame (rad).")
      .def_property_readonly(
          "keypoint_scales_m",
          [](const Submap& s) {
            return KeypointColumn<double>(s, [](const StableKeypoint& k) { return k.scale_m; });
          },
          "Scales (m).")
      .def_property_readonly(
          "keypoint_stability",
          [](const Submap& s) {
            return KeypointColumn<float>(s, [](const StableKeypoint& k) { return k.stability; });
          },
          "Stability score s of each keypoint's cell when the submap was completed.")
      .def_property_readonly(
          "keypoint_occurrences",
          [](const Submap& s) {
            return KeypointColumn<int>(s, [](const StableKeypoint& k) { return k.occurrences; });
          },
          "occ: size of each keypoint cell's largest history cluster.")
      .def_property_readonly(
          "keypoint_scan_indices",
          [](const Submap& s) {
            return KeypointColumn<int>(s, [](const StableKeypoint& k) { return k.scan_index; });
          },
          "The log scan each keypoint instance was detected in.")
      .def_property_readonly(
          "descriptors",
          [](const Submap& s) {
            std::vector<BetaGridDescriptor> descriptors;
            for (const StableKeypoint& keypoint : s.keypoints) {
              descriptors.push_back(keypoint.descriptor);
            }
            return DescriptorsArray(descriptors);
          },
          "N x 48 float32 beta-grid descriptors.")
      .def_property_readonly("keypoint_count", [](const Submap& s) { return s.keypoints.size(); })
      .def_readonly("overlap", &Submap::overlap, "rho when the submap was completed.")
      .def_readonly("distribution", &Submap::distribution, "delta when completed.")
      .def_readonly("forced", &Submap::forced, "Closed by max_scans_per_submap.")
      .def("__repr__", [](const Submap& s) {
        return "<keyplace.Submap " + std::to_string(s.id) + ": " +
               std::to_string(s.scan_indices.size()) + " scans, " +
               std::to_string(s.keypoints.size()) + " keypoints>";
      });
}

void BindStats(py::module_& module) {
  py::class_<MappingStats> cls(module, "MappingStats",
                               "The mapping criteria of paper Section 5.1.");
  DefResultFields(cls, MappingStatsFields());
}

void BindMap(py::module_& module) {
  py::class_<GlobalMap>(module, "Map", "A global map: the submaps of a log, with what made it.")
      .def_property_readonly(
          "submaps",
          [](const py::object& self) {
            auto& map = self.cast<GlobalMap&>();
            py::list submaps;
            for (Submap& submap : map.submaps) {
              submaps.append(py::cast(&submap, py::return_value_policy::reference_internal, self));
            }
            return submaps;
          },
          "The submaps in map order (views into the map).")
      .def_property_readonly("submap_count", [](const GlobalMap& m) { return m.submaps.size(); })
      .def_property_readonly("keypoint_count", &GlobalMap::KeypointCount,
                             "Stable keypoints of all submaps.")
      .def_property_readonly(
          "origins",
          [](const GlobalMap& m) {
            std::vector<Pose2> origins;
            for (const Submap& submap : m.submaps) origins.push_back(submap.origin());
            return PosesArray(origins);
          },
          "N x 3 T_world_submap of every submap.")
      .def_readonly("source_log", &GlobalMap::source_log, "File name of the log mapped.")
      .def_readonly("source_hash", &GlobalMap::source_hash, "'crc32:<hex>:<bytes>' of that log.")
      .def_readonly("pose_source", &GlobalMap::pose_source, "corrected | odometry | icp | slam.")
      .def_readonly("source_scans", &GlobalMap::source_scans, "Scans in the log.")
      .def_readonly("source_keypoints", &GlobalMap::source_keypoints,
                    "FLIRT keypoints of all scans of the log.")
      .def_readonly("configuration", &GlobalMap::configuration,
                    "The whole configuration that made the map, as YAML.")
      .def("stats", &ComputeStats, "The mapping criteria (MappingStats).")
      .def(
          "save",
          [](const GlobalMap& map, const std::string& path) {
            CheckPythonOutput(path, {}, map.source_hash);
            py::gil_scoped_release release;
            SaveMap(map, path);
          },
          py::arg("path"),
          "Writes the map file (.kpm, SQLite) atomically; RuntimeError naming the path on failure, "
          "ValueError (nothing written) when the path is the log the map was made from or its "
          "directory is missing.")
      .def("__repr__", [](const GlobalMap& m) {
        return "<keyplace.Map " + m.source_log + ": " + std::to_string(m.submaps.size()) +
               " submaps, " + std::to_string(m.KeypointCount()) + " keypoints>";
      });
}

}  // namespace

void BindMapping(py::module_& module) {
  BindSubmap(module);
  BindStats(module);
  BindMap(module);
  module.def("build_map", &BuildMap, py::arg("path"), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(), py::arg("poses") = py::none(),
             py::arg("scans") = py::none(), py::arg("start_at_origin") = false,
             py::arg("skip_bad_lines") = false,
             "build_map(path, config=None, overrides=None, poses=None, scans=None, "
             "start_at_origin=False, skip_bad_lines=False) -> Map: the global map of a log or "
             "bag as `keyplace map` builds it (paper Algorithms 1-2). poses: 'corrected', "
             "'odometry' or 'icp' (default: corrected when the log has them, else icp); scans: "
             "(first, end) to map only those scans (file indices stay). The map records the "
             "configuration.");
  module.def(
      "load_map",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return LoadMap(path);
      },
      py::arg("path"),
      "load_map(path) -> Map: reads and checks a map file (.kpm); RuntimeError naming the path "
      "and the problem for a missing, damaged or foreign file.");
}

}  // namespace keyplace::python
