#include "keyplace/localization/track_check.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace keyplace {
namespace {

// The reference is made of the map places whose frames lie nearest the robot, within the path of
// one bounded submap (mapping.max_path_m): 8 of them, because the 3 that place recognition scores
// a candidate with (the candidate and a neighbour on each side) missed rooms the robot's scans
// looked into and gave up Intel's correct tracks (docs/LOCALIZATION.md).
constexpr std::size_t kTrackPlaces = 8;
constexpr double kTrackPlaceRadiusM = 8.0;
// Fewest endpoints where the reference looked for a verdict (as for a candidate's dense score).
constexpr int kTrackMinEndpoints = 50;
// The poses searched around a fix that does not fit beyond doubt: turns up to the largest heading
// errors odometry has left in the logs (41 degrees after a fast turn, issue 30) and the shift of
// the window below, on steps about the hit distance at 5 m; every 2nd endpoint (about 135).
constexpr int kSearchTurnSteps = 18;  // each side
constexpr double kSearchTurnStepRad = 2.5 * M_PI / 180.0;
constexpr int kSearchShiftSteps = 4;  // each side
constexpr double kSearchShiftStepM = 0.2;
constexpr std::size_t kSearchStride = 2;
// The search uses the latest scans only: an odometry error that came between the recent scans
// (a turn it missed) leaves no single correction for all of them, and one made about the robot's
// position now is a turn plus a shift that grows with the path since the error (0.6 m per metre
// at 35 degrees, 0.77 m at 45): with a check every metre (the default track_check_every_m), the
// latest scans need the window above. A pose that puts most of them outside the places' area
// says nothing: it must keep half of the endpoints the fix has there.
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
    AppendCellsInFrame(place.occupancy_cells, place.occupancy_cell_m, place.T_world_place, cell_m,
                       cells);
  }
  return cells;
}

// The best hits of `scans` (world frame, as the fix put them) over the poses of the search window
// that keep at least `min_endpoints` of them in the reference's area and hit with at least
// `min_hit_fraction` of them (turned about the robot's position `robot_m`, then shifted; the fix's
// own pose is in it), with the correction (world frame) that gives them; the first of equals.
// No pose does: hit_fraction 0. A pose is given up once it can no longer beat both the bar and
// the best so far (DenseReference::HitsReaching), which leaves the best unchanged.
std::pair<DenseScore, Pose2> BestNearby(const DenseReference& reference,
                                        const std::vector<QueryScanPoints>& scans,
                                        const Eigen::Vector2d& robot_m, int min_endpoints,
                                        double min_hit_fraction) {
  DenseScore best;
  Pose2 best_correction;
  for (int t = -kSearchTurnSteps; t <= kSearchTurnSteps; ++t) {
    const Pose2 turn_about_robot = Pose2(robot_m.x(), robot_m.y(), t * kSearchTurnStepRad) *
                                   Pose2(-robot_m.x(), -robot_m.y(), 0.0);
    for (int i = -kSearchShiftSteps; i <= kSearchShiftSteps; ++i) {
      for (int j = -kSearchShiftSteps; j <= kSearchShiftSteps; ++j) {
        const Pose2 correction =
            Pose2(i * kSearchShiftStepM, j * kSearchShiftStepM, 0.0) * turn_about_robot;
        const std::optional<DenseScore> hits = reference.HitsReaching(
            correction, scans, kSearchStride, std::max(min_hit_fraction, best.hit_fraction));
        if (hits && hits->endpoints >= min_endpoints && hits->hit_fraction >= min_hit_fraction &&
            hits->hit_fraction > best.hit_fraction) {
          best = *hits;
          best_correction = correction;
        }
      }
    }
  }
  return {best, best_correction};
}

// The last kSearchScans of `scans`.
std::vector<QueryScanPoints> Latest(const std::vector<QueryScanPoints>& scans) {
  const auto count = static_cast<std::ptrdiff_t>(std::min(kSearchScans, scans.size()));
  return {scans.end() - count, scans.end()};
}

}  // namespace

std::string ToString(TrackFit fit) {
  switch (fit) {
    case TrackFit::kUnknown:
      return "unknown";
    case TrackFit::kFits:
      return "fits";
    case TrackFit::kMisfit:
      return "misfit";
  }
  return "?";
}

TrackCheck::TrackCheck(double misfit_turn_deg) : misfit_turn_rad_(misfit_turn_deg * M_PI / 180.0) {}

void TrackCheck::AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id) {
  scans_.push_back({T_odom_robot, DenseScanPoints(scan), scan_id});
  while (scans_.size() > kDenseQueryScans) scans_.pop_front();
}

TrackCheckResult TrackCheck::Check(const PlaceRecognizer& recognizer,
                                   const PlaceRecognitionConfig& place, const Pose2& T_world_odom,
                                   const QueryExclusion& exclusion) {
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
  result.T_world_odom_best = T_world_odom;
  if (result.score.endpoints < kTrackMinEndpoints) return result;
  Judge(reference, Latest(in_world), robot_m, place, T_world_odom, result);
  return result;
}

// The verdict on a fix whose recent scans (score) fell where the places looked. Beyond doubt, on
// all of them and on the latest, it fits. Otherwise either the fix is off (the older scans may
// still fit, from before an odometry error, while the latest already miss), or the places did not
// see all the robot sees now (a room their scans never looked into). Only the first leaves a pose
// nearby that puts the latest scans on the walls beyond doubt, and by more than the span between
// the veto and that bar (dense_sure_hit_fraction - dense_min_hit_fraction) better than the fix: a
// corridor's walls still catch half of the beams turned by 35 degrees. Three scans close together
// can still prefer a look-alike pose (FR079: turned by 17.5 degrees and shifted by 0.9 m), so
// such a pose is only a suspect until the next check's scans, which it did not choose, confirm it
// as a map <- odometry transform: an odometry error is one transform for every scan after it.
void TrackCheck::Judge(const DenseReference& reference, const std::vector<QueryScanPoints>& latest,
                       const Eigen::Vector2d& robot_m, const PlaceRecognitionConfig& place,
                       const Pose2& T_world_odom, TrackCheckResult& result) {
  const DenseScore at_fix = reference.Hits(Pose2(), latest, kSearchStride);
  result.latest_hit_fraction = at_fix.hit_fraction;
  const std::optional<Pose2> suspect = std::exchange(suspect_T_world_odom_, std::nullopt);
  if (result.score.hit_fraction >= place.dense_sure_hit_fraction &&
      at_fix.hit_fraction >= place.dense_sure_hit_fraction) {
    result.fit = TrackFit::kFits;
    return;
  }
  const int min_endpoints = std::max(kTrackMinEndpoints / 2, at_fix.endpoints / 2);
  const double margin = place.dense_sure_hit_fraction - place.dense_min_hit_fraction;
  const auto much_better = [&](const DenseScore& hits) {
    return hits.endpoints >= min_endpoints && hits.hit_fraction >= place.dense_sure_hit_fraction &&
           at_fix.hit_fraction < hits.hit_fraction - margin;
  };
  if (suspect) {
    const DenseScore at_suspect =
        reference.Hits(*suspect * T_world_odom.inverse(), latest, kSearchStride);
    result.best_hit_fraction = at_suspect.hit_fraction;
    result.T_world_odom_best = *suspect;
    if (much_better(at_suspect)) {
      result.fit = TrackFit::kMisfit;
      return;
    }
  }
  // Only a pose at least this good can make a suspect (much_better; the tolerance keeps one
  // that passes it by a rounding error), so no other needs to be scored to the end.
  const double suspect_bar =
      std::max(place.dense_sure_hit_fraction, at_fix.hit_fraction + margin) - 1e-9;
  const auto [best, correction] =
      BestNearby(reference, latest, robot_m, min_endpoints, suspect_bar);
  if (best.hit_fraction > result.best_hit_fraction) {
    result.best_hit_fraction = best.hit_fraction;
    result.T_world_odom_best = correction * T_world_odom;
  }
  if (much_better(best) && std::abs(WrapAngle(correction.theta)) > misfit_turn_rad_) {
    suspect_T_world_odom_ = correction * T_world_odom;
  } else if (result.score.hit_fraction >= place.dense_min_hit_fraction) {
    result.fit = TrackFit::kFits;
  }
}

}  // namespace keyplace
