#pragma once
// Shared pieces of the keyplace Python module: the Bind* function of each binding file and the
// conversions between the library's types and numpy arrays (docs/PYTHON.md).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/config/config.hpp"
#include "keyplace/features/descriptor.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::python {

namespace py = pybind11;

void BindConfig(py::module_& module);
void BindIo(py::module_& module);
void BindFeatures(py::module_& module);
void BindMapping(py::module_& module);
void BindLocalization(py::module_& module);
void BindEvaluation(py::module_& module);
void BindMerge(py::module_& module);
void BindNavigation(py::module_& module);  // after BindLocalization: extends RelocalizationUpdate
void BindRelocalization(py::module_& module);

/// The configuration of keyplace.Config: the library's Config and the preset it started from
/// (the preset decides defaults such as localize's rank_by, as in the CLI).
struct PyConfig {
  Config config;
  std::string preset = "default";
};

/// The configuration a function was given: `config` (None, a preset name or a keyplace.Config),
/// then `overrides` (None or a dict of "section.key" -> value, like --set).
PyConfig ResolveConfig(const py::object& config, const py::object& overrides);
/// `overrides` (None or a dict of "section.key" -> value) given to `builder`, not yet validated.
void AddOverrides(const py::object& overrides, ConfigBuilder& builder);

/// A map argument: a keyplace.Map (copied) or the path of a map file (read without the GIL).
GlobalMap ToMap(const py::object& map);

/// A progress argument: None (no callback), or a callable progress(done, total) the library calls
/// from whatever thread it works on; the GIL is taken for each call, and an exception the
/// callable raises ends the work and reaches the caller.
std::function<void(std::size_t, std::size_t)> ToProgress(const py::object& progress);

/// Sets options.first_scan / end_scan from a `scans` argument: None (every scan) or a pair
/// (first, end) of non-negative integers with first <= end; ValueError naming the argument
/// otherwise (formerly pybind11's "Unable to cast").
void ApplyScans(const py::object& scans, LogInputOptions& options);

/// The CLI's protection of inputs (CheckNotAnInput, io/atomic_file.hpp) for a Python writer:
/// `path` must be none of `inputs` under any name; with `source_fingerprint` (a map's
/// source_hash) it must not be the log or bag of that content either. ValueError otherwise,
/// before anything is written.
void CheckPythonOutput(const std::string& path, const std::vector<std::string>& inputs,
                       const std::string& source_fingerprint = "");

/// [x, y, theta] (m, m, rad).
py::array_t<double> PoseArray(const Pose2& pose);
/// None for an empty optional, else PoseArray.
py::object OptionalPoseArray(const std::optional<Pose2>& pose);
/// 3 x 3 array of a covariance over (x, y, theta).
py::array_t<double> CovarianceArray(const Eigen::Matrix3d& covariance);
/// A covariance from a 3 x 3 array-like; throws ValueError naming `what` otherwise.
Eigen::Matrix3d ToCovariance(const py::handle& value, const std::string& what);
/// N x 3 array of [x, y, theta] rows.
py::array_t<double> PosesArray(const std::vector<Pose2>& poses);
/// A pose from any sequence of three numbers; throws ValueError naming `what` otherwise.
Pose2 ToPose(const py::handle& value, const std::string& what);
/// N x 2 array of points.
py::array_t<double> PointsArray(const std::vector<Eigen::Vector2d>& points);
/// N x kBetaGridBins float32 array.
py::array_t<float> DescriptorsArray(const std::vector<BetaGridDescriptor>& descriptors);

/// 1-D array copy of a vector.
template <typename T>
py::array_t<T> VectorArray(const std::vector<T>& values) {
  py::array_t<T> array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}
/// 1-D array of flags (numpy bool).
py::array_t<bool> FlagsArray(const std::vector<std::uint8_t>& flags);

/// The scan argument of extract_keypoints and add_scan: a keyplace.Scan, or ranges (1-D array,
/// m) with their bearings `angles_rad` (laser frame), `max_range_m` and the laser mounting
/// `laser_pose` (T_robot_laser; None = identity).
LaserScan ToScan(const py::object& scan, const py::object& angles_rad, double max_range_m,
                 const py::object& laser_pose);

}  // namespace keyplace::python
