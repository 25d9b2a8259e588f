#include "keyplace/features/flirt.hpp"

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "beta_grid.hpp"
#include "curvature_detector.hpp"

namespace keyplace {
namespace {

using features_internal::ComputeBetaGrid;
using features_internal::ComputeCurvature;
using features_internal::CurvatureParams;
using features_internal::CurvatureResult;
using features_internal::CurvatureWorkspace;
using features_internal::PrepareRays;
using features_internal::ScanRays;

// Fewer valid beams cannot give a peak (peaks are searched at vertices 2 .. n-3).
constexpr int kMinValidBeams = 5;

// Per-thread scratch space, reused from scan to scan.
struct Workspace {
  CurvatureWorkspace curvature;
  CurvatureResult curvature_result;
  std::vector<int> beam_of_vertex;
  std::vector<Eigen::Vector2d> accepted_world;
  ScanRays rays;
};

Workspace& ThreadWorkspace() {
  thread_local Workspace workspace;
  return workspace;
}

void Require(bool condition, const char* field, const char* what) {
  if (!condition) {
    throw std::invalid_argument(std::string("FlirtConfig.") + field + " " + what);
  }
}

void CheckScan(const LaserScan& scan) {
  if (scan.angles_rad.size() != scan.ranges_m.size()) {
    throw std::invalid_argument(
        "LaserScan.angles_rad has " + std::to_string(scan.angles_rad.size()) +
        " entries but ranges_m has " + std::to_string(scan.ranges_m.size()));
  }
  if (scan.ranges_m.size() > kMaxScanBeams) {
    throw std::invalid_argument("LaserScan has " + std::to_string(scan.ranges_m.size()) +
                                " beams, more than the " + std::to_string(kMaxScanBeams) +
                                " FLIRT takes (kMaxScanBeams): downsample the scan");
  }
}

bool BeamValid(const LaserScan& scan, std::size_t i) {
  const double range = scan.ranges_m[i];
  return std::isfinite(range) && range >= 0.0 && range < scan.max_range_m;
}

// Loads the valid beams as graph vertices, in the frame given by T_world_laser (computed like
// FLIRTLib's world points, so that near-equal edge lengths compare the same way); returns false
// when there are too few.
bool LoadVertices(const LaserScan& scan, const Pose2& T_world_laser, Workspace& ws) {
  ws.beam_of_vertex.clear();
  ws.curvature.x.clear();
  ws.curvature.y.clear();
  if (!(scan.max_range_m > 0.0)) return false;
  for (std::size_t i = 0; i < scan.ranges_m.size(); ++i) {
    if (!BeamValid(scan, i)) continue;
    ws.beam_of_vertex.push_back(static_cast<int>(i));
    const double world_angle = scan.angles_rad[i] + T_world_laser.theta;
    ws.curvature.x.push_back(std::cos(world_angle) * scan.ranges_m[i] + T_world_laser.x);
    ws.curvature.y.push_back(std::sin(world_angle) * scan.ranges_m[i] + T_world_laser.y);
  }
  return static_cast<int>(ws.beam_of_vertex.size()) >= kMinValidBeams;
}

CurvatureParams MakeCurvatureParams(const FlirtConfig& config, const std::vector<double>& sigmas) {
  CurvatureParams params;
  params.sigmas_m = sigmas;
  params.num_trees = config.dmst + 1;
  params.cutoff_sigmas = config.kernel_cutoff_sigmas;
  return params;
}

// FLIRTLib's SimplePeakFinder (the MinMax variant's minima never occur: the signal is >= 0).
bool IsPeak(const std::vector<double>& signal, std::size_t i, const FlirtConfig& config) {
  return signal[i] > config.min_peak && signal[i] - signal[i - 1] > config.min_peak_difference &&
         signal[i] - signal[i + 1] > config.min_peak_difference;
}

}  // namespace

void ValidateFlirtConfig(const FlirtConfig& c) {
  Require(c.num_scales >= 1 && c.num_scales <= 32, "num_scales", "must be in [1, 32]");
  Require(std::isfinite(c.base_sigma_m) && c.base_sigma_m > 0.0, "base_sigma_m",
          "must be positive and finite");
  Require(std::isfinite(c.sigma_step) && c.sigma_step > 0.0, "sigma_step",
          "must be positive and finite");
  Require(c.dmst >= 0 && c.dmst <= 16, "dmst", "must be in [0, 16]");
  Require(std::isfinite(c.min_peak), "min_peak", "must be finite");
  Require(std::isfinite(c.min_peak_difference) && c.min_peak_difference >= 0.0,
          "min_peak_difference", "must be finite and >= 0");
  Require(std::isfinite(c.duplicate_box_m) && c.duplicate_box_m >= 0.0, "duplicate_box_m",
          "must be finite and >= 0");
  Require(c.kernel_cutoff_sigmas > 0.0, "kernel_cutoff_sigmas", "must be positive (may be inf)");
  Require(std::isfinite(c.descriptor_min_rho_m) && c.descriptor_min_rho_m >= 0.0,
          "descriptor_min_rho_m", "must be finite and >= 0");
  Require(std::isfinite(c.descriptor_max_rho_m) && c.descriptor_max_rho_m > c.descriptor_min_rho_m,
          "descriptor_max_rho_m", "must be finite and > descriptor_min_rho_m");
  Require(std::isfinite(c.descriptor_radial_border_m) && c.descriptor_radial_border_m >= 0.0,
          "descriptor_radial_border_m", "must be finite and >= 0");
  Require(std::isfinite(c.descriptor_angular_border_rad) &&
              c.descriptor_angular_border_rad >= 0.0 &&
              c.descriptor_angular_border_rad < M_PI / 4.0,
          "descriptor_angular_border_rad", "must be in [0, pi/4)");
}

FlirtExtractor::FlirtExtractor(FlirtConfig config) : config_(config) {
  ValidateFlirtConfig(config_);
  sigmas_m_.resize(config_.num_scales);
  for (int l = 0; l < config_.num_scales; ++l) {
    sigmas_m_[l] = config_.base_sigma_m * std::pow(config_.sigma_step, l);
  }
}

std::vector<Keypoint> FlirtExtractor::Detect(const LaserScan& scan,
                                             const Pose2& T_world_laser) const {
  CheckScan(scan);
  std::vector<Keypoint> keypoints;
  Workspace& ws = ThreadWorkspace();
  if (!LoadVertices(scan, T_world_laser, ws)) return keypoints;
  ComputeCurvature(MakeCurvatureParams(config_, sigmas_m_), ws.curvature, ws.curvature_result);

  // FLIRTLib works on world-frame points; we do the same (T_world_laser) so that the
  // axis-aligned duplicate box and every floating-point comparison come out the same, and
  // report positions and orientations in the laser frame.
  const std::size_t num_vertices = ws.beam_of_vertex.size();
  const std::size_t num_beams = scan.ranges_m.size();
  const auto world_point = [&](std::size_t beam) {
    const double range = BeamValid(scan, beam) ? scan.ranges_m[beam] : scan.max_range_m;
    const double world_angle = scan.angles_rad[beam] + T_world_laser.theta;
    return Eigen::Vector2d(std::cos(world_angle) * range + T_world_laser.x,
                           std::sin(world_angle) * range + T_world_laser.y);
  };
  const Eigen::Vector2d first_point = world_point(0);
  const Eigen::Vector2d last_point = world_point(num_beams - 1);
  const double box = config_.duplicate_box_m;
  std::vector<Eigen::Vector2d>& accepted_world = ws.accepted_world;
  accepted_world.clear();

  for (int level = 0; level < config_.num_scales; ++level) {
    const std::vector<double>& signal = ws.curvature_result.signal[level];
    const double sigma = sigmas_m_[level];
    for (std::size_t vertex = 2; vertex + 2 < num_vertices; ++vertex) {
      if (!IsPeak(signal, vertex, config_)) continue;
      // "Push to foreground": move to the nearer neighbouring beam (raw ranges, invalid ones
      // included). FLIRTLib uses the previous beam only from beam 2 on.
      std::size_t beam = static_cast<std::size_t>(ws.beam_of_vertex[vertex]);
      const double range_before = beam > 1 ? scan.ranges_m[beam - 1] : scan.max_range_m;
      const double range_after = beam + 1 < num_beams ? scan.ranges_m[beam + 1] : scan.max_range_m;
      const double range_current = scan.ranges_m[beam];
      if (range_before < range_after) {
        if (range_before < range_current) --beam;
      } else if (range_after < range_current) {
        ++beam;
      }
      if (!BeamValid(scan, beam)) continue;

      const Eigen::Vector2d position_world = world_point(beam);
      const double theta_world =
          std::atan2(ws.curvature_result.ay[level][vertex] - position_world.y(),
                     ws.curvature_result.ax[level][vertex] - position_world.x());
      // Duplicate suppression in an axis-aligned box of the world frame.
      bool duplicate = false;
      for (const Eigen::Vector2d& other : accepted_world) {
        if (std::fabs(position_world.x() - other.x()) <= box &&
            std::fabs(position_world.y() - other.y()) <= box) {
          duplicate = true;
          break;
        }
      }
      if (duplicate) continue;
      // Border rejection against the first and last beam endpoints (of all beams).
      const double scale = 2.0 * sigma;
      const Eigen::Vector2d to_first = position_world - first_point;
      const Eigen::Vector2d to_last = position_world - last_point;
      if (std::hypot(to_first.x(), to_first.y()) < scale ||
          std::hypot(to_last.x(), to_last.y()) < scale) {
        continue;
      }
      accepted_world.push_back(position_world);
      Keypoint keypoint;
      keypoint.position_m = {std::cos(scan.angles_rad[beam]) * scan.ranges_m[beam],
                             std::sin(scan.angles_rad[beam]) * scan.ranges_m[beam]};
      keypoint.orientation_rad = WrapAngle(theta_world - T_world_laser.theta);
      keypoint.scale_m = scale;
      keypoint.scale_level = level;
      keypoint.beam_index = static_cast<int>(beam);
      keypoints.push_back(keypoint);
    }
  }
  return keypoints;
}

void FlirtExtractor::Describe(const LaserScan& scan, std::vector<Keypoint>& keypoints) const {
  CheckScan(scan);
  if (keypoints.empty()) return;
  Workspace& ws = ThreadWorkspace();
  PrepareRays(scan, ws.rays);
  for (Keypoint& keypoint : keypoints) {
    keypoint.descriptor =
        ComputeBetaGrid(ws.rays, keypoint.position_m, keypoint.orientation_rad, config_);
  }
}

BetaGridDescriptor FlirtExtractor::Describe(const LaserScan& scan,
                                            const Eigen::Vector2d& position_m,
                                            double orientation_rad) const {
  CheckScan(scan);
  Workspace& ws = ThreadWorkspace();
  PrepareRays(scan, ws.rays);
  return ComputeBetaGrid(ws.rays, position_m, orientation_rad, config_);
}

std::vector<Keypoint> FlirtExtractor::Extract(const LaserScan& scan,
                                              const Pose2& T_world_laser) const {
  std::vector<Keypoint> keypoints = Detect(scan, T_world_laser);
  Describe(scan, keypoints);
  return keypoints;
}

FlirtSignals FlirtExtractor::ComputeSignals(const LaserScan& scan,
                                            const Pose2& T_world_laser) const {
  CheckScan(scan);
  FlirtSignals signals;
  signals.sigma_m = sigmas_m_;
  Workspace& ws = ThreadWorkspace();
  const bool enough = LoadVertices(scan, T_world_laser, ws);
  signals.beam_of_vertex = ws.beam_of_vertex;
  const std::size_t n = ws.beam_of_vertex.size();
  for (std::size_t v = 0; v < n; ++v) {
    signals.vertices_m.emplace_back(ws.curvature.x[v], ws.curvature.y[v]);
  }
  const int num_scales = config_.num_scales;
  signals.smoothed_m.resize(num_scales);
  signals.signal.resize(num_scales);
  signals.peak_vertices.resize(num_scales);
  if (!enough) return signals;
  ComputeCurvature(MakeCurvatureParams(config_, sigmas_m_), ws.curvature, ws.curvature_result);
  int begin = 0;
  for (const int end : ws.curvature.tree_end) {
    auto& tree = signals.spanning_trees.emplace_back();
    for (int e = begin; e < end; ++e)
      tree.emplace_back(ws.curvature.edge_a[e], ws.curvature.edge_b[e]);
    begin = end;
  }
  for (int level = 0; level < num_scales; ++level) {
    signals.signal[level] = ws.curvature_result.signal[level];
    signals.smoothed_m[level].resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      signals.smoothed_m[level][v] = {ws.curvature_result.ax[level][v],
                                      ws.curvature_result.ay[level][v]};
    }
    for (std::size_t v = 2; v + 2 < n; ++v) {
      if (IsPeak(signals.signal[level], v, config_)) {
        signals.peak_vertices[level].push_back(static_cast<int>(v));
      }
    }
  }
  return signals;
}

}  // namespace keyplace
