// FLIRT keypoints of one scan (features/flirt.hpp) and the descriptor distance.

#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"

namespace keyplace::python {
namespace {

// The keypoints of one scan, handed to Python as columns.
struct Keypoints {
  std::vector<Keypoint> keypoints;
};

template <typename T, typename Field>
py::array_t<T> Column(const Keypoints& set, Field field) {
  std::vector<T> values;
  values.reserve(set.keypoints.size());
  for (const Keypoint& keypoint : set.keypoints) values.push_back(field(keypoint));
  return VectorArray(values);
}

Keypoints ExtractKeypoints(const py::object& scan, const py::object& angles_rad, double max_range_m,
                           const py::object& T_world_laser, const py::object& config,
                           const py::object& overrides) {
  const LaserScan laser_scan = ToScan(scan, angles_rad, max_range_m, py::none());
  const Pose2 frame = T_world_laser.is_none() ? Pose2() : ToPose(T_world_laser, "T_world_laser");
  const FlirtConfig flirt = ResolveConfig(config, overrides).config.features;
  py::gil_scoped_release release;
  const FlirtExtractor extractor(flirt);
  return {extractor.Extract(laser_scan, frame)};
}

BetaGridDescriptor ToDescriptor(const py::handle& value) {
  const auto array = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 1 || array.size() != kBetaGridBins) {
    throw py::value_error("a descriptor is " + std::to_string(kBetaGridBins) + " numbers");
  }
  BetaGridDescriptor descriptor{};
  std::copy(array.data(), array.data() + kBetaGridBins, descriptor.begin());
  return descriptor;
}

}  // namespace

void BindFeatures(py::module_& module) {
  py::class_<Keypoints>(module, "Keypoints",
                        "FLIRT keypoints of one scan as columns (numpy copies), in FLIRTLib's "
                        "order: scale level ascending, then beam order. Laser frame.")
      .def("__len__", [](const Keypoints& k) { return k.keypoints.size(); })
      .def_property_readonly(
          "positions_m",
          [](const Keypoints& k) {
            std::vector<Eigen::Vector2d> points;
            for (const Keypoint& keypoint : k.keypoints) points.push_back(keypoint.position_m);
            return PointsArray(points);
          },
          "N x 2 positions in the laser frame (m): the end points of the keypoint beams.")
      .def_property_readonly(
          "orientations_rad",
          [](const Keypoints& k) {
            return Column<double>(k, [](const Keypoint& p) { return p.orientation_rad; });
          },
          "Orientations in the laser frame (rad, (-pi, pi]).")
      .def_property_readonly(
          "scales_m",
          [](const Keypoints& k) {
            return Column<double>(k, [](const Keypoint& p) { return p.scale_m; });
          },
          "Scales (m): 2 sigma of the detection scale, FLIRTLib's getScale().")
      .def_property_readonly(
          "scale_levels",
          [](const Keypoints& k) {
            return Column<int>(k, [](const Keypoint& p) { return p.scale_level; });
          },
          "Detection scale levels (0 .. features.num_scales - 1).")
      .def_property_readonly(
          "beam_indices",
          [](const Keypoints& k) {
            return Column<int>(k, [](const Keypoint& p) { return p.beam_index; });
          },
          "Index of each keypoint's beam in the scan.")
      .def_property_readonly(
          "descriptors",
          [](const Keypoints& k) {
            std::vector<BetaGridDescriptor> descriptors;
            for (const Keypoint& keypoint : k.keypoints) descriptors.push_back(keypoint.descriptor);
            return DescriptorsArray(descriptors);
          },
          "N x 48 float32 beta-grid descriptors (12 angular x 4 radial bins, phi-major; each "
          "row sums to 1).")
      .def("__repr__", [](const Keypoints& k) {
        return "<keyplace.Keypoints " + std::to_string(k.keypoints.size()) + ">";
      });

  module.def("extract_keypoints", &ExtractKeypoints, py::arg("scan"),
             py::arg("angles_rad") = py::none(), py::arg("max_range_m") = 80.0,
             py::arg("T_world_laser") = py::none(), py::arg("config") = py::none(),
             py::arg("overrides") = py::none(),
             "extract_keypoints(scan, angles_rad=None, max_range_m=80.0, T_world_laser=None, "
             "config=None, overrides=None) -> Keypoints: FLIRT keypoints of a keyplace.Scan, or "
             "of ranges (1-D array, m) with their bearings angles_rad (laser frame, rad). "
             "T_world_laser: the frame the detector computes in (orients FLIRTLib's "
             "duplicate-suppression box); pass scan.logged_laser_pose to get exactly what "
             "`keyplace features` writes. Settings: the config's features section.");
  module.def(
      "descriptor_distance",
      [](const py::object& a, const py::object& b) {
        return SymmetricChi2(ToDescriptor(a), ToDescriptor(b));
      },
      py::arg("a"), py::arg("b"),
      "Symmetric chi-squared distance of two beta-grid descriptors (0 for equal ones; pairs "
      "below place.descriptor_match_chi2 match).");
}

}  // namespace keyplace::python
