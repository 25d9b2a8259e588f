#include "beta_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace keyplace::features_internal {
namespace {

constexpr int kPhi = kBetaGridPhiBins;
constexpr int kRho = kBetaGridRhoBins;
constexpr int kCircles = 2 * kRho;  // inner and outer boundary radius of every ring

// FLIRTLib converts the (possibly negative) window bounds with `unsigned int x = double` and
// then does arithmetic on them. GCC on x86-64 truncates towards zero to 64 bits and keeps the
// low 32 bits; we spell that out so that the window is well-defined C++ with the same values.
std::int64_t TruncateLikeFlirtLib(double value) {
  if (!(std::fabs(value) < 9.0e18)) return 0;  // NaN / huge: no meaningful window (not reached)
  return static_cast<std::int64_t>(value);
}

// [begin, end) of the beams whose rays FLIRTLib tests for one keypoint.
void BeamWindow(const ScanRays& rays, double min_alpha, double max_alpha, int& begin, int& end) {
  const int n = static_cast<int>(rays.x.size());
  const std::int64_t low =
      TruncateLikeFlirtLib(rays.angle_normalizer * (min_alpha - rays.first_angle_rad));
  const std::int64_t high =
      TruncateLikeFlirtLib(rays.angle_normalizer * (max_alpha - rays.first_angle_rad));
  // minIndex = max(0, int(minIndex) - 1)
  begin = static_cast<int>(std::min<std::int64_t>(std::max<std::int64_t>(0, low - 1), n));
  // maxIndex = min(size, size_t(unsigned(maxIndex) + 2)) with 32-bit wrap-around.
  const std::uint32_t high32 = static_cast<std::uint32_t>(high) + 2u;
  end = static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(n), high32));
}

}  // namespace

void PrepareRays(const LaserScan& scan, ScanRays& rays) {
  const std::size_t n = scan.ranges_m.size();
  rays.x.resize(n);
  rays.y.resize(n);
  rays.valid.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double range = scan.ranges_m[i];
    const bool valid = std::isfinite(range) && range >= 0.0 && range < scan.max_range_m;
    rays.valid[i] = valid ? 1 : 0;
    rays.x[i] = valid ? std::cos(scan.angles_rad[i]) * range : 0.0;
    rays.y[i] = valid ? std::sin(scan.angles_rad[i]) * range : 0.0;
  }
  rays.first_angle_rad = n > 0 ? scan.angles_rad.front() : 0.0;
  rays.angle_normalizer =
      n > 1 ? static_cast<double>(n) / (scan.angles_rad.back() - scan.angles_rad.front()) : 0.0;
}

BetaGridDescriptor ComputeBetaGrid(const ScanRays& rays, const Eigen::Vector2d& position_m,
                                   double orientation_rad, const FlirtConfig& config) {
  const double kx = position_m.x();
  const double ky = position_m.y();

  // Rings: FLIRTLib's edges, widened by the radial border except the innermost inner edge.
  std::array<double, kRho + 1> rho_edges;
  for (int r = 0; r <= kRho; ++r) {
    rho_edges[r] = config.descriptor_min_rho_m +
                   r * (config.descriptor_max_rho_m - config.descriptor_min_rho_m) / kRho;
  }
  std::array<double, kRho> inner, outer;
  for (int r = 0; r < kRho; ++r) {
    inner[r] = r == 0 ? rho_edges[0] : rho_edges[r] - config.descriptor_radial_border_m;
    outer[r] = rho_edges[r + 1] + config.descriptor_radial_border_m;
  }
  std::array<double, kCircles> circle_r2;  // circle 2r = inner of ring r, 2r+1 = outer
  double max_radius = 0.0;
  for (int r = 0; r < kRho; ++r) {
    const auto inner_circle = 2 * static_cast<std::size_t>(r);
    circle_r2[inner_circle] = inner[r] * inner[r];
    circle_r2[inner_circle + 1] = outer[r] * outer[r];
    max_radius = std::max({max_radius, std::fabs(inner[r]), std::fabs(outer[r])});
  }

  // Sectors: [edge_phi + theta - border, edge_phi+1 + theta + border].
  std::array<double, kPhi> cos1, sin1, cos2, sin2;
  for (int p = 0; p < kPhi; ++p) {
    const double edge0 = -M_PI + p * (2.0 * M_PI) / kPhi;
    const double edge1 = -M_PI + (p + 1) * (2.0 * M_PI) / kPhi;
    const double angle1 = edge0 + orientation_rad - config.descriptor_angular_border_rad;
    const double angle2 = edge1 + orientation_rad + config.descriptor_angular_border_rad;
    cos1[p] = std::cos(angle1);
    sin1[p] = std::sin(angle1);
    cos2[p] = std::cos(angle2);
    sin2[p] = std::sin(angle2);
  }
  // Chord vector (end - start) of every arc, per sector and circle, relative to the keypoint.
  std::array<std::array<double, kPhi>, kCircles> chord_sx, chord_sy, chord_dx, chord_dy;
  for (int c = 0; c < kCircles; ++c) {
    const double radius = std::sqrt(circle_r2[c]);
    for (int p = 0; p < kPhi; ++p) {
      chord_sx[c][p] = cos1[p] * radius;
      chord_sy[c][p] = sin1[p] * radius;
      chord_dx[c][p] = cos2[p] * radius - chord_sx[c][p];
      chord_dy[c][p] = sin2[p] * radius - chord_sy[c][p];
    }
  }

  // k x u for every radial line (k = keypoint position, u = line direction).
  std::array<std::array<double, 2>, kPhi> line_k_cross_u;
  for (int p = 0; p < kPhi; ++p) {
    line_k_cross_u[p][0] = kx * sin1[p] - ky * cos1[p];
    line_k_cross_u[p][1] = kx * sin2[p] - ky * cos2[p];
  }

  // FLIRTLib's beam window: the angular interval that covers max_rho around the keypoint.
  const double alpha = std::atan2(ky, kx);
  const double alpha_diff = std::atan2(config.descriptor_max_rho_m, std::hypot(kx, ky));
  int begin = 0, end = 0;
  BeamWindow(rays, alpha - alpha_diff, alpha + alpha_diff, begin, end);

  std::array<int, kBetaGridBins> hit{}, miss{};
  const double prune_r2 = (max_radius + 1e-9) * (max_radius + 1e-9);
  for (int i = begin; i < end; ++i) {
    if (!rays.valid[i]) continue;
    // Ray from the laser (origin) to the endpoint; delta = ray start - keypoint.
    const double dir_x = rays.x[i];
    const double dir_y = rays.y[i];
    const double delta_x = -kx;
    const double delta_y = -ky;
    const double dir2 = dir_x * dir_x + dir_y * dir_y;
    if (!(dir2 > 0.0)) continue;
    // Every boundary piece lies in the disc of radius max_radius: skip rays that miss it.
    {
      const double t = std::clamp(-(delta_x * dir_x + delta_y * dir_y) / dir2, 0.0, 1.0);
      const double cx = delta_x + t * dir_x;
      const double cy = delta_y + t * dir_y;
      if (cx * cx + cy * cy > prune_r2) continue;
    }

    // Crossings with each circle: up to two points (relative to the keypoint).
    std::array<std::array<double, 2>, kCircles> ix, iy;
    std::array<int, kCircles> num_points{};
    const double dir_dot_delta = dir_x * delta_x + dir_y * delta_y;
    const double delta2 = delta_x * delta_x + delta_y * delta_y;
    for (int c = 0; c < kCircles; ++c) {
      const double discriminant = dir_dot_delta * dir_dot_delta - dir2 * (delta2 - circle_r2[c]);
      if (discriminant == 0.0) {
        const double t = -dir_dot_delta / dir2;
        if (t >= 0.0 && t <= 1.0) {
          ix[c][0] = delta_x + t * dir_x;
          iy[c][0] = delta_y + t * dir_y;
          num_points[c] = 1;
        }
      } else if (discriminant > 0.0) {
        const double root = std::sqrt(discriminant);
        for (const double t : {(-dir_dot_delta + root) / dir2, (-dir_dot_delta - root) / dir2}) {
          if (t >= 0.0 && t <= 1.0) {
            ix[c][num_points[c]] = delta_x + t * dir_x;
            iy[c][num_points[c]] = delta_y + t * dir_y;
            ++num_points[c];
          }
        }
      }
    }

    // Crossings with the radial lines (two per sector): the ray meets the line through the
    // keypoint with direction u at ray parameter t = (k x u) / (d x u) and at distance
    // s = (k x d) / (d x u) from the keypoint; it crosses the radial segment of ring r when
    // t is in [0, 1] and s in [inner_r, outer_r]. Tested without dividing.
    const double k_cross_d = kx * dir_y - ky * dir_x;
    std::array<std::array<unsigned char, 2>, kPhi> ring_mask;
    for (int p = 0; p < kPhi; ++p) {
      for (int side = 0; side < 2; ++side) {
        const double ux = side == 0 ? cos1[p] : cos2[p];
        const double uy = side == 0 ? sin1[p] : sin2[p];
        double denominator = dir_x * uy - dir_y * ux;
        double t_numerator = line_k_cross_u[p][side];
        double s_numerator = k_cross_d;
        if (denominator < 0.0) {
          denominator = -denominator;
          t_numerator = -t_numerator;
          s_numerator = -s_numerator;
        }
        unsigned char mask = 0;
        if (denominator != 0.0 && t_numerator >= 0.0 && t_numerator <= denominator) {
          for (int r = 0; r < kRho; ++r) {
            const bool crosses =
                s_numerator >= inner[r] * denominator && s_numerator <= outer[r] * denominator;
            mask |= static_cast<unsigned char>(crosses << r);
          }
        }
        ring_mask[p][side] = mask;
      }
    }

    // Crossings with the arcs: a crossing point of circle c belongs to the arc of sector p
    // when it lies beyond the arc's chord (FLIRTLib's test; the arcs span less than pi).
    std::array<std::array<int, kPhi>, kCircles> arc_count{};
    for (int c = 0; c < kCircles; ++c) {
      for (int k = 0; k < num_points[c]; ++k) {
        const double px = ix[c][k];
        const double py = iy[c][k];
        for (int p = 0; p < kPhi; ++p) {
          arc_count[c][p] +=
              (px - chord_sx[c][p]) * chord_dy[c][p] >= (py - chord_sy[c][p]) * chord_dx[c][p];
        }
      }
    }

    for (int p = 0; p < kPhi; ++p) {
      for (int r = 0; r < kRho; ++r) {
        const auto inner_circle = 2 * static_cast<std::size_t>(r);
        const int crossings = ((ring_mask[p][0] >> r) & 1) + ((ring_mask[p][1] >> r) & 1) +
                              arc_count[inner_circle][p] + arc_count[inner_circle + 1][p];
        const int bin = p * kRho + r;
        hit[bin] += crossings == 1;
        miss[bin] += crossings >= 2;
      }
    }
  }

  // Cell value hit / (hit + miss), 0.5 when no ray touched it; normalised to sum 1 (summed in
  // FLIRTLib's rho-major order).
  std::array<double, kBetaGridBins> value;
  for (int b = 0; b < kBetaGridBins; ++b) {
    const int total = hit[b] + miss[b];
    value[b] = total > 0 ? static_cast<double>(hit[b]) / total : 0.5;
  }
  double sum = 0.0;
  for (int r = 0; r < kRho; ++r) {
    for (int p = 0; p < kPhi; ++p) sum += value[p * kRho + r];
  }
  BetaGridDescriptor descriptor;
  for (int b = 0; b < kBetaGridBins; ++b) {
    // All-miss grids would divide by zero in FLIRTLib (NaN); we return the uniform histogram.
    descriptor[b] = static_cast<float>(sum > 0.0 ? value[b] / sum : 1.0 / kBetaGridBins);
  }
  return descriptor;
}

}  // namespace keyplace::features_internal
