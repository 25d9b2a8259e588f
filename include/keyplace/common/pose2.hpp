#pragma once
// SE(2) rigid transforms. T_a_b maps points expressed in frame b into frame a.

#include <cmath>

#include <Eigen/Core>

namespace keyplace {

/// Wraps an angle to (-pi, pi].
inline double WrapAngle(double angle_rad) {
  double wrapped = std::remainder(angle_rad, 2.0 * M_PI);  // [-pi, pi]
  if (wrapped <= -M_PI) wrapped += 2.0 * M_PI;
  return wrapped;
}

/// A planar pose / rigid transform (x_m, y_m, theta_rad), theta wrapped to (-pi, pi].
struct Pose2 {
  double x = 0.0;      // metres
  double y = 0.0;      // metres
  double theta = 0.0;  // radians

  Pose2() = default;
  Pose2(double x_m, double y_m, double theta_rad) : x(x_m), y(y_m), theta(WrapAngle(theta_rad)) {}

  Eigen::Vector2d translation() const { return {x, y}; }

  /// Composition: T_a_b * T_b_c = T_a_c.
  Pose2 operator*(const Pose2& rhs) const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return {x + c * rhs.x - s * rhs.y, y + s * rhs.x + c * rhs.y, theta + rhs.theta};
  }

  /// Maps a point from frame b into frame a (this = T_a_b).
  Eigen::Vector2d operator*(const Eigen::Vector2d& point_b) const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return {x + c * point_b.x() - s * point_b.y(), y + s * point_b.x() + c * point_b.y()};
  }

  /// T_a_b.inverse() = T_b_a.
  Pose2 inverse() const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return {-c * x - s * y, s * x - c * y, -theta};
  }
};

/// The pose of `to` expressed in the frame of `from`: from^-1 * to.
inline Pose2 Between(const Pose2& from, const Pose2& to) { return from.inverse() * to; }

inline double TranslationNorm(const Pose2& pose) { return std::hypot(pose.x, pose.y); }

}  // namespace keyplace
