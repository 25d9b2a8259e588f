#pragma once
// Point-to-line ICP for 2D point sets.
//
// The target is indexed once (IcpTarget: kd-tree over the caller's points plus one normal per
// point, fitted to its neighbours); any number of source sets can then be aligned against it
// (AlignPointToLine). Gauss-Newton on the point-to-line residual n_q . (T p - q), with a robust
// kernel (IRLS), a correspondence distance gate and a degeneracy guard: directions of the
// parameter space that the correspondences do not constrain (a corridor along its axis) are not
// updated, so the estimate stays at the initial guess there. See docs/REGISTRATION.md.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

enum class RobustKernel { kNone, kHuber, kCauchy, kTukey };

/// Settings of one point-to-line ICP alignment. Defaults work on the Intel and FR079 logs
/// (docs/RESULTS.md) and are not taken from any paper.
struct IcpConfig {
  // --- correspondences -------------------------------------------------------------------
  // A source point is paired with its nearest target point when they are at most this far apart
  // (m). Larger values tolerate a worse initial guess, smaller ones reject more clutter.
  double max_correspondence_distance_m = 0.5;
  // A correspondence counts as an inlier (inlier_ratio, residual_rms_m) when its point-to-line
  // distance is at most this (m).
  double inlier_distance_m = 0.05;

  // --- robust kernel ---------------------------------------------------------------------
  RobustKernel kernel = RobustKernel::kCauchy;
  // Scale of the kernel on the point-to-line residual (m): Huber threshold, Cauchy c, Tukey c.
  double kernel_scale_m = 0.1;

  // --- target normals --------------------------------------------------------------------
  // Neighbours (including the point itself) used to fit the line through each target point.
  int normal_neighbours = 5;
  // Neighbours farther than this from the point are ignored for its normal (m).
  double normal_max_neighbour_distance_m = 0.3;
  // A normal is used only when the fitted neighbourhood is line-like: smallest / largest
  // eigenvalue of the neighbourhood covariance at most this (dimensionless, 0..1).
  double normal_max_eigenvalue_ratio = 0.2;

  // --- iterations ------------------------------------------------------------------------
  int max_iterations = 30;
  // Converged when one Gauss-Newton increment moves less than both of these.
  double convergence_translation_m = 1e-4;
  double convergence_rotation_rad = 1e-4;

  // --- degeneracy ------------------------------------------------------------------------
  // Eigen-directions of the (per-correspondence mean) Gauss-Newton information whose eigenvalue
  // is below this are not updated (dimensionless for translation; rotation is measured as
  // angle times 1 m about the current sensor origin). 0 disables the guard.
  double degeneracy_min_eigenvalue = 0.02;

  // --- acceptance ------------------------------------------------------------------------
  // Fewer valid source or target points than this: status kTooFewPoints, no iteration.
  int min_points = 10;
  // The result is "converged" only with at least this many inliers and this inlier ratio.
  int min_inliers = 10;
  double min_inlier_ratio = 0.3;
};

enum class IcpStatus {
  kConverged,      // increment below the convergence thresholds, enough inliers
  kMaxIterations,  // max_iterations reached without a small enough increment
  kTooFewPoints,   // source or target below min_points (nothing was attempted)
  kTooFewInliers,  // converged numerically but fewer inliers than min_inliers/min_inlier_ratio
  kSingular,       // no usable correspondences / singular normal equations
};

std::string ToString(IcpStatus status);
std::string ToString(RobustKernel kernel);

struct IcpResult {
  // Maps source points into the target frame. The initial guess when not converged.
  Pose2 T_target_source;
  bool converged = false;
  IcpStatus status = IcpStatus::kTooFewPoints;
  int iterations = 0;           // Gauss-Newton iterations run
  int num_source_points = 0;    // source points considered
  int num_inliers = 0;          // inliers at the final pose
  double inlier_ratio = 0.0;    // num_inliers / num_source_points
  double residual_rms_m = 0.0;  // RMS point-to-line distance of the inliers
  // True when the points of the last iteration leave at least one direction below the degeneracy
  // guard (e.g. a corridor's axis): without a prior that direction was held at the initial
  // guess, with one the prior decided it. Either way the points alone measure the pose only
  // partially.
  bool degenerate = false;
  // True when the iterates returned to a recent pose (a cycle of the nearest-neighbour
  // association) and the estimate is the mean of the cycle; counts as converged.
  bool cycled = false;
  // Smallest eigenvalue of the per-correspondence mean information at the final iteration.
  double min_information_eigenvalue = 0.0;
};

/// Unit normals of a point set, one per point; valid[i] == 0 where no line could be fitted.
struct PointNormals {
  std::vector<Eigen::Vector2d> normals;
  std::vector<std::uint8_t> valid;
};

/// Fits a line to the config.normal_neighbours nearest neighbours of every point (within
/// normal_max_neighbour_distance_m) and keeps it when line-like (normal_max_eigenvalue_ratio).
PointNormals EstimateNormals(const std::vector<Eigen::Vector2d>& points, const IcpConfig& config);

/// A target point set prepared for alignment: kd-tree (nanoflann, reading the caller's points
/// through an adaptor, no copy) and per-point normals. The caller's vector must outlive the
/// IcpTarget and must not be modified while it exists.
class IcpTarget {
 public:
  /// Estimates the normals from the points' neighbours (EstimateNormals).
  /// Throws std::invalid_argument naming the field when the config is invalid.
  IcpTarget(const std::vector<Eigen::Vector2d>& points, const IcpConfig& config);
  /// Uses the given normals (e.g. estimated per scan before scans were merged into a map, which
  /// avoids fitting lines across the noise of different scans). Their size must match `points`.
  IcpTarget(const std::vector<Eigen::Vector2d>& points, PointNormals normals,
            const IcpConfig& config);
  ~IcpTarget();
  IcpTarget(const IcpTarget&) = delete;
  IcpTarget& operator=(const IcpTarget&) = delete;

  std::size_t size() const;
  const std::vector<Eigen::Vector2d>& points() const;
  /// Unit normal of point i; only meaningful when HasNormal(i).
  const Eigen::Vector2d& normal(std::size_t i) const;
  bool HasNormal(std::size_t i) const;
  std::size_t CountNormals() const;
  /// Fits a normal, as the first constructor does but over all the target's points, to each
  /// point that has none (e.g. a far point its own scan was too sparse for, now among the points
  /// of several scans). Points with a normal keep it. Returns how many got one; throws
  /// std::invalid_argument for an invalid config.
  std::size_t FillMissingNormals(const IcpConfig& config);

  /// Index of the nearest target point and its squared distance (m^2). Returns false when the
  /// target is empty.
  bool Nearest(const Eigen::Vector2d& query, std::size_t* index, double* squared_distance_m2) const;
  /// No hint for NearestWithin.
  static constexpr std::size_t kNoHint = std::numeric_limits<std::size_t>::max();
  /// As Nearest, for a point no farther than sqrt(max_squared_distance_m2): false when none is,
  /// and otherwise the same point as Nearest (among equally near ones too). `hint`, an index
  /// (ignored when out of range; kNoHint: none), is a point likely near the query, such as the
  /// answer for the previous of a scan's points: its distance bounds the tree search from the
  /// start, so consecutive queries of a scan cost little.
  bool NearestWithin(const Eigen::Vector2d& query, double max_squared_distance_m2, std::size_t hint,
                     std::size_t* index, double* squared_distance_m2) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The source points (mapped by T_target_source) that ICP counts as inliers there: a nearest
/// target point within max_correspondence_distance_m, with a normal, and a point-to-line
/// distance of at most inlier_distance_m; and the sum of those squared distances (m^2). What
/// AlignPointToLine reports at its estimate, and what loop refinement counts for its overlap.
struct IcpInliers {
  int count = 0;
  double sum_squared_residuals_m2 = 0.0;
};
IcpInliers CountIcpInliers(const IcpTarget& target, const std::vector<Eigen::Vector2d>& source,
                           const Pose2& T_target_source, const IcpConfig& config);

/// A Gaussian prior on the estimated pose, such as the wheel odometry's prediction: the cost gains
/// e^T information e / 2 with e = (x, y, theta) of the estimate minus those of the mean, in the
/// target frame. The information is in the units of the point-to-line cost, where one point with
/// residual r costs r^2 / 2 (m^2): a prior of standard deviation sigma, for residuals of standard
/// deviation sigma_r, has information sigma_r^2 / sigma^2 (rotation: m^2 / rad^2).
struct IcpPosePrior {
  Pose2 T_target_source_mean;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
};

/// Aligns `source` (points in the source frame) to `target`, starting from T_target_source_guess.
/// Expected failures are reported in the result; the config is validated (std::invalid_argument).
/// With fewer than 3 correspondences the result is kSingular, prior or not. The information
/// must be positive definite: a prior on some axes only is a large sigma on the others.
/// With a prior the normal equations include it and no direction is held by the degeneracy guard
/// (the prior is what keeps a weakly measured direction near its mean); `degenerate` still reports
/// whether the points alone would have been held.
IcpResult AlignPointToLine(const IcpTarget& target, const std::vector<Eigen::Vector2d>& source,
                           const Pose2& T_target_source_guess, const IcpConfig& config,
                           const IcpPosePrior* prior = nullptr);

/// Throws std::invalid_argument naming the first invalid field of `config`.
void ValidateIcpConfig(const IcpConfig& config);

}  // namespace keyplace
