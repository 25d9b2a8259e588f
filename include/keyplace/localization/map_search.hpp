#pragma once
// Where in the whole map do the robot's last few metres of scans fit? Keypoints propose places
// only where enough stable keypoints were re-detected; in an open hall or a log of scans a metre
// apart that is rare, while the walls the beams end on are there at every scan. This searches
// every pose of the map, every 2 degrees and every cell, for the one that puts the recent beams
// on the map's occupied cells, by branch and bound over a pyramid of maxima of a closeness field
// (the global search of Hess et al., "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016), and
// then for the best pose distinct from it (more than kDistinctM or kDistinctDeg away). The
// answer counts only when the best beats every distinct pose by a margin: a corridor or two
// look-alike rooms fit several poses nearly as well, and then nothing is said
// (docs/LOCALIZATION.md, "Search of the whole map").

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// Two poses of a search are distinct when they lie this far apart or are turned by this much.
inline constexpr double kMapSearchDistinctM = 1.0;
inline constexpr double kMapSearchDistinctDeg = 20.0;
/// Rotations over the circle a search tries at most (every 2 degrees).
inline constexpr int kMapSearchRotations = 180;

struct MapSearchResult {
  bool found = false;   // the best pose beats every distinct pose by the margin asked for
  Pose2 T_world_robot;  // the best pose (valid when score > 0)
  double score = 0.0;   // mean closeness of the points there, 0..1
  // The best score of a pose distinct from the best (0 when none scores above the search's floor).
  double runner_up = 0.0;
  long long nodes = 0;  // poses and boxes of poses scored (the search's cost)
};

/// The map's occupancy as a closeness field exp(-d² / 2σ²) of the distance d to the nearest
/// occupied cell (σ = 1.5 cells, 0 beyond 3σ) on the map's own cells, quantized to a byte, with
/// the maxima over squares of 2^h cells that bound a box of translations from above.
class MapField {
 public:
  /// The field of the places marked in `use` (all when empty), their Place::occupancy_cells put
  /// into the world by T_world_place. An empty field (no occupied cell) finds nothing.
  explicit MapField(const std::vector<Place>& places, const std::vector<char>& use = {});

  /// The best pose of points (robot frame) and whether a distinct one comes within min_margin
  /// of it. `found` when the best scores at least min_score and none does.
  MapSearchResult Search(const std::vector<Eigen::Vector2d>& points_robot, double min_score,
                         double min_margin) const;

  bool empty() const { return width_ == 0; }
  double cell_m() const { return cell_m_; }

 private:
  // A box of 2^level x 2^level translations (robot cells from x, y) at one rotation.
  struct Node {
    float bound = 0.0F;
    int rotation = 0;
    int x = 0;
    int y = 0;
  };
  // The points' cell offsets at one rotation.
  struct Rotation {
    int index = 0;  // of kRotations over the circle
    double theta_rad = 0.0;
    std::vector<Eigen::Vector2i> offsets;
  };
  // Called at each pose (level 0) that scores above the floor; may raise the floor.
  using Visit = std::function<void(const Node&, float& floor)>;
  // Mean closeness of the rotation's points with the robot in cell (x, y), at `level`: an upper
  // bound of the score of every translation of the box. Once it cannot exceed `floor` the sum
  // stops, and the value returned is still a bound, at or below the floor.
  float Bound(const Rotation& rotation, int x, int y, int level, float floor) const;
  // Depth first, best bound first; boxes not above the floor are pruned.
  void Branch(const std::vector<Rotation>& rotations, std::vector<Node>& nodes, int level,
              float& floor, const Visit& visit, long long& count) const;
  std::vector<Rotation> Rotations(const std::vector<Eigen::Vector2d>& points_robot) const;
  bool Distinct(const std::vector<Rotation>& rotations, const Node& a, const Node& b) const;

  double cell_m_ = 0.1;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();  // world position of cell (0, 0)'s centre
  int width_ = 0;
  int height_ = 0;
  std::vector<std::vector<std::uint8_t>> levels_;  // levels_[h]: maxima over 2^h x 2^h cells
};

/// Feeds the Relocalizer answers from searches of the whole map while it has no fix: every
/// `window_m` of odometry, the beams of the scans over the last window_m (DenseScanPoints) are
/// searched (MapField::Search); a pose found becomes an accepted answer.
class MapSearch {
 public:
  /// window_m <= 0: never searches.
  MapSearch(double window_m, double min_margin);

  void AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id);
  /// An answer when a search is due and finds a pose (the field of the places `exclusion` allows
  /// for the window's scan ids; rebuilt only when they change).
  std::optional<LocalizationResult> Search(const PlaceRecognizer& recognizer,
                                           const QueryExclusion& exclusion);
  /// Forgets the scans and the distance since the last search (not the field).
  void Reset();

 private:
  struct Recent {
    Pose2 T_odom_robot;
    std::vector<Eigen::Vector2d> endpoints_robot;
    int scan_id = -1;
    double odometry_m = 0.0;  // path since construction or Reset
  };
  const MapField& FieldFor(const PlaceRecognizer& recognizer, const std::vector<char>& use);

  double window_m_;
  double min_margin_;
  std::deque<Recent> recent_;
  double odometry_m_ = 0.0;
  double searched_at_m_ = 0.0;
  std::shared_ptr<const MapField> field_;
  std::vector<char> field_use_;
  const PlaceRecognizer* field_recognizer_ = nullptr;
};

}  // namespace keyplace
