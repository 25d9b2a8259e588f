#pragma once
// A FLIRT interest point: position, orientation and scale in the laser frame, plus descriptor.

#include <Eigen/Core>

#include "keyplace/features/descriptor.hpp"

namespace keyplace {

struct Keypoint {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // laser frame: endpoint of beam_index
  double orientation_rad = 0.0;     // laser frame, (-pi, pi]: towards the smoothed position
  double scale_m = 0.0;             // FLIRTLib's getScale(): 2 sigma of the detection scale
  int scale_level = 0;              // 0 .. FlirtConfig::num_scales - 1
  int beam_index = 0;               // index into LaserScan::ranges_m
  BetaGridDescriptor descriptor{};  // all zero until described
};

}  // namespace keyplace
