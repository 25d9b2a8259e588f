#pragma once
// The bundled corrected FR079 log (data/fr079-corrected.log.gz) with its poses and keypoints, its
// map (default mapping) and its ground truth, built once per test program.

#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::testing {

struct BundledMap {
  LogInputs inputs;
  GlobalMap map;
  GroundTruth truth;
};

const BundledMap& BundledFr079();

}  // namespace keyplace::testing
