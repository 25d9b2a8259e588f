#include "keyplace/registration/icp.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

namespace keyplace {
// Named, not anonymous: IcpTarget::Impl, a class with external linkage, holds these.
namespace icp_kdtree {

// nanoflann reads the caller's points through this adaptor (no copy).
struct PointsAdaptor {
  const std::vector<Eigen::Vector2d>* points;

  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::size_t index, std::size_t dim) const { return (*points)[index][dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bbox*/) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<
    nanoflann::L2_Simple_Adaptor<double, PointsAdaptor, double, std::size_t>, PointsAdaptor, 2,
    std::size_t>;

}  // namespace icp_kdtree

namespace {

using icp_kdtree::KdTree;
using icp_kdtree::PointsAdaptor;

constexpr int kMaxNormalNeighbours = 64;
// How many past iterates are checked for a cycle of the association.
constexpr int kCycleMemory = 10;

void RequireIcpField(bool condition, const char* field, const char* what) {
  if (!condition) {
    throw std::invalid_argument(std::string("IcpConfig.") + field + " " + what);
  }
}

double KernelWeight(RobustKernel kernel, double scale_m, double residual_m) {
  const double a = std::abs(residual_m);
  switch (kernel) {
    case RobustKernel::kNone:
      return 1.0;
    case RobustKernel::kHuber:
      return a <= scale_m ? 1.0 : scale_m / a;
    case RobustKernel::kCauchy: {
      const double u = residual_m / scale_m;
      return 1.0 / (1.0 + u * u);
    }
    case RobustKernel::kTukey: {
      if (a >= scale_m) return 0.0;
      const double u = residual_m / scale_m;
      const double v = 1.0 - u * u;
      return v * v;
    }
  }
  return 1.0;
}

}  // namespace

std::string ToString(IcpStatus status) {
  switch (status) {
    case IcpStatus::kConverged:
      return "converged";
    case IcpStatus::kMaxIterations:
      return "max_iterations";
    case IcpStatus::kTooFewPoints:
      return "too_few_points";
    case IcpStatus::kTooFewInliers:
      return "too_few_inliers";
    case IcpStatus::kSingular:
      return "singular";
  }
  return "unknown";
}

std::string ToString(RobustKernel kernel) {
  switch (kernel) {
    case RobustKernel::kNone:
      return "none";
    case RobustKernel::kHuber:
      return "huber";
    case RobustKernel::kCauchy:
      return "cauchy";
    case RobustKernel::kTukey:
      return "tukey";
  }
  return "unknown";
}

void ValidateIcpConfig(const IcpConfig& c) {
  RequireIcpField(c.max_correspondence_distance_m > 0.0, "max_correspondence_distance_m",
                  "must be > 0");
  RequireIcpField(c.inlier_distance_m > 0.0, "inlier_distance_m", "must be > 0");
  RequireIcpField(c.kernel_scale_m > 0.0, "kernel_scale_m", "must be > 0");
  RequireIcpField(c.normal_neighbours >= 2 && c.normal_neighbours <= kMaxNormalNeighbours,
                  "normal_neighbours", "must be in [2, 64]");
  RequireIcpField(c.normal_max_neighbour_distance_m > 0.0, "normal_max_neighbour_distance_m",
                  "must be > 0");
  RequireIcpField(c.normal_max_eigenvalue_ratio >= 0.0 && c.normal_max_eigenvalue_ratio <= 1.0,
                  "normal_max_eigenvalue_ratio", "must be in [0, 1]");
  RequireIcpField(c.max_iterations >= 1, "max_iterations", "must be >= 1");
  RequireIcpField(c.convergence_translation_m >= 0.0, "convergence_translation_m", "must be >= 0");
  RequireIcpField(c.convergence_rotation_rad >= 0.0, "convergence_rotation_rad", "must be >= 0");
  RequireIcpField(c.degeneracy_min_eigenvalue >= 0.0, "degeneracy_min_eigenvalue", "must be >= 0");
  RequireIcpField(c.min_points >= 3, "min_points", "must be >= 3");
  RequireIcpField(c.min_inliers >= 0, "min_inliers", "must be >= 0");
  RequireIcpField(c.min_inlier_ratio >= 0.0 && c.min_inlier_ratio <= 1.0, "min_inlier_ratio",
                  "must be in [0, 1]");
}

// ------------------------------------------------------------------------------------------
// IcpTarget

struct IcpTarget::Impl {
  const std::vector<Eigen::Vector2d>& points;
  PointsAdaptor adaptor;
  KdTree tree;
  PointNormals normals;

  explicit Impl(const std::vector<Eigen::Vector2d>& pts)
      : points(pts),
        adaptor{&pts},
        tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
};

namespace {

// The unit normal of the line fitted to point i's normal_neighbours nearest neighbours (those
// within normal_max_neighbour_distance_m, at least 3 with the point itself), when the fit is
// line-like (normal_max_eigenvalue_ratio); nullopt otherwise.
std::optional<Eigen::Vector2d> FitNormal(const std::vector<Eigen::Vector2d>& points,
                                         const KdTree& tree, std::size_t i,
                                         const IcpConfig& config) {
  const std::size_t k =
      std::min<std::size_t>(static_cast<std::size_t>(config.normal_neighbours), points.size());
  const double max_d2 =
      config.normal_max_neighbour_distance_m * config.normal_max_neighbour_distance_m;
  std::array<std::size_t, kMaxNormalNeighbours> indices{};
  std::array<double, kMaxNormalNeighbours> d2{};
  nanoflann::KNNResultSet<double, std::size_t, std::size_t> result(k);
  result.init(indices.data(), d2.data());
  tree.findNeighbors(result, points[i].data(), nanoflann::SearchParams());
  const std::size_t found = result.size();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  int count = 0;
  for (std::size_t j = 0; j < found; ++j) {
    if (d2[j] > max_d2) continue;
    mean += points[indices[j]];
    ++count;
  }
  if (count < 3) return std::nullopt;
  mean /= count;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (std::size_t j = 0; j < found; ++j) {
    if (d2[j] > max_d2) continue;
    const Eigen::Vector2d d = points[indices[j]] - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(cov);
  const double lmin = eig.eigenvalues()(0);
  const double lmax = eig.eigenvalues()(1);
  if (!(lmax > 0.0) || lmin > config.normal_max_eigenvalue_ratio * lmax) return std::nullopt;
  return eig.eigenvectors().col(0).normalized();
}

PointNormals NormalsFromTree(const std::vector<Eigen::Vector2d>& points, const KdTree& tree,
                             const IcpConfig& config) {
  const std::size_t n = points.size();
  PointNormals out;
  out.normals.assign(n, Eigen::Vector2d::Zero());
  out.valid.assign(n, 0);
  if (n < 3) return out;
  for (std::size_t i = 0; i < n; ++i) {
    if (const std::optional<Eigen::Vector2d> normal = FitNormal(points, tree, i, config)) {
      out.normals[i] = *normal;
      out.valid[i] = 1;
    }
  }
  return out;
}

}  // namespace

PointNormals EstimateNormals(const std::vector<Eigen::Vector2d>& points, const IcpConfig& config) {
  ValidateIcpConfig(config);
  const PointsAdaptor adaptor{&points};
  const KdTree tree(2, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  return NormalsFromTree(points, tree, config);
}

IcpTarget::IcpTarget(const std::vector<Eigen::Vector2d>& points, const IcpConfig& config) {
  ValidateIcpConfig(config);
  impl_ = std::make_unique<Impl>(points);
  impl_->normals = NormalsFromTree(points, impl_->tree, config);
}

IcpTarget::IcpTarget(const std::vector<Eigen::Vector2d>& points, PointNormals normals,
                     const IcpConfig& config) {
  ValidateIcpConfig(config);
  if (normals.normals.size() != points.size() || normals.valid.size() != points.size()) {
    throw std::invalid_argument(
        "IcpTarget: normals.normals and normals.valid must have one entry per point");
  }
  impl_ = std::make_unique<Impl>(points);
  impl_->normals = std::move(normals);
}

IcpTarget::~IcpTarget() = default;

std::size_t IcpTarget::size() const { return impl_->points.size(); }
const std::vector<Eigen::Vector2d>& IcpTarget::points() const { return impl_->points; }
const Eigen::Vector2d& IcpTarget::normal(std::size_t i) const { return impl_->normals.normals[i]; }
bool IcpTarget::HasNormal(std::size_t i) const { return impl_->normals.valid[i] != 0; }
std::size_t IcpTarget::FillMissingNormals(const IcpConfig& config) {
  ValidateIcpConfig(config);
  const std::vector<Eigen::Vector2d>& points = impl_->points;
  if (points.size() < 3) return 0;
  std::size_t filled = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (impl_->normals.valid[i] != 0) continue;
    if (const std::optional<Eigen::Vector2d> normal = FitNormal(points, impl_->tree, i, config)) {
      impl_->normals.normals[i] = *normal;
      impl_->normals.valid[i] = 1;
      ++filled;
    }
  }
  return filled;
}

std::size_t IcpTarget::CountNormals() const {
  return static_cast<std::size_t>(
      std::count(impl_->normals.valid.begin(), impl_->normals.valid.end(), std::uint8_t{1}));
}

bool IcpTarget::Nearest(const Eigen::Vector2d& query, std::size_t* index,
                        double* squared_distance_m2) const {
  if (impl_->points.empty()) return false;
  std::size_t found_index = 0;
  double found_d2 = 0.0;
  nanoflann::KNNResultSet<double, std::size_t, std::size_t> result(1);
  result.init(&found_index, &found_d2);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (result.size() == 0) return false;
  if (index != nullptr) *index = found_index;
  if (squared_distance_m2 != nullptr) *squared_distance_m2 = found_d2;
  return true;
}

namespace {

// Margins of NearestWithin's search bound over the distance it must not miss: far above the
// rounding of the tree's branch bounds (sums of a few squares of metres) and far below any
// spacing of laser points (1e-9 m^2: 0.03 mm).
constexpr double kBoundMarginRelative = 1e-9;
constexpr double kBoundMarginM2 = 1e-9;

// nanoflann's result set for one neighbour under a bound: the tree search skips every branch
// farther than the best so far, so a tight bound from the start prunes most of it.
class BoundedNearest {
 public:
  explicit BoundedNearest(double bound_d2) : best_d2_(bound_d2) {}
  bool addPoint(double d2, std::size_t index) {
    // Needed: the tree reads worstDist() once per leaf and passes every point of the leaf below
    // that. Strictly nearer only, so the first of equally near points found is kept, as with
    // nanoflann's own result set.
    if (d2 < best_d2_) {
      best_d2_ = d2;
      best_index_ = index;
      found_ = true;
    }
    return true;
  }
  double worstDist() const { return best_d2_; }
  bool full() const { return found_; }
  std::size_t best_index() const { return best_index_; }

 private:
  double best_d2_;
  std::size_t best_index_ = 0;
  bool found_ = false;
};

}  // namespace

bool IcpTarget::NearestWithin(const Eigen::Vector2d& query, double max_squared_distance_m2,
                              std::size_t hint, std::size_t* index,
                              double* squared_distance_m2) const {
  const std::vector<Eigen::Vector2d>& points = impl_->points;
  if (points.empty() || !(max_squared_distance_m2 >= 0.0)) return false;
  // The tree prunes a branch by a lower bound of its distance that it sums up with rounding, so
  // a bound as tight as the nearest point's distance could prune that point's branch: the bound
  // keeps a margin above the limit (or the hint's distance), far below the points' spacing,
  // and the limit is checked after. The branches it prunes hold no point as near as the
  // nearest, and the tree visits the rest in its usual order: the answer, among equally near
  // points too, is the unbounded search's (Nearest) when that lies within the limit.
  double bound_d2 = max_squared_distance_m2;
  if (hint < points.size()) {
    // The tree's own formula, so that the hint's distance is the one the tree compares.
    bound_d2 = std::min(bound_d2, impl_->tree.distance.evalMetric(query.data(), hint, 2));
  }
  BoundedNearest result(bound_d2 * (1.0 + kBoundMarginRelative) + kBoundMarginM2);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (!result.full() || result.worstDist() > max_squared_distance_m2) return false;
  if (index != nullptr) *index = result.best_index();
  if (squared_distance_m2 != nullptr) *squared_distance_m2 = result.worstDist();
  return true;
}

IcpInliers CountIcpInliers(const IcpTarget& target, const std::vector<Eigen::Vector2d>& source,
                           const Pose2& T_target_source, const IcpConfig& config) {
  const double gate_d2 =
      config.max_correspondence_distance_m * config.max_correspondence_distance_m;
  IcpInliers inliers;
  std::size_t index = IcpTarget::kNoHint;  // the previous point's neighbour, near the next one's
  const PointMapper to_target(T_target_source);
  for (const Eigen::Vector2d& p : source) {
    const Eigen::Vector2d pt = to_target(p);
    double d2 = 0.0;
    if (!target.NearestWithin(pt, gate_d2, index, &index, &d2) || !target.HasNormal(index)) {
      continue;
    }
    const double r = target.normal(index).dot(pt - target.points()[index]);
    if (std::abs(r) > config.inlier_distance_m) continue;
    ++inliers.count;
    inliers.sum_squared_residuals_m2 += r * r;
  }
  return inliers;
}

// ------------------------------------------------------------------------------------------
// Alignment

namespace {

// The Gauss-Newton step of the points' normal equations (H, g) with the prior added. The prior's
// information is positive definite, so the sum is too and every direction is updated.
Eigen::Vector3d PriorStep(const Eigen::Matrix3d& H, const Eigen::Vector3d& g,
                          const Eigen::Vector3d& pose, const IcpPosePrior& prior) {
  const Pose2& mean = prior.T_target_source_mean;
  const Eigen::Vector3d error(pose(0) - mean.x, pose(1) - mean.y, WrapAngle(pose(2) - mean.theta));
  const Eigen::Matrix3d H_total = H + prior.information;
  const Eigen::Vector3d g_total = g + prior.information * error;
  return -H_total.ldlt().solve(g_total);
}

}  // namespace

IcpResult AlignPointToLine(const IcpTarget& target, const std::vector<Eigen::Vector2d>& source,
                           const Pose2& T_target_source_guess, const IcpConfig& config,
                           const IcpPosePrior* prior) {
  ValidateIcpConfig(config);
  if (prior != nullptr && (!prior->information.allFinite() ||
                           !prior->information.isApprox(prior->information.transpose()) ||
                           prior->information.llt().info() != Eigen::Success)) {
    throw std::invalid_argument("IcpPosePrior.information must be symmetric positive definite");
  }
  IcpResult result;
  result.T_target_source = T_target_source_guess;
  result.num_source_points = static_cast<int>(source.size());
  const int min_points = config.min_points;
  if (static_cast<int>(source.size()) < min_points ||
      static_cast<int>(target.size()) < min_points || static_cast<int>(target.CountNormals()) < 3) {
    result.status = IcpStatus::kTooFewPoints;
    return result;
  }

  const double gate_d2 =
      config.max_correspondence_distance_m * config.max_correspondence_distance_m;
  double x = T_target_source_guess.x;
  double y = T_target_source_guess.y;
  double theta = T_target_source_guess.theta;
  bool numerically_converged = false;
  std::vector<Eigen::Vector3d> history;  // poses after each update (x, y, theta)
  history.reserve(static_cast<std::size_t>(config.max_iterations));
  bool singular = false;

  for (int iteration = 1; iteration <= config.max_iterations; ++iteration) {
    result.iterations = iteration;
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int count = 0;
    // The previous point's neighbour: the next one's is near it.
    std::size_t index = IcpTarget::kNoHint;
    for (const Eigen::Vector2d& p : source) {
      // Source point relative to the sensor origin, rotated into the target frame.
      const Eigen::Vector2d rp(c * p.x() - s * p.y(), s * p.x() + c * p.y());
      const Eigen::Vector2d pt(rp.x() + x, rp.y() + y);
      double d2 = 0.0;
      if (!target.NearestWithin(pt, gate_d2, index, &index, &d2) || !target.HasNormal(index)) {
        continue;
      }
      const Eigen::Vector2d& n = target.normal(index);
      const double r = n.dot(pt - target.points()[index]);
      // d r / d(dx, dy, dtheta), rotation about the current sensor origin.
      const Eigen::Vector3d J(n.x(), n.y(), n.y() * rp.x() - n.x() * rp.y());
      const double w = KernelWeight(config.kernel, config.kernel_scale_m, r);
      H.noalias() += w * J * J.transpose();
      g.noalias() += w * r * J;
      ++count;
    }
    if (count < 3) {
      singular = true;
      break;
    }
    // Solve in the eigen-basis of H; directions whose mean information is below the threshold
    // are held (solution remapping), which keeps a corridor at the initial guess along its axis.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(H);
    const Eigen::Vector3d lambda = eig.eigenvalues();
    const double threshold =
        std::max(config.degeneracy_min_eigenvalue * count, 1e-12 * std::max(1.0, lambda(2)));
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    int held = 0;
    for (int i = 0; i < 3; ++i) {
      if (lambda(i) < threshold) {
        ++held;
        continue;
      }
      const Eigen::Vector3d v = eig.eigenvectors().col(i);
      delta -= v * (v.dot(g) / lambda(i));
    }
    result.degenerate = held > 0;
    result.min_information_eigenvalue = lambda(0) / count;
    if (prior != nullptr) {
      delta = PriorStep(H, g, Eigen::Vector3d(x, y, theta), *prior);
    } else if (held == 3) {
      singular = true;
      break;
    }
    x += delta(0);
    y += delta(1);
    theta = WrapAngle(theta + delta(2));
    if (std::hypot(delta(0), delta(1)) < config.convergence_translation_m &&
        std::abs(delta(2)) < config.convergence_rotation_rad) {
      numerically_converged = true;
      break;
    }
    // Nearest-neighbour association can switch back and forth between a few correspondence
    // sets: the iterates then cycle through the same poses. A return to a recent pose is
    // convergence as well; the estimate is the mean of the poses of the cycle.
    const Eigen::Vector3d current(x, y, theta);
    for (int back = 2; back <= kCycleMemory && back <= static_cast<int>(history.size()); ++back) {
      const Eigen::Vector3d& earlier = history[history.size() - back];
      if (std::hypot(current(0) - earlier(0), current(1) - earlier(1)) <
              config.convergence_translation_m &&
          std::abs(WrapAngle(current(2) - earlier(2))) < config.convergence_rotation_rad) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int j = 1; j < back; ++j) {
          const Eigen::Vector3d& member = history[history.size() - j];
          sum += Eigen::Vector3d(member(0), member(1), theta + WrapAngle(member(2) - theta));
        }
        sum += current;
        x = sum(0) / back;
        y = sum(1) / back;
        theta = WrapAngle(sum(2) / back);
        result.cycled = true;
        numerically_converged = true;
        break;
      }
    }
    if (numerically_converged) break;
    history.push_back(current);
  }

  const Pose2 estimate(x, y, theta);
  const IcpInliers final_inliers = CountIcpInliers(target, source, estimate, config);
  const int inliers = final_inliers.count;
  result.num_inliers = inliers;
  result.inlier_ratio = static_cast<double>(inliers) / static_cast<double>(source.size());
  result.residual_rms_m =
      inliers > 0 ? std::sqrt(final_inliers.sum_squared_residuals_m2 / inliers) : 0.0;

  if (singular) {
    result.status = IcpStatus::kSingular;
    return result;  // T_target_source stays at the guess
  }
  result.T_target_source = estimate;
  if (!numerically_converged) {
    result.status = IcpStatus::kMaxIterations;
  } else if (inliers < config.min_inliers || result.inlier_ratio < config.min_inlier_ratio) {
    result.status = IcpStatus::kTooFewInliers;
  } else {
    result.status = IcpStatus::kConverged;
    result.converged = true;
  }
  if (!result.converged) result.T_target_source = T_target_source_guess;
  return result;
}

}  // namespace keyplace
