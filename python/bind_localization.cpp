// The streaming localizers (localization/global_localizer.hpp, relocalizer.hpp): one scan and
// its odometry pose at a time, as a robot feeds them.

#include <optional>
#include <string>
#include <utility>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/relocalizer.hpp"

namespace keyplace::python {
namespace {

template <typename Localizer>
Localizer MakeLocalizer(const py::object& map, const py::object& config,
                        const py::object& overrides) {
  const Config resolved = ResolveConfig(config, overrides).config;
  const GlobalMap global_map = ToMap(map);
  py::gil_scoped_release release;
  return Localizer(global_map, ToLocalizerConfig(resolved), resolved.features);
}

constexpr const char* kAddScanArguments =
    "scan: a keyplace.Scan, or ranges (1-D array, m) with angles_rad (laser frame, rad), "
    "max_range_m and laser_pose (T_robot_laser; None: identity). odom_pose: T_odom_robot "
    "[x_m, y_m, theta_rad], the robot's pose in its odometry frame.";

void BindPlaceMatch(py::module_& module) {
  py::class_<PlaceMatch>(module, "PlaceMatch", "The details of one place recognition.")
      .def_readonly("verified", &PlaceMatch::verified, "A candidate passed both checks.")
      .def_readonly("found", &PlaceMatch::found, "Verified, not ambiguous, confident enough.")
      .def_readonly("ambiguous", &PlaceMatch::ambiguous)
      .def_readonly("place_id", &PlaceMatch::place_id, "Matched submap id (-1: none).")
      .def_property_readonly(
          "T_ref_cur", [](const PlaceMatch& m) { return PoseArray(m.T_ref_cur); },
          "The query frame in the matched submap's frame.")
      .def_property_readonly(
          "estimated_pose", [](const PlaceMatch& m) { return PoseArray(m.estimated_pose); },
          "The estimated pose in the map frame (paper Eq. 9).")
      .def_property_readonly(
          "estimated_pose_covariance",
          [](const PlaceMatch& m) { return CovarianceArray(m.estimated_pose_covariance); },
          "3 x 3 covariance of estimated_pose over (x, y, theta), from the RANSAC inliers' "
          "least-squares fit (docs/NAVIGATION.md).")
      .def_readonly("pairs", &PlaceMatch::pairs, "Unique descriptor pairs with the match.")
      .def_readonly("consensus", &PlaceMatch::consensus, "RANSAC consensus.")
      .def_readonly("gamma", &PlaceMatch::gamma, "Second verification (paper Eq. 10).")
      .def_readonly("reference_coverage", &PlaceMatch::reference_coverage)
      .def_readonly("dense_checked", &PlaceMatch::dense_checked,
                    "The query's beams were scored against the matched submap's occupancy.")
      .def_property_readonly(
          "dense_hit_fraction", [](const PlaceMatch& m) { return m.dense.hit_fraction; },
          "Share of the query's endpoints in the submap's area that end on its walls.")
      .def_property_readonly(
          "dense_see_through", [](const PlaceMatch& m) { return m.dense.see_through_fraction; },
          "Share of the query's beams crossing the submap's area that pass through a wall.")
      .def_readonly("score", &PlaceMatch::score)
      .def_readonly("second_score", &PlaceMatch::second_score)
      .def_readonly("confidence", &PlaceMatch::confidence, "In [0, 1].")
      .def_readonly("candidates", &PlaceMatch::candidates)
      .def_readonly("candidates_verified", &PlaceMatch::candidates_verified)
      .def_readonly("candidates_accepted", &PlaceMatch::candidates_accepted)
      .def_readonly("seconds", &PlaceMatch::seconds, "Time of the recognition (s).");
}

void BindLocalizationResult(py::module_& module) {
  py::class_<LocalizationResult>(module, "LocalizationResult",
                                 "One answer of the GlobalLocalizer (a completed query submap).")
      .def_readonly("found", &LocalizationResult::found,
                    "The match was accepted (verified, not ambiguous, confident enough).")
      .def_readonly("ambiguous", &LocalizationResult::ambiguous)
      .def_readonly("confidence", &LocalizationResult::confidence, "In [0, 1].")
      .def_readonly("submap_id", &LocalizationResult::submap_id, "Matched submap (-1: none).")
      .def_property_readonly(
          "pose", [](const LocalizationResult& r) { return PoseArray(r.T_world_robot); },
          "T_world_robot at the latest scan [x_m, y_m, theta_rad] (valid when match.verified).")
      .def_property_readonly(
          "T_world_odom", [](const LocalizationResult& r) { return PoseArray(r.T_world_odom); },
          "The map <- odometry correction: T_world_robot = T_world_odom * T_odom_robot.")
      .def_property_readonly(
          "T_odom_origin", [](const LocalizationResult& r) { return PoseArray(r.T_odom_origin); },
          "Odometry pose of the query's first scan (the query frame).")
      .def_readonly("scans", &LocalizationResult::scans, "Scans in the query.")
      .def_readonly("query_id", &LocalizationResult::query_id,
                    "Answers with the same id came from one growing query (-1: independent).")
      .def_property_readonly(
          "scan_ids", [](const LocalizationResult& r) { return VectorArray(r.scan_ids); },
          "The ids given to add_scan for the query's scans (-1 when none was given).")
      .def_property_readonly(
          "weak_T_world_odom",
          [](const LocalizationResult& r) { return OptionalPoseArray(r.weak_T_world_odom); },
          "Not found, but a weak answer (keypoints and beams support it, gamma did not pass): "
          "its map <- odometry correction; None otherwise. The Relocalizer adds these up.")
      .def_readonly("match", &LocalizationResult::match, "The PlaceMatch details.")
      .def("__repr__", [](const LocalizationResult& r) {
        return std::string("<keyplace.LocalizationResult ") + (r.found ? "found" : "not found") +
               ", submap " + std::to_string(r.submap_id) + ", confidence " +
               std::to_string(r.confidence) + ">";
      });
}

void BindGlobalLocalizer(py::module_& module) {
  py::class_<GlobalLocalizer>(
      module, "GlobalLocalizer",
      "Streaming global localization (paper Algorithm 4): scans go into a query submap built as "
      "the map's were; when it completes it is recognised against the map.")
      .def(py::init(&MakeLocalizer<GlobalLocalizer>), py::arg("map"),
           py::arg("config") = py::none(), py::arg("overrides") = py::none(),
           "GlobalLocalizer(map, config=None, overrides=None): map is a keyplace.Map or a map "
           "file path; settings from the config's place and localization sections.")
      .def(
          "add_scan",
          [](GlobalLocalizer& localizer, const py::object& scan, const py::object& odom_pose,
             const py::object& angles_rad, double max_range_m, const py::object& laser_pose) {
            const LaserScan laser_scan = ToScan(scan, angles_rad, max_range_m, laser_pose);
            const Pose2 T_odom_robot = ToPose(odom_pose, "odom_pose");
            py::gil_scoped_release release;
            return localizer.AddScan(laser_scan, T_odom_robot);
          },
          py::arg("scan"), py::arg("odom_pose"), py::arg("angles_rad") = py::none(),
          py::arg("max_range_m") = 80.0, py::arg("laser_pose") = py::none(),
          (std::string("add_scan(scan, odom_pose, angles_rad=None, max_range_m=80.0, "
                       "laser_pose=None) -> LocalizationResult or None: None until the query "
                       "submap completes with this scan; then the answer (its `found` says "
                       "whether it was accepted). ") +
           kAddScanArguments)
              .c_str())
      .def(
          "localize_now",
          [](const GlobalLocalizer& localizer) {
            py::gil_scoped_release release;
            return localizer.LocalizeNow();
          },
          "Recognises the query as it stands (incomplete); None when no scan was added since the "
          "last answer or reset().")
      .def("reset", &GlobalLocalizer::Reset, "Forgets the query being built (kidnapped robot).")
      .def_property_readonly("buffered_scans", &GlobalLocalizer::buffered_scans,
                             "Scans in the query being built.")
      .def_property_readonly(
          "place_count",
          [](const GlobalLocalizer& localizer) { return localizer.recognizer().places().size(); },
          "Places (submaps) of the map.");
}

void BindRelocalizer(py::module_& module) {
  py::class_<RelocalizationUpdate>(module, "RelocalizationUpdate", "The Relocalizer after a scan.")
      .def_property_readonly(
          "status", [](const RelocalizationUpdate& u) { return ToString(u.status); },
          "'searching', 'fixed' or 'lost'.")
      .def_readonly("new_fix", &RelocalizationUpdate::new_fix)
      .def_readonly("lost", &RelocalizationUpdate::lost)
      .def_property_readonly(
          "pose", [](const RelocalizationUpdate& u) { return PoseArray(u.T_world_robot); },
          "T_world_robot now (valid when status is 'fixed').")
      .def_property_readonly(
          "T_world_odom", [](const RelocalizationUpdate& u) { return PoseArray(u.T_world_odom); })
      .def_readonly("confidence", &RelocalizationUpdate::confidence)
      .def_readonly("unconfirmed_m", &RelocalizationUpdate::unconfirmed_m,
                    "Odometry distance since the last confirming answer (m).")
      .def_readonly("position_variance_m2", &RelocalizationUpdate::position_variance_m2)
      .def_readonly("heading_variance_rad2", &RelocalizationUpdate::heading_variance_rad2)
      .def_property_readonly(
          "covariance", [](const RelocalizationUpdate& u) { return CovarianceArray(u.covariance); },
          "3 x 3 covariance of pose over (x, y, theta), derived from the matches (valid when "
          "status is 'fixed').")
      .def_readonly("answer", &RelocalizationUpdate::answer,
                    "The GlobalLocalizer's answer with this scan, or None.")
      .def_readonly("map_search_answer", &RelocalizationUpdate::map_search_answer,
                    "The answer of a search of the whole map taken with this scan (judged after "
                    "`answer`), or None.")
      .def_readonly("confirmed", &RelocalizationUpdate::confirmed)
      .def_readonly("contradicted", &RelocalizationUpdate::contradicted)
      .def_readonly("self_contradicted", &RelocalizationUpdate::self_contradicted,
                    "The answer's query named places that disagree: its answers were set aside.")
      .def_property_readonly(
          "track_fit", [](const RelocalizationUpdate& u) { return ToString(u.track_fit); },
          "The track check of this scan: 'unknown' (none, or the map cannot tell), 'fits' or "
          "'misfit'.")
      .def_readonly("track_misfit", &RelocalizationUpdate::track_misfit,
                    "The fix was given up because the scans no longer fit the map at it.");

  py::class_<Relocalizer>(module, "Relocalizer",
                          "The GlobalLocalizer's answers turned into a fix once they agree "
                          "through odometry, tracked, and lost when no answer confirms it.")
      .def(py::init(&MakeLocalizer<Relocalizer>), py::arg("map"), py::arg("config") = py::none(),
           py::arg("overrides") = py::none(),
           "Relocalizer(map, config=None, overrides=None); fix policy: localization.fix.*.")
      .def(
          "add_scan",
          [](Relocalizer& relocalizer, const py::object& scan, const py::object& odom_pose,
             const py::object& angles_rad, double max_range_m, const py::object& laser_pose) {
            const LaserScan laser_scan = ToScan(scan, angles_rad, max_range_m, laser_pose);
            const Pose2 T_odom_robot = ToPose(odom_pose, "odom_pose");
            py::gil_scoped_release release;
            return relocalizer.AddScan(laser_scan, T_odom_robot);
          },
          py::arg("scan"), py::arg("odom_pose"), py::arg("angles_rad") = py::none(),
          py::arg("max_range_m") = 80.0, py::arg("laser_pose") = py::none(),
          (std::string("add_scan(scan, odom_pose, ...) -> RelocalizationUpdate. ") +
           kAddScanArguments)
              .c_str())
      .def("reset", &Relocalizer::Reset, "Forgets fix, hypotheses and the query.")
      .def_property_readonly("status", [](const Relocalizer& r) { return ToString(r.status()); });
}

}  // namespace

void BindLocalization(py::module_& module) {
  BindPlaceMatch(module);
  BindLocalizationResult(module);
  BindGlobalLocalizer(module);
  BindRelocalizer(module);
}

}  // namespace keyplace::python
