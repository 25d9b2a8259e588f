#pragma once
// Large maps for the scale benchmark (docs/BENCHMARKS.md, "Map size"): a real map embedded among
// distractor submaps, copies of real submaps of other maps moved far away, so that place
// recognition runs at any map size on real descriptors and every answer from a distractor is
// measurably wrong.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

struct DistractorOptions {
  // Submaps of the result, the map's own included; no distractor when it is not above the map's.
  std::size_t total_submaps = 0;
  double margin_m = 100.0;  // free space between two copies, and between a copy and the map
  std::uint64_t seed = 1;   // draws the heading of each copy
  // Distractor scan indices start at or above this (and above the map's scans): the scan count
  // of every log whose scan indices are compared with the map's (the query and truth logs).
  int first_scan = 0;
};

/// `map` unchanged (submaps, ids, scans, source fields) followed by distractor submaps until the
/// result holds options.total_submaps. A distractor copy is one whole source map moved by one
/// rigid transform (a random heading, then a translation to its own square tile of a lattice
/// whose first tile holds the map, the others towards +x and +y; tiles are wider than any
/// source's extent plus margin_m, so no two copies and no copy and the map come closer than
/// margin_m), the sources taken in turn and again as needed; the last copy is cut short.
/// Keypoints and occupancy stay in their submap frames, so descriptors, geometry and map
/// neighbours are those of the real submaps. Distractor ids follow the map's largest id, each
/// copy after a gap of one (no two copies are map neighbours), and their scan indices start
/// above the map's and at options.first_scan or above, so that no evaluation rule relates a
/// distractor to a log. Throws std::invalid_argument when distractors are needed but `sources`
/// hold no submap, or margin_m is negative or not finite. Submaps without poses are copied but
/// take no part in the extents.
GlobalMap EmbedAmongDistractors(const GlobalMap& map, const std::vector<GlobalMap>& sources,
                                const DistractorOptions& options);

}  // namespace keyplace
