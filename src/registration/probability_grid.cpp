#include "probability_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

#include "common/ray_cells.hpp"

namespace keyplace {
namespace {

// Cartographer's inserter probabilities (hit 0.55, miss 0.49), as log-odds.
const double kHitLogOdds = std::log(0.55 / 0.45);
const double kMissLogOdds = std::log(0.49 / 0.51);
constexpr double kOccupiedSpaceWeight = 1.0;
constexpr double kTranslationWeightPerM = 10.0;
constexpr double kRotationWeightPerRad = 40.0;
constexpr int kMaxIterations = 20;

// The grid's correspondence costs as Ceres's interpolator reads them: outside the grid the cost of
// a cell no ray reached (Ceres's Grid2D would repeat the edge cell, often a miss, and give a point
// beyond it a false gradient along the edge).
class PaddedCosts {
 public:
  enum { DATA_DIMENSION = 1 };

  explicit PaddedCosts(const ProbabilityGrid& grid)
      : costs_(grid.correspondence_costs()), width_(grid.width()) {}

  void GetValue(int row, int column, double* value) const {
    if (row < 0 || column < 0 || row >= width_ || column >= width_) {
      *value = 1.0 - ProbabilityGrid::kMinProbability;
      return;
    }
    *value = costs_[static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) +
                    static_cast<std::size_t>(column)];
  }

 private:
  const std::vector<float>& costs_;
  int width_;
};

using CostInterpolator = ceres::BiCubicInterpolator<PaddedCosts>;

// Every point's correspondence cost at the candidate pose (x, y, θ), with the analytic
// Jacobian: one rotation per evaluation instead of automatic differentiation per point.
class OccupiedSpaceCost : public ceres::SizedCostFunction<ceres::DYNAMIC, 3> {
 public:
  OccupiedSpaceCost(const CostInterpolator& interpolator,
                    const std::vector<Eigen::Vector2d>& points_laser,
                    const Eigen::Vector2d& grid_origin, double cell_m)
      : interpolator_(interpolator),
        points_(points_laser),
        grid_origin_(grid_origin),
        cell_m_(cell_m),
        weight_(kOccupiedSpaceWeight / std::sqrt(static_cast<double>(points_laser.size()))) {
    set_num_residuals(static_cast<int>(points_.size()));
  }

  double weight() const { return weight_; }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    const double c = std::cos(pose[2]);
    const double s = std::sin(pose[2]);
    double* jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    const double scale = weight_ / cell_m_;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector2d& p = points_[i];
      const double x = pose[0] + c * p.x() - s * p.y();
      const double y = pose[1] + s * p.x() + c * p.y();
      double cost = 0.0;
      double d_row = 0.0;
      double d_column = 0.0;
      interpolator_.Evaluate((y - grid_origin_.y()) / cell_m_, (x - grid_origin_.x()) / cell_m_,
                             &cost, &d_row, &d_column);
      residuals[i] = weight_ * cost;
      if (jacobian != nullptr) {
        const double dx_dtheta = -s * p.x() - c * p.y();
        const double dy_dtheta = c * p.x() - s * p.y();
        jacobian[3 * i + 0] = scale * d_column;
        jacobian[3 * i + 1] = scale * d_row;
        jacobian[3 * i + 2] = scale * (d_column * dx_dtheta + d_row * dy_dtheta);
      }
    }
    return true;
  }

 private:
  const CostInterpolator& interpolator_;
  const std::vector<Eigen::Vector2d>& points_;
  Eigen::Vector2d grid_origin_;
  double cell_m_;
  double weight_;
};

// Keeps the solution near the initial pose where the grid cannot tell poses apart.
class InitialPoseResidual {
 public:
  explicit InitialPoseResidual(const Pose2& initial) : initial_(initial) {}

  template <typename T>
  bool operator()(const T* const pose, T* residual) const {
    residual[0] = kTranslationWeightPerM * (pose[0] - initial_.x);
    residual[1] = kTranslationWeightPerM * (pose[1] - initial_.y);
    residual[2] = kRotationWeightPerRad * (pose[2] - initial_.theta);
    return true;
  }

 private:
  Pose2 initial_;
};

}  // namespace

ProbabilityGrid::ProbabilityGrid(double cell_m, int width_cells)
    : cell_m_(cell_m), width_(width_cells) {
  if (!(std::isfinite(cell_m) && cell_m > 0.0)) {
    throw std::invalid_argument("ProbabilityGrid: cell_m must be finite and > 0");
  }
  if (width_cells < 8 || width_cells > 8192) {
    throw std::invalid_argument("ProbabilityGrid: width_cells must be in [8, 8192]");
  }
  const std::size_t cells = static_cast<std::size_t>(width_) * static_cast<std::size_t>(width_);
  hits_.assign(cells, 0);
  misses_.assign(cells, 0);
  costs_.assign(cells, static_cast<float>(1.0 - kMinProbability));
  last_scan_.assign(cells, 0);
  cost_of_counts_.resize(static_cast<std::size_t>(kCountTableSize) * kCountTableSize);
  for (int hits = 0; hits < kCountTableSize; ++hits) {
    for (int misses = 0; misses < kCountTableSize; ++misses) {
      cost_of_counts_[hits * kCountTableSize + misses] = CostOfCounts(hits, misses);
    }
  }
}

void ProbabilityGrid::Push(GridScan scan) {
  if (scans_.size() >= kMaxScans) {
    throw std::length_error("ProbabilityGrid: more than 32767 scans held (a cell counts each)");
  }
  Inserted inserted;
  inserted.scan = std::move(scan);
  const Eigen::Vector2d origin = inserted.scan.origin_world;
  const double recentre_m = 0.25 * width_ * cell_m_;
  if (!origin.allFinite()) return;
  if (scans_.empty() || (origin - Centre()).lpNorm<Eigen::Infinity>() > recentre_m) {
    scans_.push_back(std::move(inserted));
    CentreOn(origin);
    return;
  }
  Insert(inserted);
  scans_.push_back(std::move(inserted));
}

void ProbabilityGrid::Pop() {
  if (scans_.empty()) return;
  const Inserted& oldest = scans_.front();
  Count(oldest.hit_cells, hits_, -1);
  Count(oldest.miss_cells, misses_, -1);
  scans_.pop_front();
}

Eigen::Vector2d ProbabilityGrid::Centre() const {
  return origin_ + Eigen::Vector2d::Constant(0.5 * (width_ - 1) * cell_m_);
}

void ProbabilityGrid::CentreOn(const Eigen::Vector2d& position_world) {
  origin_ = position_world - Eigen::Vector2d::Constant(0.5 * (width_ - 1) * cell_m_);
  std::fill(hits_.begin(), hits_.end(), 0);
  std::fill(misses_.begin(), misses_.end(), 0);
  std::fill(costs_.begin(), costs_.end(), static_cast<float>(1.0 - kMinProbability));
  for (Inserted& inserted : scans_) Insert(inserted);
}

std::int32_t ProbabilityGrid::IndexOf(const Eigen::Vector2d& point_world) const {
  // Shifted by half a cell, as the ray traversal: the cell is the integer part.
  const Eigen::Vector2d shifted =
      (point_world - origin_) / cell_m_ + Eigen::Vector2d::Constant(0.5);
  if (!(shifted.x() >= 0.0 && shifted.y() >= 0.0 && shifted.x() < width_ && shifted.y() < width_)) {
    return -1;
  }
  const int column = static_cast<int>(std::floor(shifted.x()));
  const int row = static_cast<int>(std::floor(shifted.y()));
  return row * width_ + column;
}

void ProbabilityGrid::Insert(Inserted& inserted) {
  const std::uint32_t scan = ++scan_counter_;
  inserted.hit_cells.clear();
  inserted.miss_cells.clear();
  // Hits first, so that a ray through a cell another beam of this scan ended in does not clear
  // it.
  for (const Eigen::Vector2d& p : inserted.scan.points_world) {
    const std::int32_t index = IndexOf(p);
    if (index < 0 || last_scan_[index] == scan) continue;
    last_scan_[index] = scan;
    inserted.hit_cells.push_back(index);
  }
  // Every cell a ray crosses before its end cell, in order (Amanatides and Woo 1987), in cell
  // coordinates shifted by half a cell so that a cell is the integer part of a position.
  const Eigen::Vector2d from =
      (inserted.scan.origin_world - origin_) / cell_m_ + Eigen::Vector2d::Constant(0.5);
  for (const Eigen::Vector2d& p : inserted.scan.points_world) {
    const Eigen::Vector2d to = (p - origin_) / cell_m_ + Eigen::Vector2d::Constant(0.5);
    ForEachCellBeforeEnd(from, to, [&](int column, int row) {
      if (column >= 0 && row >= 0 && column < width_ && row < width_) {
        const std::int32_t index = row * width_ + column;
        if (last_scan_[index] != scan) {
          last_scan_[index] = scan;
          inserted.miss_cells.push_back(index);
        }
      }
      return true;
    });
  }
  Count(inserted.hit_cells, hits_, 1);
  Count(inserted.miss_cells, misses_, 1);
}

void ProbabilityGrid::Count(const std::vector<std::int32_t>& cells,
                            std::vector<std::int16_t>& counts, int sign) {
  for (const std::int32_t index : cells) {
    counts[index] = static_cast<std::int16_t>(counts[index] + sign);
    UpdateCost(index);
  }
}

float ProbabilityGrid::CostOfCounts(int hits, int misses) {
  double probability = kMinProbability;
  if (hits != 0 || misses != 0) {
    const double log_odds = hits * kHitLogOdds + misses * kMissLogOdds;
    probability = std::clamp(1.0 / (1.0 + std::exp(-log_odds)), kMinProbability, kMaxProbability);
  }
  return static_cast<float>(1.0 - probability);
}

void ProbabilityGrid::UpdateCost(std::int32_t index) {
  const int hits = hits_[index];
  const int misses = misses_[index];
  costs_[index] = hits < kCountTableSize && misses < kCountTableSize
                      ? cost_of_counts_[hits * kCountTableSize + misses]
                      : CostOfCounts(hits, misses);
}

double ProbabilityGrid::Probability(int column, int row) const {
  if (column < 0 || row < 0 || column >= width_ || row >= width_) return kMinProbability;
  return 1.0 - costs_[static_cast<std::size_t>(row) * width_ + column];
}

double MeanGridCost(const ProbabilityGrid& grid, const std::vector<Eigen::Vector2d>& points_laser,
                    const Pose2& T_world_laser) {
  if (points_laser.empty()) return 1.0 - ProbabilityGrid::kMinProbability;
  const PaddedCosts costs(grid);
  const CostInterpolator interpolator(costs);
  const OccupiedSpaceCost cost(interpolator, points_laser, grid.origin(), grid.cell_m());
  std::vector<double> residuals(points_laser.size());
  const double pose[3] = {T_world_laser.x, T_world_laser.y, T_world_laser.theta};
  const double* parameters[1] = {pose};
  cost.Evaluate(parameters, residuals.data(), nullptr);
  double sum = 0.0;
  for (const double r : residuals) sum += r;
  return sum / (cost.weight() * static_cast<double>(points_laser.size()));
}

GridMatch MatchOnGrid(const ProbabilityGrid& grid, const std::vector<Eigen::Vector2d>& points_laser,
                      const Pose2& initial_T_world_laser) {
  GridMatch match;
  match.T_world_laser = initial_T_world_laser;
  if (points_laser.empty()) return match;
  const PaddedCosts costs(grid);
  const CostInterpolator interpolator(costs);
  double pose[3] = {initial_T_world_laser.x, initial_T_world_laser.y, initial_T_world_laser.theta};
  ceres::Problem problem;
  problem.AddResidualBlock(
      new OccupiedSpaceCost(interpolator, points_laser, grid.origin(), grid.cell_m()), nullptr,
      pose);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<InitialPoseResidual, 3, 3>(
                               new InitialPoseResidual(initial_T_world_laser)),
                           nullptr, pose);
  ceres::Solver::Options options;
  options.max_num_iterations = kMaxIterations;
  options.function_tolerance = 1e-4;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  match.converged = summary.IsSolutionUsable() && std::isfinite(pose[0]) &&
                    std::isfinite(pose[1]) && std::isfinite(pose[2]);
  if (match.converged) match.T_world_laser = Pose2(pose[0], pose[1], pose[2]);
  return match;
}

}  // namespace keyplace
