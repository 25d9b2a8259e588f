// Conversions between the library's types and numpy arrays, and configuration from Python.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "io/atomic_file.hpp"
#include "io/file_fingerprint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/store/map_file.hpp"

namespace keyplace::python {
namespace {

// A Python value as the text ConfigBuilder::Set parses: bools as true/false, floats by repr (the
// shortest text that reads back the same double), everything else by str.
std::string ConfigText(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::float_>(value)) return py::repr(value).cast<std::string>();
  return py::str(value).cast<std::string>();
}

std::vector<double> ToDoubles(const py::object& values, const std::string& what) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!array || array.ndim() != 1) {
    throw py::value_error(what + " must be a 1-D array of numbers");
  }
  return {array.data(), array.data() + array.size()};
}

}  // namespace

void AddOverrides(const py::object& overrides, ConfigBuilder& builder) {
  if (overrides.is_none()) return;
  if (!py::isinstance<py::dict>(overrides)) {
    throw py::type_error("overrides must be a dict of 'section.key' -> value");
  }
  for (const auto& [key, value] : overrides.cast<py::dict>()) {
    builder.Set(py::str(key).cast<std::string>(), ConfigText(value), "overrides");
  }
}

PyConfig ResolveConfig(const py::object& config, const py::object& overrides) {
  PyConfig resolved;
  if (py::isinstance<PyConfig>(config)) {
    resolved = config.cast<PyConfig>();
  } else if (py::isinstance<py::str>(config)) {
    resolved.preset = config.cast<std::string>();
    resolved.config = PresetConfig(resolved.preset);
  } else if (!config.is_none()) {
    throw py::type_error("config must be None, a preset name or a keyplace.Config");
  }
  if (overrides.is_none()) return resolved;
  // Validated once, after the last override: settings valid only together pass in any order.
  ConfigBuilder builder(resolved.config);
  AddOverrides(overrides, builder);
  resolved.config = builder.Build();
  return resolved;
}

void ApplyScans(const py::object& scans, LogInputOptions& options) {
  if (scans.is_none()) return;
  const auto refuse = [&] {
    std::string shown = py::repr(scans).cast<std::string>();
    if (shown.size() > 60) shown = shown.substr(0, 60) + "...";
    throw py::value_error("scans=" + shown +
                          ": expected (first, end), two integers with 0 <= first <= end");
  };
  if (py::isinstance<py::str>(scans) || py::isinstance<py::bytes>(scans) ||
      !py::isinstance<py::sequence>(scans)) {
    refuse();
  }
  const auto sequence = scans.cast<py::sequence>();
  if (sequence.size() != 2) refuse();
  long long bounds[2] = {0, 0};
  for (std::size_t i = 0; i < 2; ++i) {
    const py::object item = sequence[i];
    if (py::isinstance<py::bool_>(item) || !py::isinstance<py::int_>(item)) refuse();
    try {
      bounds[i] = item.cast<long long>();
    } catch (const py::cast_error&) {
      refuse();
    }
  }
  if (bounds[0] < 0 || bounds[1] < bounds[0]) refuse();
  options.first_scan = static_cast<std::size_t>(bounds[0]);
  options.end_scan = static_cast<std::size_t>(bounds[1]);
}

void CheckPythonOutput(const std::string& path, const std::vector<std::string>& inputs,
                       const std::string& source_fingerprint) {
  // std::invalid_argument: ValueError. A missing directory stays the write's RuntimeError.
  CheckNotAnInput(path, inputs);
  if (source_fingerprint.empty()) return;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return;
  // Only a file of the source's size can be it: the size is the fingerprint's last field.
  const std::string size = std::to_string(std::filesystem::file_size(path, error));
  const std::size_t colon = source_fingerprint.rfind(':');
  if (error || colon == std::string::npos || source_fingerprint.substr(colon + 1) != size) return;
  if (FileFingerprint(path) == source_fingerprint) {
    throw py::value_error(path + ": is the log the map was made from (" + source_fingerprint +
                          "); writing it would destroy the input");
  }
}

GlobalMap ToMap(const py::object& map) {
  if (py::isinstance<GlobalMap>(map)) return map.cast<const GlobalMap&>();
  const std::string path = py::str(map).cast<std::string>();
  py::gil_scoped_release release;
  return LoadMap(path);
}

std::function<void(std::size_t, std::size_t)> ToProgress(const py::object& progress) {
  if (progress.is_none()) return {};
  if (!PyCallable_Check(progress.ptr())) {
    throw py::type_error("progress must be None or a callable progress(done, total)");
  }
  // The library copies and drops its callbacks on worker threads without the GIL: the callable
  // is held through a shared pointer whose copies leave its reference count alone, and the last
  // owner takes the GIL to release it.
  const std::shared_ptr<py::object> callable(new py::object(progress), [](py::object* object) {
    const py::gil_scoped_acquire acquire;
    delete object;
  });
  return [callable](std::size_t done, std::size_t total) {
    const py::gil_scoped_acquire acquire;
    (*callable)(done, total);
  };
}

py::array_t<double> PoseArray(const Pose2& pose) {
  py::array_t<double> array(3);
  double* data = array.mutable_data();
  data[0] = pose.x;
  data[1] = pose.y;
  data[2] = pose.theta;
  return array;
}

py::array_t<double> CovarianceArray(const Eigen::Matrix3d& covariance) {
  py::array_t<double> array({py::ssize_t{3}, py::ssize_t{3}});
  auto view = array.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < 3; ++i) {
    for (py::ssize_t j = 0; j < 3; ++j) view(i, j) = covariance(i, j);
  }
  return array;
}

Eigen::Matrix3d ToCovariance(const py::handle& value, const std::string& what) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 2 || array.shape(0) != 3 || array.shape(1) != 3) {
    throw py::value_error(what + " must be a 3 x 3 array over (x, y, theta)");
  }
  const auto view = array.unchecked<2>();
  Eigen::Matrix3d covariance;
  for (py::ssize_t i = 0; i < 3; ++i) {
    for (py::ssize_t j = 0; j < 3; ++j) covariance(i, j) = view(i, j);
  }
  return covariance;
}

py::object OptionalPoseArray(const std::optional<Pose2>& pose) {
  if (!pose) return py::none();
  return PoseArray(*pose);
}

py::array_t<double> PosesArray(const std::vector<Pose2>& poses) {
  py::array_t<double> array({static_cast<py::ssize_t>(poses.size()), py::ssize_t{3}});
  auto view = array.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    const Pose2& pose = poses[static_cast<std::size_t>(i)];
    view(i, 0) = pose.x;
    view(i, 1) = pose.y;
    view(i, 2) = pose.theta;
  }
  return array;
}

namespace {

// A 3 x 3 homogeneous transform [[c, -s, x], [s, c, y], [0, 0, 1]] as a pose; anything that is not
// a rigid motion of the plane (within rounding) is refused, naming what is wrong.
Pose2 PoseOfMatrix(const py::array_t<double, py::array::c_style | py::array::forcecast>& m,
                   const std::string& what) {
  constexpr double kTolerance = 1e-6;
  const auto at = [&](py::ssize_t row, py::ssize_t column) { return m.at(row, column); };
  for (py::ssize_t row = 0; row < 3; ++row) {
    for (py::ssize_t column = 0; column < 3; ++column) {
      if (!std::isfinite(at(row, column))) {
        throw py::value_error(what + ": the 3 x 3 matrix has a value that is not finite");
      }
    }
  }
  if (std::abs(at(2, 0)) > kTolerance || std::abs(at(2, 1)) > kTolerance ||
      std::abs(at(2, 2) - 1.0) > kTolerance) {
    throw py::value_error(what + ": the last row of a 3 x 3 homogeneous transform is [0, 0, 1]");
  }
  const double c = at(0, 0), s = at(1, 0);
  if (std::abs(at(1, 1) - c) > kTolerance || std::abs(at(0, 1) + s) > kTolerance ||
      std::abs(c * c + s * s - 1.0) > kTolerance) {
    throw py::value_error(what +
                          ": the upper left 2 x 2 block is not a rotation [[c, -s], [s, c]]");
  }
  return {at(0, 2), at(1, 2), std::atan2(s, c)};
}

}  // namespace

Pose2 ToPose(const py::handle& value, const std::string& what) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (array && array.ndim() == 2 && array.shape(0) == 3 && array.shape(1) == 3) {
    return PoseOfMatrix(array, what);
  }
  if (!array || array.ndim() != 1 || array.size() != 3) {
    throw py::value_error(what +
                          " must be three numbers [x_m, y_m, theta_rad] or a 3 x 3 homogeneous "
                          "transform");
  }
  return {array.at(0), array.at(1), array.at(2)};
}

py::array_t<double> PointsArray(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{2}});
  auto view = array.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    view(i, 0) = points[static_cast<std::size_t>(i)].x();
    view(i, 1) = points[static_cast<std::size_t>(i)].y();
  }
  return array;
}

py::array_t<float> DescriptorsArray(const std::vector<BetaGridDescriptor>& descriptors) {
  py::array_t<float> array(
      {static_cast<py::ssize_t>(descriptors.size()), static_cast<py::ssize_t>(kBetaGridBins)});
  float* data = array.mutable_data();
  for (const BetaGridDescriptor& descriptor : descriptors) {
    data = std::copy(descriptor.begin(), descriptor.end(), data);
  }
  return array;
}

py::array_t<bool> FlagsArray(const std::vector<std::uint8_t>& flags) {
  py::array_t<bool> array(static_cast<py::ssize_t>(flags.size()));
  std::transform(flags.begin(), flags.end(), array.mutable_data(),
                 [](std::uint8_t flag) { return flag != 0; });
  return array;
}

LaserScan ToScan(const py::object& scan, const py::object& angles_rad, double max_range_m,
                 const py::object& laser_pose) {
  if (py::isinstance<LogScan>(scan)) return scan.cast<const LogScan&>();
  if (angles_rad.is_none()) {
    throw py::value_error(
        "ranges need their bearings: pass angles_rad (laser frame, rad; e.g. "
        "numpy.linspace(-fov / 2, fov / 2, len(ranges))) or a keyplace.Scan");
  }
  const Pose2 T_robot_laser = laser_pose.is_none() ? Pose2() : ToPose(laser_pose, "laser_pose");
  return MakeLaserScan(ToDoubles(scan, "ranges"), ToDoubles(angles_rad, "angles_rad"), max_range_m,
                       0.0, T_robot_laser);
}

}  // namespace keyplace::python
