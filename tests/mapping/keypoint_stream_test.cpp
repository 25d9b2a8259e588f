// KeypointStream: keypoints extracted ahead of their consumer, in the consumer's order, equal to
// those extracted at once; an extraction error reaches the consumer.

#include "mapping/keypoint_stream.hpp"

#include <cstddef>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/mapping/scan_sources.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

CarmenLog BundledScans(std::size_t count) {
  LogInputOptions options;
  options.end_scan = count;
  options.keypoints = false;
  options.compute_poses = false;
  return PrepareLogInputs(testing::SourceDir() + "/data/fr079-corrected.log.gz", options).log;
}

void ExpectSameKeypoints(const std::vector<Keypoint>& a, const std::vector<Keypoint>& b,
                         const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].position_m, b[i].position_m) << what << ", keypoint " << i;
    EXPECT_EQ(a[i].descriptor, b[i].descriptor) << what << ", keypoint " << i;
  }
}

TEST(KeypointStream, GivesTheKeypointsOfEachScanInTheConsumersOrder) {
  const CarmenLog log = BundledScans(100);  // more than one batch
  const std::vector<std::vector<Keypoint>> at_once = ExtractKeypoints(log, FlirtExtractor(), {});
  std::vector<std::size_t> order(log.scans.size());
  std::iota(order.rbegin(), order.rend(), std::size_t{0});  // last scan first
  KeypointStream stream(log, order, FlirtConfig{});
  std::size_t with_keypoints = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::vector<Keypoint>& keypoints = stream.Wait(k);
    ExpectSameKeypoints(keypoints, at_once[order[k]], "scan " + std::to_string(order[k]));
    with_keypoints += keypoints.empty() ? 0 : 1;
  }
  EXPECT_GT(with_keypoints, 90u);
  EXPECT_GT(stream.seconds(), 0.0);
  EXPECT_THROW(stream.Wait(order.size()), std::out_of_range);
}

TEST(KeypointStream, AnExtractionErrorReachesTheConsumer) {
  CarmenLog log = BundledScans(100);
  log.scans[70].angles_rad.pop_back();  // ranges and angles differ in size: Extract throws
  std::vector<std::size_t> order(log.scans.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  KeypointStream stream(log, order, FlirtConfig{});
  EXPECT_NO_THROW(stream.Wait(0));
  try {
    stream.Wait(70);
    ADD_FAILURE() << "the scan whose keypoints cannot be extracted gave keypoints";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("LaserScan.angles_rad has"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(stream.Wait(99), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
