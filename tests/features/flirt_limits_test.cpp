// FLIRT on large scans (issue 18): memory grows with the beams and the pairs of beams within the
// kernel cutoff, not with the square of the beam count; more than kMaxScanBeams is an error.

#include <sys/resource.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "support/sanitizers.hpp"

namespace keyplace {
namespace {

// A 360-degree scan of `beams` beams from the centre of a square room of half side half_m, with
// a few centimetres of texture so that no two edges of the geodesic graph tie.
LaserScan RoomScan(std::size_t beams, double half_m) {
  LaserScan scan;
  scan.max_range_m = 80.0;
  for (std::size_t k = 0; k < beams; ++k) {
    const double angle = -M_PI + 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(beams);
    const double c = std::abs(std::cos(angle));
    const double s = std::abs(std::sin(angle));
    double range = std::min(c > 1e-12 ? half_m / c : 1e9, s > 1e-12 ? half_m / s : 1e9);
    range += 0.01 * std::sin(37.0 * static_cast<double>(k));
    scan.ranges_m.push_back(range);
    scan.angles_rad.push_back(angle);
    scan.valid.push_back(1);
  }
  return scan;
}

// The process's virtual memory size (VmSize of /proc/self/status), in bytes.
rlim_t VirtualMemoryBytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmSize:") {
      rlim_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    std::getline(status, key);
  }
  return 0;
}

// Extracts the keypoints of a kMaxScanBeams-beam scan with 256 MiB of address space to spare;
// the exit status of a death test.
[[noreturn]] void ExtractLargeScanWith256MiB() {
  const LaserScan scan = RoomScan(kMaxScanBeams, 20.0);  // built before the limit
  const FlirtExtractor extractor;
  const rlim_t used = VirtualMemoryBytes();
  if (used == 0) std::exit(2);
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = used + (rlim_t{256} << 20);
  if (setrlimit(RLIMIT_AS, &limit) != 0) std::exit(2);
  const std::vector<Keypoint> keypoints = extractor.Extract(scan);
  std::exit(keypoints.empty() ? 3 : 0);
}

// Formerly the geodesic distances took a dense n x n table: 512 MiB for 8192 beams (and 3.2 GB,
// then std::bad_alloc, for 20 000); now this scan needs about 60 MiB.
TEST(FlirtLimitsDeathTest, MemoryIsNotQuadraticInTheBeamCount) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << testing::kAddressSpaceLimitUnderAsan;
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  EXPECT_EXIT(ExtractLargeScanWith256MiB(), ::testing::ExitedWithCode(0), "");
}

TEST(FlirtLimits, MoreThanTheMostBeamsPerScanIsAnError) {
  const FlirtExtractor extractor;
  const LaserScan scan = RoomScan(kMaxScanBeams + 1, 5.0);
  try {
    extractor.Extract(scan);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(std::to_string(kMaxScanBeams)), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(extractor.Detect(scan), std::invalid_argument);
  EXPECT_THROW(extractor.ComputeSignals(scan), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
