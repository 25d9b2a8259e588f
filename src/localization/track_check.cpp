#include "keyplace/localization/track_check.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace keyplace {
namespace {

// The reference is made of the map places whose frames lie nearest the robot: as many as place
// recognition scores a candidate with (the candidate and a neighbour on each side), within the
// path of one bounded submap (mapping.max_path_m) of the robot.
constexpr std::size_t kTrackPlaces = 8;
constexpr double kTrackPlaceRadiusM = 8.0;
// Fewest endpoints where the reference looked for a verdict (as for a candidate's dense score).
constexpr int kTrackMinEndpoints = 50;
// The poses searched around a fix that fails the veto: turns up to the largest heading errors
// odometry has left in the logs (41 degrees after a fast turn, issue 30) and the translation of
// a few scans, on steps finer than the hit distance at 5 m; every 4th endpoint (about 225).
constexpr double kSearchHalfTurnRad = 45.0 * M_PI / 180.0;
constexpr double kSearchTurnStepRad = 2.0 * M_PI / 180.0;
constexpr double kSearchHalfShiftM = 0.8;
constexpr double kSearchShiftStepM = 0.2;
constexpr std::size_t kSearchStride = 2;
// The search uses the latest scans only: an odometry error that came between the recent scans
// (a turn it missed) leaves no single correction for all of them, and one made about the robot's
// position now is a turn plus a shift that grows with the path since the error (0.6 m per metre
// at 35 degrees, 0.77 m at 45): with a check every metre, the latest scans need the window above.
constexpr std::size_t kSearchScans = 3;

// Indices of up to kTrackPlaces places with occupancy nearest `position_m`, allowed by `allowed`.
template <typename Allowed>
std::vector<std::size_t> NearestPlaces(const std::vector<Place>& places,
                                       const Eigen::Vector2d& position_m, Allowed allowed) {
  std::vector<std::pair<double, std::size_t>> near;
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (places[p].occupancy_cells.empty() || !(places[p].occupancy_cell_m > 0.0)) continue;
    const double distance_m = (places[p].T_world_place.translation() - position_m).norm();
    if (distance_m <= kTrackPlaceRadiusM) near.emplace_back(distance_m, p);
  }
  std::sort(near.begin(), near.end());
  std::vector<std::size_t> chosen;
  for (const auto& [distance_m, p] : near) {
    if (chosen.size() == kTrackPlaces) break;
    if (allowed(places[p])) chosen.push_back(p);
  }
  return chosen;
}

// The occupied cells of `chosen` places in the world frame, on the first one's cell size.
std::vector<Eigen::Vector2i> WorldCells(const std::vector<Place>& places,
                                        const std::vector<std::size_t>& chosen, double cell_m) {
  std::vector<Eigen::Vector2i> cells;
  for (const std::size_t p : chosen) {
    const Place& place = places[p];
    const PointMapper to_world(place.T_world_place);
    for (const Eigen::Vector2i& cell : place.occupancy_cells) {
      const Eigen::Vector2d centre =
          (cell.cast<double>().array() + 0.5).matrix() * place.occupancy_cell_m;
      const Eigen::Vector2d point = to_world(centre);
      cells.emplace_back(static_cast<int>(std::floor(point.x() / cell_m)),
                         static_cast<int>(std::floor(point.y() / cell_m)));
    }
  }
  return cells;
}

// The best hit fraction of `scans` (world frame, as the fix put them) over the poses of the search
// window: turned about the robot's position `robot_m`, then shifted. The fix's own pose is in it.
std::pair<double, Pose2> BestNearby(const DenseReference& reference,
                                    const std::vector<QueryScanPoints>& scans,
                                    const Eigen::Vector2d& robot_m) {
  const int turns = static_cast<int>(std::round(kSearchHalfTurnRad / kSearchTurnStepRad));
  const int shifts = static_cast<int>(std::round(kSearchHalfShiftM / kSearchShiftStepM));
  double best = -1.0;
  Pose2 best_correction;  // world frame: applied to the fix's world poses
  for (int t = -turns; t <= turns; ++t) {
    const Pose2 turn_about_robot = Pose2(robot_m.x(), robot_m.y(), t * kSearchTurnStepRad) *
                                   Pose2(-robot_m.x(), -robot_m.y(), 0.0);
    for (int i = -shifts; i <= shifts; ++i) {
      for (int j = -shifts; j <= shifts; ++j) {
        const Pose2 correction =
            Pose2(i * kSearchShiftStepM, j * kSearchShiftStepM, 0.0) * turn_about_robot;
        const double hit = reference.HitFraction(correction, scans, kSearchStride);
        if (hit > best) {
          best = hit;
          best_correction = correction;
        }
      }
    }
  }
  return {best, best_correction};
}

}  // namespace

TrackCheck::TrackCheck(double misfit_turn_deg) : misfit_turn_rad_(misfit_turn_deg * M_PI / 180.0) {}

void TrackCheck::AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id) {
  scans_.push_back({T_odom_robot, DenseScanPoints(scan), scan_id});
  while (scans_.size() > kDenseQueryScans) scans_.pop_front();
}

TrackCheckResult TrackCheck::Check(const PlaceRecognizer& recognizer,
                                   const PlaceRecognitionConfig& place, const Pose2& T_world_odom,
                                   const QueryExclusion& exclusion) const {
  TrackCheckResult result;
  if (scans_.empty()) return result;
  std::vector<int> scan_ids;
  for (const RecentScan& recent : scans_) scan_ids.push_back(recent.scan_id);
  const Eigen::Vector2d robot_m = (T_world_odom * scans_.back().T_odom_robot).translation();
  const std::vector<Place>& places = recognizer.places();
  const std::vector<std::size_t> chosen = NearestPlaces(
      places, robot_m, [&](const Place& p) { return !exclusion || !exclusion(p, scan_ids); });
  if (chosen.empty()) return result;
  const double cell_m = places[chosen.front()].occupancy_cell_m;
  const DenseReference reference(WorldCells(places, chosen, cell_m), cell_m);
  if (reference.empty()) return result;

  std::vector<QueryScanPoints> in_world;
  in_world.reserve(scans_.size());
  for (const RecentScan& recent : scans_) {
    in_world.push_back(InQueryFrame(recent.points, T_world_odom * recent.T_odom_robot));
  }
  result.places = static_cast<int>(chosen.size());
  result.score = reference.Score(Pose2(), in_world);
  if (result.score.endpoints < kTrackMinEndpoints) return result;
  if (result.score.hit_fraction >= place.dense_sure_hit_fraction) {
    result.fit = TrackFit::kFits;
    return result;
  }
  // Not beyond doubt: either the fix is off (while the older scans still fit, from before an
  // odometry error, the latest ones already miss), or the places around it did not see all the
  // robot sees now (a room their scans never looked into). Only the first leaves a pose nearby
  // that puts the latest scans on the walls beyond doubt, and by more than the span between the
  // veto and that bar (dense_sure_hit_fraction - dense_min_hit_fraction) better than the fix: a
  // corridor's walls still catch half of the beams turned by 35 degrees.
  const std::vector<QueryScanPoints> latest(
      in_world.end() - static_cast<std::ptrdiff_t>(std::min(kSearchScans, in_world.size())),
      in_world.end());
  result.latest_hit_fraction = reference.HitFraction(Pose2(), latest, kSearchStride);
  const auto [best_hit, correction] = BestNearby(reference, latest, robot_m);
  result.best_hit_fraction = best_hit;
  result.T_world_odom_best = correction * T_world_odom;
  const double margin = place.dense_sure_hit_fraction - place.dense_min_hit_fraction;
  if (best_hit >= place.dense_sure_hit_fraction && result.latest_hit_fraction < best_hit - margin &&
      std::abs(WrapAngle(correction.theta)) > misfit_turn_rad_) {
    result.fit = TrackFit::kMisfit;
  } else if (result.score.hit_fraction >= place.dense_min_hit_fraction) {
    result.fit = TrackFit::kFits;
  }
  return result;
}

}  // namespace keyplace
