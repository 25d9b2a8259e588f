// libFuzzer harness of the map loader (LoadMap, SQLite .kpm files). Correct rejection is
// std::runtime_error naming the file; anything else is a finding. The seeds include version 1
// maps (no content checksum) so that mutations reach the checks behind the checksum.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/store/map_file.hpp"

namespace {

const double kMaxCoordinateM = keyplace::CarmenReadOptions{}.max_coordinate_m;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("map-file");
  const std::string& path = file.Write(data, size);
  try {
    const keyplace::GlobalMap map = keyplace::LoadMap(path);
    // A loaded map is one SaveMap can write back: every submap has one pose per scan. Its
    // geometry is what a log could give (issue 31: finite poses of 1e300 m, scales <= 0 and
    // descriptors that are no histogram passed every check once the checksum was recomputed).
    for (const keyplace::Submap& submap : map.submaps) {
      const std::string where = "submap " + std::to_string(submap.id) + ": ";
      if (submap.poses.empty() || submap.poses.size() != submap.scan_indices.size()) {
        keyplace::fuzz::Finding(where + std::to_string(submap.poses.size()) + " poses for " +
                                std::to_string(submap.scan_indices.size()) + " scans");
      }
      for (const keyplace::Pose2& pose : submap.poses) {
        if (!(std::abs(pose.x) <= kMaxCoordinateM && std::abs(pose.y) <= kMaxCoordinateM &&
              std::abs(pose.theta) <= 2.0 * M_PI)) {
          keyplace::fuzz::Finding(where + "a pose beyond the log readers' bounds");
        }
      }
      for (const keyplace::StableKeypoint& keypoint : submap.keypoints) {
        double sum = 0.0;
        for (const float bin : keypoint.descriptor) sum += bin;
        if (!(std::abs(keypoint.position_m.x()) <= kMaxCoordinateM &&
              std::abs(keypoint.position_m.y()) <= kMaxCoordinateM &&
              std::abs(keypoint.orientation_rad) <= 2.0 * M_PI && keypoint.scale_m > 0.0 &&
              std::abs(sum - 1.0) <= 1e-3)) {
          keyplace::fuzz::Finding(where +
                                  "a keypoint beyond the bounds, of scale <= 0 or whose "
                                  "descriptor is no histogram");
        }
      }
    }
  } catch (const std::runtime_error& error) {
    keyplace::fuzz::ExpectNamedError("std::runtime_error", error.what(), path);
  }
  return 0;
}
