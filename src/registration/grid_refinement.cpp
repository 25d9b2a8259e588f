#include "grid_refinement.hpp"

#include <cmath>
#include <memory>

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

namespace keyplace {
namespace {

// The field as Ceres' interpolators read it: value of cell (row, column), 0 outside.
struct FieldGrid {
  enum { DATA_DIMENSION = 1 };
  explicit FieldGrid(const ProximityField& proximity) : field(proximity) {}
  void GetValue(int row, int column, double* value) const { *value = field.AtCell(column, row); }
  const ProximityField& field;
};

// One residual per point: scale * (1 - field at the transformed point).
class OccupiedSpaceCost {
 public:
  OccupiedSpaceCost(const ProximityField& field, const std::vector<Eigen::Vector2d>& points,
                    double scale)
      : field_(field), grid_(field), interpolator_(grid_), points_(points), scale_(scale) {}

  template <typename T>
  bool operator()(const T* const pose, T* residuals) const {
    const T c = ceres::cos(pose[2]);
    const T s = ceres::sin(pose[2]);
    const double inverse_cell = 1.0 / field_.cell_m();
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector2d& p = points_[i];
      const T x = c * p.x() - s * p.y() + pose[0];
      const T y = s * p.x() + c * p.y() + pose[1];
      // Cell centres are at half cells: cell k's value belongs to coordinate k + 0.5.
      const T column = (x - field_.origin().x()) * inverse_cell - 0.5;
      const T row = (y - field_.origin().y()) * inverse_cell - 0.5;
      T value;
      interpolator_.Evaluate(row, column, &value);
      residuals[i] = scale_ * (1.0 - value);
    }
    return true;
  }

 private:
  const ProximityField& field_;
  FieldGrid grid_;
  ceres::BiCubicInterpolator<FieldGrid> interpolator_;
  const std::vector<Eigen::Vector2d>& points_;
  double scale_;
};

class PriorCost {
 public:
  PriorCost(const Pose2& start, const GridRefinementWeights& weights)
      : start_(start), weights_(weights) {}
  template <typename T>
  bool operator()(const T* const pose, T* residuals) const {
    residuals[0] = weights_.translation_per_m * (pose[0] - start_.x);
    residuals[1] = weights_.translation_per_m * (pose[1] - start_.y);
    residuals[2] = weights_.rotation_per_rad * (pose[2] - start_.theta);
    return true;
  }

 private:
  Pose2 start_;
  GridRefinementWeights weights_;
};

double MeanField(const ProximityField& field, const std::vector<Eigen::Vector2d>& source,
                 const Pose2& pose) {
  if (source.empty()) return 0.0;
  double sum = 0.0;
  for (const Eigen::Vector2d& p : source) sum += field.At(pose * p);
  return sum / static_cast<double>(source.size());
}

}  // namespace

GridRefinement RefineOnField(const ProximityField& field,
                             const std::vector<Eigen::Vector2d>& source, const Pose2& start,
                             const GridRefinementWeights& weights) {
  GridRefinement result;
  result.T_target_source = start;
  result.start_field = MeanField(field, source, start);
  result.mean_field = result.start_field;
  if (source.empty()) return result;
  double pose[3] = {start.x, start.y, start.theta};
  ceres::Problem problem;
  const double scale = weights.occupied / std::sqrt(static_cast<double>(source.size()));
  auto* occupied = new ceres::AutoDiffCostFunction<OccupiedSpaceCost, ceres::DYNAMIC, 3>(
      new OccupiedSpaceCost(field, source, scale), static_cast<int>(source.size()));
  problem.AddResidualBlock(occupied, nullptr, pose);
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<PriorCost, 3, 3>(new PriorCost(start, weights)), nullptr,
      pose);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.usable = summary.IsSolutionUsable();
  if (result.usable) {
    result.T_target_source = Pose2(pose[0], pose[1], WrapAngle(pose[2]));
    result.mean_field = MeanField(field, source, result.T_target_source);
  }
  return result;
}

}  // namespace keyplace
