// keyplace.Scan, keyplace.Log and read_log: CARMEN logs and ROS 1 and 2 bags through the library's
// reader (io/carmen_log.hpp).

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace::python {
namespace {

LogScan MakeScan(const py::object& ranges, const py::object& angles_rad, double max_range_m,
                 double timestamp_s, const py::object& laser_pose,
                 const py::object& odometry_pose) {
  LogScan scan;
  static_cast<LaserScan&>(scan) = ToScan(ranges, angles_rad, max_range_m, laser_pose);
  scan.timestamp_s = timestamp_s;
  if (!odometry_pose.is_none()) scan.odometry_pose = ToPose(odometry_pose, "odometry_pose");
  return scan;
}

// N x 3 poses of the scans, NaN rows where a scan has none.
template <typename Getter>
py::array_t<double> ScanPoses(const CarmenLog& log, Getter pose_of) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  py::array_t<double> array = PosesArray(std::vector<Pose2>(log.scans.size()));
  auto view = array.mutable_unchecked<2>();
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    const std::optional<Pose2> pose = pose_of(log.scans[i]);
    const auto row = static_cast<py::ssize_t>(i);
    view(row, 0) = pose ? pose->x : nan;
    view(row, 1) = pose ? pose->y : nan;
    view(row, 2) = pose ? pose->theta : nan;
  }
  return array;
}

CarmenLog ReadLog(const std::string& path, const py::object& config, const py::object& scan_topic,
                  const py::object& odom_topic, const py::object& laser_pose, bool skip_bad_lines,
                  bool keep_beams) {
  py::dict overrides;
  if (!scan_topic.is_none()) overrides["input.scan_topic"] = scan_topic;
  if (!odom_topic.is_none()) overrides["input.odom_topic"] = odom_topic;
  if (!laser_pose.is_none()) {
    if (py::isinstance<py::str>(laser_pose)) {
      overrides["input.laser_pose"] = laser_pose;
    } else {
      // "x,y,theta" with each number as repr writes it (reads back the same double).
      const Pose2 pose = ToPose(laser_pose, "laser_pose");
      std::string text;
      for (const double value : {pose.x, pose.y, pose.theta}) {
        text += (text.empty() ? "" : ",") + py::repr(py::float_(value)).cast<std::string>();
      }
      overrides["input.laser_pose"] = text;
    }
  }
  CarmenReadOptions options;
  options.bag = ResolveConfig(config, overrides).config.input;
  options.skip_bad_lines = skip_bad_lines;
  options.keep_beams = keep_beams;
  py::gil_scoped_release release;
  return ReadCarmenLogWithScans(path, options);
}

void BindScan(py::module_& module) {
  py::class_<LogScan>(module, "Scan",
                      "One 2D laser scan: beams in the laser frame, and the poses a log writes "
                      "beside it. Array properties return copies.")
      .def(py::init(&MakeScan), py::arg("ranges"), py::arg("angles_rad"),
           py::arg("max_range_m") = 80.0, py::arg("timestamp_s") = 0.0,
           py::arg("laser_pose") = py::none(), py::arg("odometry_pose") = py::none(),
           "Scan(ranges, angles_rad, max_range_m=80.0, timestamp_s=0.0, laser_pose=None, "
           "odometry_pose=None): ranges (m) and bearings (rad, laser frame) of the beams; a beam "
           "is valid when its range is finite, > 0 and < max_range_m. laser_pose: T_robot_laser "
           "[x, y, theta] (None: the laser at the robot's origin).")
      .def_property_readonly(
          "ranges", [](const LogScan& s) { return VectorArray(s.ranges_m); }, "Ranges (m).")
      .def_property_readonly(
          "angles_rad", [](const LogScan& s) { return VectorArray(s.angles_rad); },
          "Beam bearings in the laser frame (rad).")
      .def_property_readonly(
          "valid", [](const LogScan& s) { return FlagsArray(s.valid); },
          "True where the beam returned a usable range (finite, > 0, < max_range_m).")
      .def_readonly("max_range_m", &LogScan::max_range_m, "Readings at or beyond are no return.")
      .def_readonly("timestamp_s", &LogScan::timestamp_s, "Acquisition time (s).")
      .def_readonly("logger_timestamp_s", &LogScan::logger_timestamp_s, "Logger time (s).")
      .def_property_readonly(
          "laser_pose", [](const LogScan& s) { return PoseArray(s.T_robot_laser); },
          "T_robot_laser: the laser on the robot [x_m, y_m, theta_rad].")
      .def_property_readonly(
          "odometry_pose", [](const LogScan& s) { return OptionalPoseArray(s.odometry_pose); },
          "T_odom_robot [x_m, y_m, theta_rad] (raw logs), or None.")
      .def_property_readonly(
          "corrected_pose", [](const LogScan& s) { return OptionalPoseArray(s.corrected_pose); },
          "SLAM-corrected T_world_robot [x_m, y_m, theta_rad] (corrected logs), or None.")
      .def_property_readonly(
          "logged_laser_pose", [](const LogScan& s) { return PoseArray(s.logged_laser_pose); },
          "The laser pose exactly as the log writes it (the frame FLIRT detects in, to match "
          "`keyplace features`).")
      .def_readonly("line", &LogScan::line, "1-based line of the scan in its file (bag: message).")
      .def_property_readonly(
          "endpoints", [](const LogScan& s) { return PointsArray(s.ValidEndpoints()); },
          "N x 2 end points of the valid beams in the laser frame (m).")
      .def("__len__", &LogScan::size)
      .def("__repr__", [](const LogScan& s) {
        return "<keyplace.Scan " + std::to_string(s.size()) +
               " beams, t=" + std::to_string(s.timestamp_s) + " s>";
      });
}

void BindLog(py::module_& module) {
  py::class_<CarmenLog>(module, "Log", "A log or bag as the library reads it.")
      .def_readonly("path", &CarmenLog::path)
      .def_readonly("format", &CarmenLog::format, "'CARMEN log', 'ROS 1 bag' or 'ROS 2 bag'.")
      .def_readonly("corrected", &CarmenLog::corrected,
                    "True when the scans' poses are SLAM-corrected (Scan.corrected_pose).")
      .def_readonly("fingerprint", &CarmenLog::fingerprint, "'crc32:<hex>:<bytes>' of the file.")
      .def_readonly("warnings", &CarmenLog::warnings, "Damage the reader worked around.")
      .def_readonly("params", &CarmenLog::params, "PARAM name -> value.")
      .def_property_readonly(
          "scans",
          [](const py::object& self) {
            auto& log = self.cast<CarmenLog&>();
            py::list scans;
            for (LogScan& scan : log.scans) {
              scans.append(py::cast(&scan, py::return_value_policy::reference_internal, self));
            }
            return scans;
          },
          "The scans in file order (views into the log, no copies).")
      .def("__len__", [](const CarmenLog& log) { return log.scans.size(); })
      .def(
          "__getitem__",
          [](const py::object& self, py::ssize_t index) {
            auto& log = self.cast<CarmenLog&>();
            const auto count = static_cast<py::ssize_t>(log.scans.size());
            if (index < 0) index += count;
            if (index < 0 || index >= count) throw py::index_error("scan index out of range");
            return py::cast(&log.scans[static_cast<std::size_t>(index)],
                            py::return_value_policy::reference_internal, self);
          },
          "The scan at an index (a view into the log).")
      .def_property_readonly(
          "timestamps_s",
          [](const CarmenLog& log) {
            std::vector<double> stamps;
            for (const LogScan& scan : log.scans) stamps.push_back(scan.timestamp_s);
            return VectorArray(stamps);
          },
          "Acquisition time of every scan (s).")
      .def_property_readonly(
          "odometry_poses",
          [](const CarmenLog& log) {
            return ScanPoses(log, [](const LogScan& s) { return s.odometry_pose; });
          },
          "N x 3 T_odom_robot of every scan (NaN rows where a scan has none).")
      .def_property_readonly(
          "corrected_poses",
          [](const CarmenLog& log) {
            return ScanPoses(log, [](const LogScan& s) { return s.corrected_pose; });
          },
          "N x 3 corrected T_world_robot of every scan (NaN rows where a scan has none).")
      .def("__repr__", [](const CarmenLog& log) {
        return "<keyplace.Log " + log.path + ": " + std::to_string(log.scans.size()) + " scans>";
      });
}

}  // namespace

void BindIo(py::module_& module) {
  BindScan(module);
  BindLog(module);
  module.def("read_log", &ReadLog, py::arg("path"), py::arg("config") = py::none(),
             py::arg("scan_topic") = py::none(), py::arg("odom_topic") = py::none(),
             py::arg("laser_pose") = py::none(), py::arg("skip_bad_lines") = false,
             py::arg("keep_beams") = true,
             "read_log(path, config=None, scan_topic=None, odom_topic=None, laser_pose=None, "
             "skip_bad_lines=False, keep_beams=True) -> Log: a CARMEN log (.log, .log.gz), a "
             "ROS 1 bag or a ROS 2 bag (rosbag2 directory, metadata.yaml, .mcap, .db3). For bags, "
             "the topics and laser_pose (T_base_laser, [x, y, theta] or "
             "'x,y,theta') override the config's input section. Raises RuntimeError when the "
             "file cannot be read and ValueError naming file and line for malformed content or "
             "a file without laser scans.");
}

}  // namespace keyplace::python
