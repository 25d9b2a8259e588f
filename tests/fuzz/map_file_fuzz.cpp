// libFuzzer harness of the map loader (LoadMap, SQLite .kpm files). Correct rejection is
// std::runtime_error naming the file; anything else is a finding. The seeds include version 1
// maps (no content checksum) so that mutations reach the checks behind the checksum.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/store/map_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("map-file");
  const std::string& path = file.Write(data, size);
  try {
    const keyplace::GlobalMap map = keyplace::LoadMap(path);
    // A loaded map is one SaveMap can write back: every submap has one pose per scan.
    for (const keyplace::Submap& submap : map.submaps) {
      if (submap.poses.empty() || submap.poses.size() != submap.scan_indices.size()) {
        keyplace::fuzz::Finding("submap " + std::to_string(submap.id) + ": " +
                                std::to_string(submap.poses.size()) + " poses for " +
                                std::to_string(submap.scan_indices.size()) + " scans");
      }
    }
  } catch (const std::runtime_error& error) {
    keyplace::fuzz::ExpectNamedError("std::runtime_error", error.what(), path);
  }
  return 0;
}
