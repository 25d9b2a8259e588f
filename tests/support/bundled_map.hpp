#pragma once
// The bundled corrected FR079 log (data/fr079-corrected.log.gz) with its poses and keypoints, its
// map (default mapping) and its ground truth, built once per test program.

#include <cstddef>
#include <vector>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/io/sensor_input.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::testing {

struct BundledMap {
  LogInputs inputs;
  GlobalMap map;
  GroundTruth truth;
};

const BundledMap& BundledFr079();

/// Scan k of the bundled log as a laser driver sends it (sensor_msgs/LaserScan's fields, frame
/// "laser", the log's mounting as the laser pose tf gives).
ScanInput BundledScanMessage(std::size_t k);

/// Every step-th of the bundled log's submap queries (Algorithm 4, QueryStarts of 500, default
/// query keypoints), built for those starts only: BuildSubmapQueries builds each start's query
/// alone, so they are the ones built among all 500 (queries cost seconds under the sanitizers).
std::vector<LocalizationQuery> BundledQueriesEvery(std::size_t step);

}  // namespace keyplace::testing
