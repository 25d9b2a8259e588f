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

  /// Maps a point from frame b into frame a (this = T_a_b). To map many points with one pose,
  /// PointMapper takes the cosine and sine once.
  Eigen::Vector2d operator*(const Eigen::Vector2d& point_b) const;

  /// T_a_b.inverse() = T_b_a.
  Pose2 inverse() const {
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    return {-c * x - s * y, s * x - c * y, -theta};
  }
};

/// T_a_b ready to map many points from frame b into frame a: its cosine and sine taken once (in
/// RANSAC's scoring they were 7 % of a SLAM run), the mapping itself that of Pose2::operator*,
/// which uses this class, so both give the same results bit for bit.
class PointMapper {
 public:
  explicit PointMapper(const Pose2& T_a_b)
      : x_(T_a_b.x), y_(T_a_b.y), c_(std::cos(T_a_b.theta)), s_(std::sin(T_a_b.theta)) {}

  Eigen::Vector2d operator()(const Eigen::Vector2d& point_b) const {
    return {x_ + c_ * point_b.x() - s_ * point_b.y(), y_ + s_ * point_b.x() + c_ * point_b.y()};
  }

 private:
  double x_, y_, c_, s_;
};

inline Eigen::Vector2d Pose2::operator*(const Eigen::Vector2d& point_b) const {
  return PointMapper(*this)(point_b);
}

/// The pose of `to` expressed in the frame of `from`: from^-1 * to.
inline Pose2 Between(const Pose2& from, const Pose2& to) { return from.inverse() * to; }

inline double TranslationNorm(const Pose2& pose) { return std::hypot(pose.x, pose.y); }

}  // namespace keyplace
