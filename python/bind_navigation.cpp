// What a navigation stack loads (docs/NAVIGATION.md): occupancy grids in the ROS map_server format
// (mapping/occupancy_grid.hpp, map_server.hpp), built as `keyplace map --grid` and
// `keyplace slam --grid` build them, and a fix as the /initialpose message
// (localization/initial_pose.hpp).

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/config/log_inputs.hpp"
#include "keyplace/eval/slam_evaluation.hpp"
#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/mapping/map_server.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::python {
namespace {

// A grid with the settings that classify its cells (grid.occupied_thresh, free_thresh).
struct PyGrid {
  OccupancyGrid grid;
  OccupancyGridConfig config;
  std::string source_path;  // the log or bag it was built from: write_map_server protects it
};

// H x W array of one value per cell, in the image's order: row 0 is the top (largest y) row.
template <typename T, typename Value>
py::array_t<T> CellArray(const OccupancyGrid& grid, Value value) {
  py::array_t<T> array(
      {static_cast<py::ssize_t>(grid.height), static_cast<py::ssize_t>(grid.width)});
  auto view = array.template mutable_unchecked<2>();
  for (int image_row = 0; image_row < grid.height; ++image_row) {
    const int row = grid.height - 1 - image_row;
    for (int column = 0; column < grid.width; ++column) {
      view(image_row, column) = value(column, row);
    }
  }
  return array;
}

template <typename T>
py::array_t<T> ImageArray(const std::vector<T>& pixels, int width, int height) {
  py::array_t<T> array({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width)});
  std::copy(pixels.begin(), pixels.end(), array.mutable_data());
  return array;
}

PyGrid BuildGrid(const std::string& path, const py::object& config, const py::object& overrides,
                 const py::object& poses, const py::object& scans, bool start_at_origin,
                 bool skip_bad_lines, const py::object& slam_run) {
  const Config resolved = ResolveConfig(config, overrides).config;
  const SlamRun* run = slam_run.is_none() ? nullptr : &slam_run.cast<const SlamRun&>();
  if (run != nullptr && !poses.is_none()) {
    throw py::value_error("build_grid: give poses or slam_run, not both");
  }
  LogInputOptions options = LogInputOptionsFor(resolved);
  options.reading.skip_bad_lines = skip_bad_lines;
  if (!poses.is_none()) options.poses = ParsePoseSource(poses.cast<std::string>());
  options.start_at_origin = start_at_origin;
  options.keypoints = false;               // a grid needs scans and poses only
  options.compute_poses = run == nullptr;  // a SLAM run brings its own
  ApplyScans(scans, options);
  py::gil_scoped_release release;
  const LogInputs inputs = PrepareLogInputs(path, options);
  if (run != nullptr && run->scans != inputs.log.scans.size()) {
    throw std::invalid_argument("build_grid: slam_run was run on " + std::to_string(run->scans) +
                                " scans, " + path + " (with scans=) has " +
                                std::to_string(inputs.log.scans.size()) +
                                ": give the log and scan range SLAM was run on");
  }
  PyGrid grid;
  grid.config = resolved.grid;
  grid.source_path = path;
  grid.grid = run != nullptr ? SlamOccupancyGrid(*run, inputs, resolved.grid)
                             : LogOccupancyGrid(inputs, resolved.grid);
  return grid;
}

void BindGrid(py::module_& module) {
  py::class_<PyGrid>(
      module, "OccupancyGrid",
      "An occupancy grid in the map frame (docs/NAVIGATION.md). Arrays are H x W in the image's "
      "order: row 0 is the top (largest y) row, column 0 the smallest x; cell [i, j] covers x in "
      "origin_m[0] + [j, j + 1] * resolution_m, y in origin_m[1] + [H - 1 - i, H - i] * "
      "resolution_m.")
      .def_property_readonly(
          "resolution_m", [](const PyGrid& g) { return g.grid.resolution_m; },
          "Side of a cell (m).")
      .def_property_readonly(
          "origin_m",
          [](const PyGrid& g) {
            return VectorArray(std::vector<double>{g.grid.origin_m.x(), g.grid.origin_m.y()});
          },
          "[x_m, y_m] of the lower-left corner of the bottom-left cell (map_server's origin, yaw "
          "0).")
      .def_property_readonly(
          "width", [](const PyGrid& g) { return g.grid.width; }, "Cells along x.")
      .def_property_readonly(
          "height", [](const PyGrid& g) { return g.grid.height; }, "Cells along y.")
      .def_property_readonly(
          "image",
          [](const PyGrid& g) {
            return ImageArray(MapServerImage(g.grid, g.config), g.grid.width, g.grid.height);
          },
          "H x W uint8 trinary image, the pixels of the .pgm write_map_server writes: 0 occupied, "
          "254 free, 205 unknown (by grid.occupied_thresh / free_thresh).")
      .def_property_readonly(
          "probabilities",
          [](const PyGrid& g) {
            return CellArray<double>(
                g.grid, [&](int column, int row) { return g.grid.Probability(column, row); });
          },
          "H x W occupancy probabilities (0.5 where no beam reached).")
      .def_property_readonly(
          "observed",
          [](const PyGrid& g) {
            return CellArray<bool>(g.grid, [&](int column, int row) {
              return g.grid.observed[g.grid.Index(column, row)] != 0;
            });
          },
          "H x W: some beam reached the cell.")
      .def(
          "write_map_server",
          [](const PyGrid& g, const std::string& yaml_path) {
            CheckPythonOutput(yaml_path, {g.source_path});
            CheckPythonOutput(MapServerImagePath(yaml_path), {g.source_path});
            py::gil_scoped_release release;
            WriteMapServerMap(g.grid, g.config, yaml_path);
            return MapServerImagePath(yaml_path);
          },
          py::arg("yaml_path"),
          "write_map_server(yaml_path) -> image path: writes the map_server YAML and its binary "
          "PGM beside it (same name, .pgm), each atomically, as `--grid FILE.yaml` does; "
          "RuntimeError naming the file that cannot be written.")
      .def("__repr__", [](const PyGrid& g) {
        return "<keyplace.OccupancyGrid " + std::to_string(g.grid.width) + " x " +
               std::to_string(g.grid.height) + " cells of " + std::to_string(g.grid.resolution_m) +
               " m>";
      });

  module.def("build_grid", &BuildGrid, py::arg("path"), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(), py::arg("poses") = py::none(),
             py::arg("scans") = py::none(), py::arg("start_at_origin") = false,
             py::arg("skip_bad_lines") = false, py::arg("slam_run") = py::none(),
             "build_grid(path, config=None, overrides=None, poses=None, scans=None, "
             "start_at_origin=False, skip_bad_lines=False, slam_run=None) -> OccupancyGrid: the "
             "occupancy grid of a log's scans (settings: grid.*), at the poses `keyplace map "
             "--grid` uses (poses, scans and start_at_origin as in build_map), or at the final "
             "trajectory of slam_run (a SlamRun of keyplace.slam on the same log and scans) as "
             "`keyplace slam --grid`. ValueError when the grid would exceed grid.max_cells.");

  py::class_<MapServerMap>(module, "MapServerMap",
                           "A map_server map as its YAML and image give it (read_map_server).")
      .def_readonly("image_path", &MapServerMap::image_path)
      .def_readonly("resolution_m", &MapServerMap::resolution_m)
      .def_property_readonly(
          "origin",
          [](const MapServerMap& m) {
            return VectorArray(std::vector<double>{m.origin_x_m, m.origin_y_m, m.origin_yaw_rad});
          },
          "[x_m, y_m, yaw_rad] of the lower-left pixel's corner.")
      .def_readonly("negate", &MapServerMap::negate)
      .def_readonly("occupied_thresh", &MapServerMap::occupied_thresh)
      .def_readonly("free_thresh", &MapServerMap::free_thresh)
      .def_readonly("mode", &MapServerMap::mode)
      .def_property_readonly(
          "image", [](const MapServerMap& m) { return ImageArray(m.pixels, m.width, m.height); },
          "H x W uint8 pixels, top row first.");
  module.def(
      "read_map_server",
      [](const std::string& yaml_path) {
        py::gil_scoped_release release;
        return ReadMapServerMap(yaml_path);
      },
      py::arg("yaml_path"),
      "read_map_server(yaml_path) -> MapServerMap: a map_server YAML and its binary PGM; "
      "ValueError naming the file and field that is wrong, RuntimeError for a missing file.");
}

InitialPose MakeInitialPose(const py::object& pose, const py::object& pose_covariance,
                            const std::string& frame_id) {
  InitialPose initial;
  initial.T_map_robot = ToPose(pose, "pose");
  if (!pose_covariance.is_none()) {
    initial.covariance = ToCovariance(pose_covariance, "pose_covariance");
  }
  CheckInitialPoseFrameId(frame_id);  // ValueError, as the docs say
  initial.frame_id = frame_id;
  return initial;
}

void BindInitialPose(py::module_& module) {
  py::class_<InitialPose>(
      module, "InitialPose",
      "A fix as a geometry_msgs/PoseWithCovarianceStamped for /initialpose (AMCL, nav2): the "
      "robot's pose in the map frame with a covariance derived from the matches "
      "(docs/NAVIGATION.md).")
      // The keyword is the 3 x 3 property's name: `.covariance` is the message's 6 x 6 array.
      .def(py::init(&MakeInitialPose), py::arg("pose"), py::arg("pose_covariance") = py::none(),
           py::arg("frame_id") = "map",
           "InitialPose(pose, pose_covariance=None, frame_id='map'): pose is T_map_robot [x_m, "
           "y_m, theta_rad], pose_covariance a 3 x 3 array over (x, y, theta) (None: zeros), as "
           "the pose_covariance property gives it.")
      .def_readonly("frame_id", &InitialPose::frame_id)
      .def_property_readonly(
          "pose", [](const InitialPose& p) { return PoseArray(p.T_map_robot); },
          "T_map_robot [x_m, y_m, theta_rad].")
      .def_property_readonly(
          "pose_covariance", [](const InitialPose& p) { return CovarianceArray(p.covariance); },
          "3 x 3 covariance over (x, y, theta) (m^2, m rad, rad^2).")
      .def_property_readonly(
          "covariance",
          [](const InitialPose& p) {
            const auto values = InitialPoseCovariance(p);
            py::array_t<double> array({py::ssize_t{6}, py::ssize_t{6}});
            std::copy(values.begin(), values.end(), array.mutable_data());
            return array;
          },
          "The message's 6 x 6 covariance over x, y, z, roll, pitch, yaw (m^2, rad^2).")
      .def("to_yaml", &InitialPoseYaml,
           "The message as YAML (`rostopic pub -f`); ValueError for a frame id that is not a ROS "
           "name.")
      .def("to_json", &InitialPoseJson, "The same fields as JSON.")
      .def(
          "write",
          [](const InitialPose& p, const std::string& path) {
            CheckPythonOutput(path, {});
            py::gil_scoped_release release;
            WriteInitialPose(p, path);
          },
          py::arg("path"),
          "write(path): YAML, or JSON for a path ending in .json, atomically (as `keyplace "
          "relocalize --initialpose`).")
      .def("__repr__", [](const InitialPose& p) {
        return "<keyplace.InitialPose " + p.frame_id + " x " + std::to_string(p.T_map_robot.x) +
               " y " + std::to_string(p.T_map_robot.y) + " theta " +
               std::to_string(p.T_map_robot.theta) + ">";
      });

  // The Relocalizer's update (bind_localization.cpp) gives its fix as the message.
  auto update =
      py::reinterpret_borrow<py::class_<RelocalizationUpdate>>(module.attr("RelocalizationUpdate"));
  update.def(
      "initial_pose",
      [](const RelocalizationUpdate& u, const std::string& frame_id) {
        return InitialPoseOf(u, frame_id);
      },
      py::arg("frame_id") = "map",
      "initial_pose(frame_id='map') -> InitialPose: the fix with its covariance; "
      "ValueError unless status is 'fixed'.");
}

}  // namespace

void BindNavigation(py::module_& module) {
  BindGrid(module);
  BindInitialPose(module);
}

}  // namespace keyplace::python
