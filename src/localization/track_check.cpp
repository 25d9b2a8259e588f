#include "keyplace/localization/track_check.hpp"

namespace keyplace {

void TrackCheck::AddScan(const LaserScan& scan, const Pose2& T_odom_robot) {
  scans_.push_back(InQueryFrame(DenseScanPoints(scan), T_odom_robot));
  if (scans_.size() > kDenseQueryScans) scans_.pop_front();
  last_T_odom_robot_ = T_odom_robot;
  ++scans_since_check_;
}

TrackFit TrackCheck::Check(const std::vector<Place>& places, const PlaceRecognitionConfig& config,
                           const Pose2& T_world_odom) {
  // Verdicts on disjoint scans: two misfits are two pieces of evidence, not one seen twice.
  if (scans_since_check_ < kDenseQueryScans) return TrackFit::kUnknown;
  scans_since_check_ = 0;
  if (config.dense_min_hit_fraction <= 0.0) return TrackFit::kUnknown;
  const std::vector<int> around =
      PlacesAround(places, (T_world_odom * last_T_odom_robot_).translation());
  if (around.empty()) return TrackFit::kUnknown;
  if (around != reference_places_ || !reference_) {
    reference_ =
        PlaceOccupancy(places, around.front(), std::vector<int>(around.begin() + 1, around.end()));
    reference_places_ = around;
  }
  if (reference_->empty()) return TrackFit::kUnknown;
  const Pose2 T_place_odom =
      places[static_cast<std::size_t>(around.front())].T_world_place.inverse() * T_world_odom;
  const DenseScore score =
      reference_->Score(T_place_odom, std::vector<QueryScanPoints>(scans_.begin(), scans_.end()));
  if (score.endpoints < kDenseMinEndpoints) return TrackFit::kUnknown;
  last_score_ = score;
  // Hits only: every pass of the map around the robot is in the reference, with the doors each
  // found open or closed and the walls each put a few centimetres apart, so beams "see through"
  // a quarter of it and more on a right track (FR079), while a beam far from every wall the map
  // ever saw here is evidence against the fix.
  return score.hit_fraction < config.dense_min_hit_fraction ? TrackFit::kMisfit : TrackFit::kFits;
}

std::vector<int> TrackCheck::PlacesAround(const std::vector<Place>& places,
                                          const Eigen::Vector2d& position_m) {
  if (areas_.size() != places.size()) {
    areas_.assign(places.size(), Eigen::AlignedBox2d());
    reference_.reset();
    for (std::size_t p = 0; p < places.size(); ++p) {
      const Place& place = places[p];
      const PointMapper to_world(place.T_world_place);
      for (const Eigen::Vector2i& cell : place.occupancy_cells) {
        areas_[p].extend(
            to_world((cell.cast<double>().array() + 0.5).matrix() * place.occupancy_cell_m));
      }
    }
  }
  std::vector<int> around;
  for (std::size_t p = 0; p < areas_.size(); ++p) {
    if (!areas_[p].isEmpty() && areas_[p].contains(position_m))
      around.push_back(static_cast<int>(p));
  }
  return around;
}

void TrackCheck::Reset() {
  scans_.clear();
  last_T_odom_robot_ = Pose2();
  scans_since_check_ = 0;
  last_score_ = DenseScore();
}

}  // namespace keyplace
