#include "keyplace/place/dense_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>

namespace keyplace {
namespace {

constexpr std::uint8_t kOccupied = 1;
constexpr std::uint8_t kNearOccupied = 2;
// A raster larger than this (a reference of several submaps spanning more than 400 m at 0.1 m)
// is not built: the check then does not apply (DenseReference::empty).
constexpr std::int64_t kMaxRasterCells = std::int64_t{1} << 24;

}  // namespace

QueryScanPoints DenseScanPoints(const LaserScan& scan) {
  QueryScanPoints points;
  points.origin_m = scan.T_robot_laser.translation();
  const std::size_t valid = scan.CountValid();
  if (valid == 0) return points;
  const std::size_t stride = (valid + kDenseBeamsPerScan - 1) / kDenseBeamsPerScan;
  std::size_t seen = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.valid[i]) continue;
    if (seen++ % stride == 0) points.endpoints_m.push_back(scan.T_robot_laser * scan.Endpoint(i));
  }
  return points;
}

QueryScanPoints InQueryFrame(const QueryScanPoints& points, const Pose2& T_query_robot) {
  const PointMapper to_query(T_query_robot);
  QueryScanPoints out;
  out.origin_m = to_query(points.origin_m);
  out.endpoints_m.reserve(points.endpoints_m.size());
  for (const Eigen::Vector2d& endpoint : points.endpoints_m) {
    out.endpoints_m.push_back(to_query(endpoint));
  }
  return out;
}

void AppendCellsInFrame(const std::vector<Eigen::Vector2i>& cells, double cell_m,
                        const Pose2& T_to_from, double out_cell_m,
                        std::vector<Eigen::Vector2i>& out) {
  const PointMapper to(T_to_from);
  out.reserve(out.size() + cells.size());
  for (const Eigen::Vector2i& cell : cells) {
    const Eigen::Vector2d point = to((cell.cast<double>().array() + 0.5).matrix() * cell_m);
    out.emplace_back(static_cast<int>(std::floor(point.x() / out_cell_m)),
                     static_cast<int>(std::floor(point.y() / out_cell_m)));
  }
}

DenseReference::DenseReference(const std::vector<Eigen::Vector2i>& cells, double cell_size_m)
    : cell_size_m_(cell_size_m) {
  if (!(cell_size_m > 0.0) || !std::isfinite(cell_size_m)) {
    throw std::invalid_argument("DenseReference: the cell size must be positive and finite");
  }
  if (cells.empty()) return;
  min_cell_ = cells.front();
  max_cell_ = cells.front();
  for (const Eigen::Vector2i& cell : cells) {
    min_cell_ = min_cell_.cwiseMin(cell);
    max_cell_ = max_cell_.cwiseMax(cell);
  }
  const int radius = static_cast<int>(std::ceil(kDenseHitDistanceM / cell_size_m_));
  margin_ = radius;
  const std::int64_t width =
      std::int64_t{max_cell_.x()} - min_cell_.x() + 1 + std::int64_t{2} * margin_;
  const std::int64_t height =
      std::int64_t{max_cell_.y()} - min_cell_.y() + 1 + std::int64_t{2} * margin_;
  if (width * height > kMaxRasterCells) return;
  width_ = static_cast<int>(width);
  height_ = static_cast<int>(height);
  flags_.assign(static_cast<std::size_t>(width * height), 0);
  const int radius2 = radius * radius;
  for (const Eigen::Vector2i& cell : cells) {
    const int ci = cell.x() - min_cell_.x() + margin_;
    const int cj = cell.y() - min_cell_.y() + margin_;
    for (int di = -radius; di <= radius; ++di) {
      for (int dj = -radius; dj <= radius; ++dj) {
        if (di * di + dj * dj > radius2) continue;
        flags_[static_cast<std::size_t>(cj + dj) * static_cast<std::size_t>(width_) +
               static_cast<std::size_t>(ci + di)] |= kNearOccupied;
      }
    }
    flags_[static_cast<std::size_t>(cj) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(ci)] |= kOccupied;
  }
  blocks_wide_ = (width_ + kBlockCells - 1) / kBlockCells;
  const int blocks_high = (height_ + kBlockCells - 1) / kBlockCells;
  block_occupied_.assign(static_cast<std::size_t>(blocks_wide_) * blocks_high, 0);
  for (const Eigen::Vector2i& cell : cells) {
    const int bi = (cell.x() - min_cell_.x() + margin_) / kBlockCells;
    const int bj = (cell.y() - min_cell_.y() + margin_) / kBlockCells;
    block_occupied_[static_cast<std::size_t>(bj) * blocks_wide_ + bi] = 1;
  }
}

double DenseReference::EmptyBlockExit(const Eigen::Vector2d& origin_m,
                                      const Eigen::Vector2d& direction,
                                      const Eigen::Vector2d& point_m, const Probe& probe,
                                      double s_m) const {
  // Far beyond the rounding of any sample's position (about 1e-13 m within a few km), so that a
  // sample the exact geometry puts inside the block shrunk by this margin is computed inside it.
  constexpr double kBlockMarginM = 1e-6;
  if (probe.raster_i < 0) return s_m;
  const int bi = probe.raster_i / kBlockCells;
  const int bj = probe.raster_j / kBlockCells;
  if (block_occupied_[static_cast<std::size_t>(bj) * blocks_wide_ + bi]) return s_m;
  const Eigen::Vector2d block_min = (Eigen::Vector2d(bi * kBlockCells, bj * kBlockCells) -
                                     Eigen::Vector2d(margin_, margin_) + min_cell_.cast<double>()) *
                                        cell_size_m_ +
                                    Eigen::Vector2d::Constant(kBlockMarginM);
  const Eigen::Vector2d block_max =
      block_min + Eigen::Vector2d::Constant(kBlockCells * cell_size_m_ - 2.0 * kBlockMarginM);
  double exit = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 2; ++axis) {
    if (!(point_m[axis] > block_min[axis] && point_m[axis] < block_max[axis])) return s_m;
    if (direction[axis] > 0.0) {
      exit = std::min(exit, (block_max[axis] - origin_m[axis]) / direction[axis]);
    } else if (direction[axis] < 0.0) {
      exit = std::min(exit, (block_min[axis] - origin_m[axis]) / direction[axis]);
    }
  }
  return exit;
}

std::uint8_t DenseReference::FlagsAt(const Eigen::Vector2d& point_m) const {
  const double i = std::floor(point_m.x() / cell_size_m_) - min_cell_.x() + margin_;
  const double j = std::floor(point_m.y() / cell_size_m_) - min_cell_.y() + margin_;
  if (!(i >= 0.0 && j >= 0.0 && i < width_ && j < height_)) return 0;
  return flags_[static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) +
                static_cast<std::size_t>(i)];
}

DenseReference::Probe DenseReference::ProbeAt(const Eigen::Vector2d& point_m) const {
  const double cell_i = std::floor(point_m.x() / cell_size_m_);
  const double cell_j = std::floor(point_m.y() / cell_size_m_);
  Probe probe;
  probe.inside = cell_i >= min_cell_.x() && cell_i <= max_cell_.x() && cell_j >= min_cell_.y() &&
                 cell_j <= max_cell_.y();
  if (!probe.inside) return probe;  // no caller reads the flags outside the box
  const double i = cell_i - min_cell_.x() + margin_;
  const double j = cell_j - min_cell_.y() + margin_;
  if (i >= 0.0 && j >= 0.0 && i < width_ && j < height_) {
    probe.raster_i = static_cast<int>(i);
    probe.raster_j = static_cast<int>(j);
    probe.flags =
        flags_[static_cast<std::size_t>(probe.raster_j) * static_cast<std::size_t>(width_) +
               static_cast<std::size_t>(probe.raster_i)];
  }
  return probe;
}

// Samples the beam every half cell up to kDenseSeeThroughMarginM short of its endpoint. A beam
// sees through when it enters an occupied cell and, kDenseWallCrossingM further on, is clear of
// every occupied cell: it crossed a wall. A beam grazing a wall (within about 35 degrees of it)
// stays near it over that stretch and is not counted: at 0.1 m cells the map cannot tell on
// which side of a wall such a beam runs.
bool DenseReference::SeesThrough(const Eigen::Vector2d& origin_m, const Eigen::Vector2d& endpoint_m,
                                 bool& crossed) const {
  crossed = false;
  const Eigen::Vector2d beam = endpoint_m - origin_m;
  const double length = beam.norm();
  const double free_length = length - kDenseSeeThroughMarginM;
  if (!(free_length > 0.0)) return false;
  const Eigen::Vector2d direction = beam / length;
  // Only the stretch inside the occupied box can cross anything (slab clipping): the samples are
  // bounded by the box, not by the beam's length.
  double enter = 0.0;
  double leave = free_length;
  const Eigen::Vector2d box_min = min_cell_.cast<double>() * cell_size_m_;
  const Eigen::Vector2d box_max = (max_cell_.cast<double>().array() + 1.0).matrix() * cell_size_m_;
  for (int axis = 0; axis < 2; ++axis) {
    if (direction[axis] == 0.0) {
      if (origin_m[axis] < box_min[axis] || origin_m[axis] > box_max[axis]) return false;
      continue;
    }
    const double a = (box_min[axis] - origin_m[axis]) / direction[axis];
    const double b = (box_max[axis] - origin_m[axis]) / direction[axis];
    enter = std::max(enter, std::min(a, b));
    leave = std::min(leave, std::max(a, b));
  }
  if (!(enter <= leave)) return false;
  const double step = 0.5 * cell_size_m_;
  const auto first = static_cast<std::int64_t>(std::floor(enter / step));
  const auto last = static_cast<std::int64_t>(std::ceil(leave / step));
  for (std::int64_t k = first; k <= last; ++k) {
    const double s = static_cast<double>(k) * step;
    if (s < 0.0 || s >= free_length) continue;
    const Eigen::Vector2d sample = origin_m + s * direction;
    const Probe probe = ProbeAt(sample);
    if (!probe.inside) continue;
    crossed = true;
    if (!(probe.flags & kOccupied)) {
      // The samples before the empty block's exit are neither occupied nor needed for `crossed`.
      const double exit = EmptyBlockExit(origin_m, direction, sample, probe, s);
      if (exit > s) k = std::max(k, static_cast<std::int64_t>(std::ceil(exit / step)) - 1);
      continue;
    }
    const double beyond = s + kDenseWallCrossingM;
    if (beyond < free_length && !(FlagsAt(origin_m + beyond * direction) & kNearOccupied)) {
      return true;
    }
  }
  return false;
}

DenseScore DenseReference::Score(const Pose2& T_ref_query,
                                 const std::vector<QueryScanPoints>& scans) const {
  DenseVeto never;
  never.min_endpoints = std::numeric_limits<int>::max();
  return Score(T_ref_query, scans, never);
}

DenseScore DenseReference::Score(const Pose2& T_ref_query,
                                 const std::vector<QueryScanPoints>& scans,
                                 const DenseVeto& veto) const {
  DenseScore score;
  if (empty()) return score;
  std::size_t beams = 0;
  for (const QueryScanPoints& scan : scans) beams += scan.endpoints_m.size();
  std::vector<Eigen::Vector2d> endpoints;
  endpoints.reserve(beams);
  int hits = 0;
  for (const QueryScanPoints& scan : scans) {
    for (const Eigen::Vector2d& endpoint_query : scan.endpoints_m) {
      endpoints.push_back(T_ref_query * endpoint_query);
      const Probe probe = ProbeAt(endpoints.back());
      if (probe.inside) {
        ++score.endpoints;
        if (probe.flags & kNearOccupied) ++hits;
      }
    }
  }
  if (score.endpoints > 0) score.hit_fraction = static_cast<double>(hits) / score.endpoints;
  const bool applies = score.endpoints >= veto.min_endpoints;
  if (applies && score.hit_fraction < veto.min_hit_fraction) {
    score.vetoed = true;
    return score;
  }
  // seen_through / rays >= seen_through / beams (each ray is a beam), and rounding keeps that
  // order: once seen_through / beams exceeds the veto, the final fraction does too.
  const auto beam_count = static_cast<double>(beams);
  int seen_through = 0;
  std::size_t k = 0;
  for (const QueryScanPoints& scan : scans) {
    const Eigen::Vector2d origin = T_ref_query * scan.origin_m;
    for (std::size_t b = 0; b < scan.endpoints_m.size(); ++b, ++k) {
      bool crossed = false;
      if (SeesThrough(origin, endpoints[k], crossed)) ++seen_through;
      if (crossed) ++score.rays;
      if (applies && static_cast<double>(seen_through) / beam_count > veto.max_see_through) {
        score.vetoed = true;
        return score;
      }
    }
  }
  if (score.rays > 0) score.see_through_fraction = static_cast<double>(seen_through) / score.rays;
  score.vetoed = applies && score.see_through_fraction > veto.max_see_through;
  return score;
}

DenseScore DenseReference::Hits(const Pose2& T_ref_query, const std::vector<QueryScanPoints>& scans,
                                std::size_t stride) const {
  // A fraction of at least 0 is always reached.
  return *HitsReaching(T_ref_query, scans, stride, 0.0);
}

std::optional<DenseScore> DenseReference::HitsReaching(const Pose2& T_ref_query,
                                                       const std::vector<QueryScanPoints>& scans,
                                                       std::size_t stride,
                                                       double min_hit_fraction) const {
  DenseScore score;
  if (empty()) return score;
  stride = std::max<std::size_t>(stride, 1);
  std::size_t left = 0;  // endpoints not yet probed
  for (const QueryScanPoints& scan : scans) left += (scan.endpoints_m.size() + stride - 1) / stride;
  const PointMapper to_ref(T_ref_query);
  int hits = 0;
  int misses = 0;
  for (const QueryScanPoints& scan : scans) {
    for (std::size_t k = 0; k < scan.endpoints_m.size(); k += stride) {
      --left;
      const Probe probe = ProbeAt(to_ref(scan.endpoints_m[k]));
      if (!probe.inside) continue;
      if (probe.flags & kNearOccupied) {
        ++hits;
        continue;
      }
      ++misses;
      // The best still possible: every endpoint left inside the area and on a wall. Divided as the
      // result is, so that a pose ending exactly at the bar is not given up by a rounding.
      const double most_hits = static_cast<double>(hits) + static_cast<double>(left);
      if (most_hits / (most_hits + misses) < min_hit_fraction) return std::nullopt;
    }
  }
  score.endpoints = hits + misses;
  if (score.endpoints > 0) score.hit_fraction = static_cast<double>(hits) / score.endpoints;
  return score;
}

}  // namespace keyplace
