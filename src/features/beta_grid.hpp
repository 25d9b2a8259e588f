#pragma once
// Internal: FLIRTLib's beta-grid descriptor (not installed, not part of the API).

#include <vector>

#include <Eigen/Core>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace::features_internal {

/// The rays of one scan, laser frame: from the laser origin to each beam endpoint.
struct ScanRays {
  std::vector<double> x, y;  // endpoint (meaningful where valid)
  std::vector<unsigned char> valid;
  double first_angle_rad = 0.0;   // angle of beam 0
  double angle_normalizer = 0.0;  // n / (angle of last beam - angle of beam 0), FLIRTLib's
};

/// Fills `rays` from the scan (same validity rule as the detector).
void PrepareRays(const LaserScan& scan, ScanRays& rays);

/// The normalised beta grid of the oriented point (position, orientation) in the laser frame.
BetaGridDescriptor ComputeBetaGrid(const ScanRays& rays, const Eigen::Vector2d& position_m,
                                   double orientation_rad, const FlirtConfig& config);

}  // namespace keyplace::features_internal
