#include "support/bundled_map.hpp"

#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/place/place_config.hpp"
#include "support/test_data.hpp"

namespace keyplace::testing {

const BundledMap& BundledFr079() {
  static const BundledMap bundled = [] {
    BundledMap b;
    // ctest runs every test case in its own process, and FLIRT on the 1464 scans takes seconds
    // (half a minute under the sanitizers): the preparation cache keeps the keypoints between
    // processes, the same bit for bit, keyed by the code that computes them.
    LogInputOptions options;
    options.cache_dir = KEYPLACE_TEST_CACHE_DIR;
    b.inputs = PrepareLogInputs(SourceDir() + "/data/fr079-corrected.log.gz", options);
    b.map =
        BuildGlobalMap({b.inputs.log.scans, b.inputs.poses, b.inputs.keypoints}, MappingConfig{});
    b.truth = TruthFromOwnPoses(b.inputs.log);
    return b;
  }();
  return bundled;
}

std::vector<LocalizationQuery> BundledQueriesEvery(std::size_t step) {
  const BundledMap& log = BundledFr079();
  const std::vector<int> all = QueryStarts(log.truth, 500);
  std::vector<int> starts;
  for (std::size_t i = 0; i < all.size(); i += step) starts.push_back(all[i]);
  return BuildSubmapQueries(log.inputs, log.truth, log.map.config, starts,
                            PlaceRecognitionConfig{}.query_keypoints);
}

ScanInput BundledScanMessage(std::size_t k) {
  const LogScan& scan = BundledFr079().inputs.log.scans.at(k);
  ScanInput input;
  input.stamp_s = scan.timestamp_s;
  input.frame_id = "laser";
  input.angle_min_rad = scan.angles_rad.front();
  input.angle_increment_rad = scan.angles_rad[1] - scan.angles_rad[0];
  input.range_min_m = 0.0;
  input.range_max_m = scan.max_range_m;
  for (const double range_m : scan.ranges_m) input.ranges_m.push_back(static_cast<float>(range_m));
  input.T_robot_laser = scan.T_robot_laser;
  return input;
}

}  // namespace keyplace::testing
