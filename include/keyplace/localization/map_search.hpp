#pragma once
// Where in the whole map do the robot's last few metres of scans fit? Keypoints propose places
// only where enough stable keypoints were re-detected; in an open hall or a log of scans a metre
// apart that is rare, while the walls the beams end on are there at every scan. This searches
// every pose of the map, every 2 degrees and every cell, for the one that puts the recent beams
// on the map's occupied cells, by branch and bound over a pyramid of maxima of a closeness field
// (the global search of Hess et al., "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016), and
// then for a pose distinct from it (more than kMapSearchDistinctM or kMapSearchDistinctDeg away)
// that scores nearly as well. The answer counts only when there is none: a corridor or two
// look-alike rooms fit several poses nearly as well, and then nothing is said
// (docs/LOCALIZATION.md, "Search of the whole map").

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// Two poses of a search are distinct when they lie this far apart or are turned by this much.
inline constexpr double kMapSearchDistinctM = 1.0;
inline constexpr double kMapSearchDistinctDeg = 20.0;
/// Turns a search tries: every 2 degrees of the circle.
inline constexpr int kMapSearchRotations = 180;
/// A map whose field would hold more cells is not searched (its field is empty): 2^24 cells of
/// 0.2 m are 820 x 820 m, and the field's pyramid holds a byte per cell and level.
inline constexpr std::size_t kMapSearchMaxCells = std::size_t{1} << 24;

struct MapSearchResult {
  bool found = false;   // the best pose beats every distinct pose by the margin asked for
  Pose2 T_world_robot;  // the best pose (valid when score > 0)
  double score = 0.0;   // mean closeness of the points there, 0..1
  // When not found: the score of a distinct pose within the margin of the best (the first the
  // search met, not necessarily the best of them); 0 when found or when nothing scored.
  double rival_score = 0.0;
  long long nodes = 0;  // poses and boxes of poses scored (the search's cost)
};

/// The map's occupancy as a closeness field exp(-d² / 2σ²) of the distance d to the nearest
/// occupied cell, on cells twice the map's (0.2 m for its 0.1 m), σ = 1.5 cells, cut at 5 cells;
/// quantized to a byte, with the maxima over squares of 2^h cells that bound a box of
/// translations from above.
class MapField {
 public:
  /// The field of the places marked in `use` (all when empty; otherwise one flag per place), their
  /// Place::occupancy_cells put into the world by T_world_place. A field without occupied cells,
  /// or of more than kMapSearchMaxCells, is empty and finds nothing.
  /// Throws std::invalid_argument when `use` is neither empty nor one flag per place.
  explicit MapField(const std::vector<Place>& places, const std::vector<char>& use = {});

  /// What a field is made of: the occupied cells of the places in the world, on its cells.
  struct Cells {
    std::vector<Eigen::Vector2i> world_cells;
    double cell_m = 0.2;
  };
  /// The cells of the field of `places` and `use` (as the constructor above takes them): the
  /// places are read here, and the field can be built from the cells on another thread.
  static Cells OccupiedCells(const std::vector<Place>& places, const std::vector<char>& use = {});
  explicit MapField(const Cells& cells);

  /// The best pose of points (robot frame) over every turn and cell, and whether a distinct one
  /// comes within min_margin of it. `found` when the best scores above min_score and none does.
  /// A search whose `stop` is raised ends early and finds nothing.
  MapSearchResult Search(const std::vector<Eigen::Vector2d>& points_robot, double min_score,
                         double min_margin, const std::atomic<bool>* stop = nullptr) const;

  /// The points' mean closeness at a pose, as the search scores its poses (a pose at a cell
  /// centre, turned by a multiple of 2 degrees, scores exactly what the search gives it).
  double ScoreAt(const std::vector<Eigen::Vector2d>& points_robot,
                 const Pose2& T_world_robot) const;

  /// The pose within a cell and a turn step of the search's grid around T_world_robot where the
  /// points' closeness, interpolated between cell centres (InterpolatedScoreAt), is highest: the
  /// search places the robot on 0.2 m cells and 2 degree turns, and a heading 1 degree off puts
  /// the robot 0.35 m away 20 m further on. Steps of half a cell and half a turn step, halved
  /// whenever no neighbour scores higher, down to a sixteenth of them.
  Pose2 Refine(const std::vector<Eigen::Vector2d>& points_robot, const Pose2& T_world_robot) const;

  /// The points' mean closeness at any pose, bilinear between the field's cell centres.
  double InterpolatedScoreAt(const std::vector<Eigen::Vector2d>& points_robot,
                             const Pose2& T_world_robot) const;

  bool empty() const { return width_ == 0; }
  double cell_m() const { return cell_m_; }
  /// World position of the centre of cell (0, 0) and the cells per side.
  const Eigen::Vector2d& origin() const { return origin_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  // A box of 2^level x 2^level translations (robot cells from x, y) at one turn.
  struct Node {
    float bound = 0.0F;
    int rotation = 0;  // of kMapSearchRotations
    int x = 0;
    int y = 0;
  };
  // The points' cell offsets at each turn.
  using Offsets = std::vector<Eigen::Vector2i>;
  // Called at each pose (level 0) that scores above the floor; may raise the floor.
  using Visit = std::function<void(const Node&, float& floor_score)>;

  void BuildField(const std::vector<Eigen::Vector2i>& world_cells);
  void BuildPyramid();
  // Mean closeness of the points (offsets) with the robot in cell (x, y), at `level`: an upper
  // bound of the score of every translation of the box.
  float Bound(const Offsets& offsets, int x, int y, int level) const;
  // Depth first, best bound first; boxes not above the floor are pruned.
  void Branch(const std::vector<Offsets>& rotations, Node* nodes, std::size_t count, int level,
              float& floor_score, const Visit& visit, long long& scored,
              const std::atomic<bool>* stop) const;
  std::vector<Offsets> Rotations(const std::vector<Eigen::Vector2d>& points_robot) const;
  bool Distinct(const Node& a, const Node& b) const;

  double cell_m_ = 0.2;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int width_ = 0;
  int height_ = 0;
  std::vector<std::vector<std::uint8_t>> levels_;  // levels_[h]: maxima over 2^h x 2^h cells
};

/// Feeds the Relocalizer answers from searches of the whole map while it has no fix: every
/// `every_m` of odometry, the beams of the scans over the last window_m at most (DenseScanPoints)
/// are searched (MapField::Search); a pose found, refined between the search's cells and turns
/// (MapField::Refine), becomes an accepted answer. The field is kept between searches for the same
/// recognizer and the same places allowed (from a search taken or stopped by Cancel); a recognizer
/// changed in place (PlaceRecognizer::AddPlace) needs Reset(true).
///
/// In the background, a search runs on a thread of its own and its answer comes with the first
/// call to Search after it ends (one search at a time; the answer's T_world_odom holds whenever
/// it comes): a robot's scans are not held up by a search of a large map. Otherwise Search
/// searches before it returns, and the answers depend on the scans alone (replays, tests).
class MapSearch {
 public:
  /// window_m <= 0: never searches; every_m > 0.
  /// A copy has the scans and the field, not a search still running (it searches that window
  /// again); destroying or assigning to one stops its search and waits for the thread.
  MapSearch(double window_m, double every_m, double min_margin, bool background = false);

  void AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id);
  /// An answer when a search is due and finds a pose (the field of the places `exclusion` allows
  /// for the window's scan ids; rebuilt only when they change), or, in the background, when a
  /// search that found one has ended.
  std::optional<LocalizationResult> Search(const PlaceRecognizer& recognizer,
                                           const QueryExclusion& exclusion);
  /// Forgets the scans, the distance since the last search and a search still running (stopped),
  /// and the field with forget_field.
  void Reset(bool forget_field = false);

  /// Stops a search still running and drops it unanswered (its answer would be stale when it is
  /// taken: the Relocalizer got a fix meanwhile). The search stops once its field is built, if it
  /// builds one, so this may wait for the rest of that build; the field is kept.
  void Cancel();

  void set_background(bool background) { background_ = background; }
  bool background() const { return background_; }
  /// A search runs in the background (its answer not yet taken by Search).
  bool searching() const { return running_.search.has_value(); }
  /// A background search has ended: the next call to Search takes its answer.
  bool search_ended() const {
    return running_.search &&
           running_.search->future.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  }
  /// Searches that ran to their end and were taken, and the time they took (on whichever thread
  /// ran them, building the field from the places' cells included when the places searched
  /// changed); a search stopped by Cancel or Reset is not counted, nor is the time it took to
  /// build the field it leaves to the next.
  long long searches() const { return searches_; }
  double search_s() const { return search_s_; }
  /// Fields the searches built (one per search whose places differ from the field kept).
  long long fields_built() const { return fields_built_; }

 private:
  struct Recent {
    Pose2 T_odom_robot;
    std::vector<Eigen::Vector2d> endpoints_robot;
    int scan_id = -1;
    double odometry_m = 0.0;  // path since construction or Reset
    long long number = 0;     // scans_kept_ when it was kept
  };
  // What an answer needs besides the search's result: the window it searched.
  struct Window {
    std::vector<Eigen::Vector2d> points_robot;  // in the frame of the newest scan
    std::vector<int> scan_ids;
    Pose2 T_odom_newest;
    Pose2 T_odom_oldest;
    std::size_t scans = 0;
    long long first_number = 0;
    long long last_number = 0;
  };
  // The places a field is of, to know when it can be kept for the next search.
  struct FieldKey {
    const PlaceRecognizer* recognizer = nullptr;
    std::vector<char> use;
    bool operator==(const FieldKey& other) const {
      return recognizer == other.recognizer && use == other.use;
    }
  };
  struct Searched {
    MapSearchResult result;
    Pose2 T_world_robot;   // the result's pose refined (MapField::Refine) when found
    double seconds = 0.0;  // building the field from the cells, when it was, included
    std::shared_ptr<const MapField> field;  // the field searched
  };
  // A search on a thread of its own.
  struct Running {
    Window window;
    FieldKey key;                             // of the field it searches
    std::shared_ptr<std::atomic<bool>> stop;  // the search's thread holds it too
    std::future<Searched> future;
    double launched_at_m = 0.0;  // becomes searched_at_m_ when the search is taken or stopped
  };
  // Holds the search running in the background: a copy holds none, and replacing or destroying
  // the search stops it and waits for its thread.
  class RunningSlot {
   public:
    RunningSlot() = default;
    RunningSlot(const RunningSlot& /*other*/) {}
    RunningSlot& operator=(const RunningSlot& other) {
      if (this != &other) Stop();
      return *this;
    }
    ~RunningSlot() { Stop(); }
    void Stop();

    std::optional<Running> search;
  };
  Window CurrentWindow() const;
  // Stops a search still running (uncounted, unanswered) and waits for its thread; keeps the
  // field it built with keep_field.
  void StopSearch(bool keep_field);
  // Keeps the searched field for the next search of the same places, counts the search and
  // makes its answer, if it found a pose.
  std::optional<LocalizationResult> TakeAnswer(const Searched& searched, const Window& window,
                                               FieldKey key);

  double window_m_;
  double every_m_;
  double min_margin_;
  bool background_;
  std::deque<Recent> recent_;  // scans at least a few cm or degrees apart
  std::optional<Pose2> last_T_odom_robot_;
  double odometry_m_ = 0.0;
  std::optional<double> searched_at_m_;
  std::shared_ptr<const MapField> field_;  // of the places field_key_ says
  FieldKey field_key_;
  RunningSlot running_;
  long long searches_ = 0;
  long long fields_built_ = 0;
  // Numbers the scans kept; not reset, so that answers given before a Reset never seem to share
  // a later window's scans.
  long long scans_kept_ = 0;
  double search_s_ = 0.0;
};

}  // namespace keyplace
