#pragma once
// Dense verification of a place match: keypoints propose a pose, the whole scans decide. The
// query's recent beams, put into the candidate's frame by the proposed pose, must end on what the
// map's own beams hit there (hit fraction) and must not pass through it (see-through fraction).
// Both are fractions of beams, so they mean the same in a corridor with 40 keypoints per submap
// and in an open hall with 8: a weak keypoint match that the walls confirm becomes an answer, a
// strong one that puts the robot inside a wall does not (docs/PLACE.md, "Dense check").
//
// The reference is the binary occupancy the map already stores per submap (Submap::occupancy:
// the cells a beam of its scans ended in), of the candidate and its verification neighbours.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace {

/// One query scan for the dense check: the laser's position and (a subset of) its beam endpoints,
/// in the query frame.
struct QueryScanPoints {
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> endpoints_m;
};

// Scans and beams per scan a query carries for the dense check: the robot's last few metres in a
// hall (scans ~1 m apart), a fraction of a second in a corridor; 90 beams of a 361-beam scan is
// one per 2 degrees, enough to outline walls at 10 m.
constexpr std::size_t kDenseQueryScans = 10;
constexpr std::size_t kDenseBeamsPerScan = 90;

/// Every k-th valid beam of `scan`, k chosen so that at most kDenseBeamsPerScan remain, in the
/// robot frame (the laser's mounting applied).
QueryScanPoints DenseScanPoints(const LaserScan& scan);

/// `points` (robot frame) seen from T_query_robot: in the query frame.
QueryScanPoints InQueryFrame(const QueryScanPoints& points, const Pose2& T_query_robot);

/// Appends occupied `cells` (indices of `cell_m` in a frame `from`) to `out` as the cells of
/// `out_cell_m` in a frame `to` holding their centres (T_to_from: `from` seen from `to`).
void AppendCellsInFrame(const std::vector<Eigen::Vector2i>& cells, double cell_m,
                        const Pose2& T_to_from, double out_cell_m,
                        std::vector<Eigen::Vector2i>& out);

struct DenseScore {
  // Query endpoints inside the reference's area (its occupied cells' bounding box): the others
  // fall where the reference never looked and say nothing.
  int endpoints = 0;
  // Of those, the fraction within kDenseHitDistanceM of an occupied reference cell.
  double hit_fraction = 0.0;
  // Beams whose path crosses the reference's area before their endpoint, and the fraction of them
  // that crosses an occupied reference cell more than kDenseSeeThroughMarginM short of it.
  int rays = 0;
  double see_through_fraction = 0.0;
  // Set by the Score that takes a DenseVeto when the veto is certain; the score stopped there, so
  // its fractions are those of what it had looked at.
  bool vetoed = false;
};

/// When the beams veto a pose: at least `min_endpoints` endpoints inside the reference's area and
/// fewer than `min_hit_fraction` of them hitting it, or more than `max_see_through` of the rays
/// crossing it seeing through (PlaceRecognitionConfig::dense_*).
struct DenseVeto {
  int min_endpoints = 0;
  double min_hit_fraction = 0.0;
  double max_see_through = 1.0;
};

// An endpoint within this of an occupied cell (of 0.1 m) hits it: two cells, the mapping grid's
// quantization plus a RANSAC pose error of about a cell.
constexpr double kDenseHitDistanceM = 0.2;
// A beam crossing a wall (an occupied cell, then clear of walls kDenseWallCrossingM further on)
// this far short of its own endpoint saw through it.
constexpr double kDenseSeeThroughMarginM = 0.4;
constexpr double kDenseWallCrossingM = 0.35;

/// The occupied cells of a reference (cell indices of `cell_size_m`, in the reference frame)
/// rasterized once with their hit neighbourhood, scored against any number of poses.
class DenseReference {
 public:
  /// Throws std::invalid_argument for a cell size that is not positive and finite.
  DenseReference(const std::vector<Eigen::Vector2i>& cells, double cell_size_m);

  /// The query scans put into the reference frame by T_ref_query.
  DenseScore Score(const Pose2& T_ref_query, const std::vector<QueryScanPoints>& scans) const;

  /// The same, stopping as soon as `veto` is certain (DenseScore::vetoed): the endpoints are
  /// scored before any beam is traced, and tracing ends once more beams saw through than the
  /// veto allows of all of them. A pose not vetoed gets Score's result exactly; most candidates
  /// of a query are vetoed, mostly by their endpoints, and tracing is most of the cost.
  DenseScore Score(const Pose2& T_ref_query, const std::vector<QueryScanPoints>& scans,
                   const DenseVeto& veto) const;

  /// Score's endpoints and hit_fraction alone (no beam is traced), from every `stride`-th
  /// endpoint: cheap enough to compare thousands of poses.
  DenseScore Hits(const Pose2& T_ref_query, const std::vector<QueryScanPoints>& scans,
                  std::size_t stride = 1) const;

  /// Hits, or nothing as soon as the endpoints not yet probed could no longer bring the hit
  /// fraction to `min_hit_fraction` even if each of them hit: a search over thousands of poses
  /// wants only those that reach a bar, and most fall short of it within a third of their
  /// endpoints. A pose that reaches it gets Hits' result exactly.
  std::optional<DenseScore> HitsReaching(const Pose2& T_ref_query,
                                         const std::vector<QueryScanPoints>& scans,
                                         std::size_t stride, double min_hit_fraction) const;

  bool empty() const { return flags_.empty(); }

 private:
  // Bit 0: occupied; bit 1: within kDenseHitDistanceM of an occupied cell.
  std::uint8_t FlagsAt(const Eigen::Vector2d& point_m) const;
  // Whether the point's cell lies in the box of the occupied cells and, only then, its flags
  // (FlagsAt; 0 outside the box, where FlagsAt may still see the margin): one cell computation
  // for both (the beams' samples ask both, millions of times per query), kept for the block
  // lookup of EmptyBlockExit.
  struct Probe {
    bool inside = false;
    std::uint8_t flags = 0;
    int raster_i = -1;  // the point's raster cell (-1: none)
    int raster_j = -1;
  };
  Probe ProbeAt(const Eigen::Vector2d& point_m) const;
  bool SeesThrough(const Eigen::Vector2d& origin_m, const Eigen::Vector2d& endpoint_m,
                   bool& crossed) const;
  // Where the beam from origin_m along direction (unit) leaves the block of kBlockCells² raster
  // cells holding `point_m` (at parameter s_m; `probe` its ProbeAt), when that block holds no
  // occupied cell: every sample before the returned parameter lies in the block, so none can be
  // occupied. s_m itself when the block is occupied or the point lies within kBlockMarginM of
  // its border.
  double EmptyBlockExit(const Eigen::Vector2d& origin_m, const Eigen::Vector2d& direction,
                        const Eigen::Vector2d& point_m, const Probe& probe, double s_m) const;

  double cell_size_m_ = 0.1;
  Eigen::Vector2i min_cell_ = Eigen::Vector2i::Zero();  // of the occupied cells
  Eigen::Vector2i max_cell_ = Eigen::Vector2i::Zero();
  int width_ = 0;  // of the raster: the box grown by the hit radius
  int height_ = 0;
  int margin_ = 0;  // raster cells around the occupied box
  std::vector<std::uint8_t> flags_;
  // Blocks of kBlockCells x kBlockCells raster cells holding an occupied cell: a beam crosses the
  // empty ones (most of a room's free space) without a sample per half cell.
  static constexpr int kBlockCells = 8;
  int blocks_wide_ = 0;
  std::vector<char> block_occupied_;
};

}  // namespace keyplace
