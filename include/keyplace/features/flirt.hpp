#pragma once
// FLIRT interest points for 2D laser scans: FLIRTLib's multi-scale curvature detector on the
// geodesic graph of the scan, and its beta-grid descriptor (Tipaldi & Arras, ICRA 2010).
//
// This is an independent reimplementation that reproduces the output of FLIRTLib
// (tipaldi/flirtlib @ f608c8c4) with the parameters of its RansacLoopClosureTest; the algorithm,
// every reproduced quirk and every deviation are described in docs/FLIRT.md.

#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/descriptor.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace {

struct FlirtConfig {
  // --- Detector (FLIRTLib CurvatureDetector + SimpleMinMaxPeakFinder) ---
  int num_scales = 5;                  // number of smoothing scales
  double base_sigma_m = 0.2;           // sigma of scale 0 (t0 in the paper)
  double sigma_step = 1.4;             // sigma_l = base_sigma_m * sigma_step^l (ti in the paper)
  int dmst = 2;                        // the geodesic graph is the union of dmst + 1 spanning trees
  double min_peak = 0.34;              // a peak needs signal > min_peak (signal = t exp(-t) <= 1/e)
  double min_peak_difference = 0.001;  // ... and signal - signal of each neighbour > this
  // A keypoint is dropped when an already accepted one (finer scales first) lies within this
  // distance along both world axes (FLIRTLib's axis-aligned box; see FlirtExtractor::Extract).
  double duplicate_box_m = 0.2;
  // Geodesic neighbours farther than kernel_cutoff_sigmas * sigma are left out of the Gaussian
  // smoothing at that scale (FLIRTLib sums over all vertices). At 8 sigma a left-out weight is
  // below exp(-32) = 1.3e-14 of the central one, so the output equals the untruncated one;
  // +infinity gives the exact all-pairs computation.
  double kernel_cutoff_sigmas = 8.0;

  // --- Descriptor (FLIRTLib BetaGridGenerator; 12 x 4 bins, see descriptor.hpp) ---
  double descriptor_min_rho_m = 0.02;        // inner radius of the innermost ring
  double descriptor_max_rho_m = 0.5;         // outer radius of the outermost ring (not scaled)
  double descriptor_radial_border_m = 0.05;  // rings overlap by this much (FLIRTLib hard-codes)
  double descriptor_angular_border_rad = 5.0 * M_PI / 180.0;  // sectors overlap by this much
};

/// Throws std::invalid_argument naming the first invalid field.
void ValidateFlirtConfig(const FlirtConfig& config);

/// Intermediate results of the detector, for diagnostics and oracle tests.
struct FlirtSignals {
  std::vector<int> beam_of_vertex;  // graph vertex (valid beam, in scan order) -> beam index
  // Vertex positions in the frame of the computation (T_world_laser applied, like FLIRTLib).
  std::vector<Eigen::Vector2d> vertices_m;
  // The dmst + 1 successive spanning trees whose union is the geodesic graph (vertex pairs).
  std::vector<std::vector<std::pair<int, int>>> spanning_trees;
  std::vector<double> sigma_m;  // per scale
  // Per scale, per vertex: geodesic-Gaussian smoothed position (frame of vertices_m) and the
  // signal t exp(-t), t = 2 / sigma * |smoothed - position|.
  std::vector<std::vector<Eigen::Vector2d>> smoothed_m;
  std::vector<std::vector<double>> signal;
  std::vector<std::vector<int>> peak_vertices;  // per scale, ascending
};

/// FLIRT detector + beta-grid descriptor. Immutable after construction; all methods are const
/// and thread-safe: scratch buffers live in a per-thread workspace that is reused between calls
/// (a few hundred bytes per valid beam plus 20 per pair of valid beams within the kernel cutoff
/// of the largest scale: 57 MiB for 8192 beams in a 40 m room, 650 MiB when all 8192 lie within
/// the cutoff of each other; docs/RELIABILITY.md).
class FlirtExtractor {
 public:
  explicit FlirtExtractor(FlirtConfig config = {});

  const FlirtConfig& config() const { return config_; }
  /// sigma of a scale level (m); the keypoint scale is 2 sigma.
  double SigmaM(int scale_level) const { return sigmas_m_.at(scale_level); }

  /// Detects and describes the keypoints of one scan, in FLIRTLib's order (scale level
  /// ascending, then beam order). Positions and orientations are in the laser frame.
  /// `T_world_laser` is the frame the detector computes in, as FLIRTLib detects on world-frame
  /// points: it orients FLIRTLib's axis-aligned duplicate-suppression box, and the rounding of
  /// the world coordinates decides between near-equal edge lengths in the spanning trees. Any
  /// pose gives valid keypoints; pass the laser pose (as printed in the log) to reproduce
  /// FLIRTLib's output exactly.
  /// A beam is used when its range is finite, >= 0 and < scan.max_range_m. Scans with fewer than
  /// 5 such beams give no keypoints. Throws std::invalid_argument when ranges_m and angles_rad
  /// differ in size or the scan has more than kMaxScanBeams beams.
  std::vector<Keypoint> Extract(const LaserScan& scan, const Pose2& T_world_laser = Pose2()) const;

  /// Extract without the descriptors (they stay zero).
  std::vector<Keypoint> Detect(const LaserScan& scan, const Pose2& T_world_laser = Pose2()) const;

  /// Fills the descriptor of each keypoint from the scan it was detected in.
  void Describe(const LaserScan& scan, std::vector<Keypoint>& keypoints) const;

  /// The beta grid of an arbitrary oriented point (laser frame) in a scan.
  BetaGridDescriptor Describe(const LaserScan& scan, const Eigen::Vector2d& position_m,
                              double orientation_rad) const;

  /// The detector's intermediate results (copies them out; for tests and diagnostics).
  FlirtSignals ComputeSignals(const LaserScan& scan, const Pose2& T_world_laser = Pose2()) const;

 private:
  FlirtConfig config_;
  std::vector<double> sigmas_m_;
};

}  // namespace keyplace
