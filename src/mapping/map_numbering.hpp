#pragma once
// Internal: the range of submap ids and scan indices a map uses, for numbering the submaps of
// another map appended to it (distractor copies, keyplace merge).

#include <algorithm>
#include <limits>

#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

// The ids and scan indices a map uses (scans 0..-1 when it has none).
struct MapNumbering {
  int first_id = std::numeric_limits<int>::max();
  int last_id = -1;
  int first_scan = std::numeric_limits<int>::max();
  int last_scan = -1;
};

inline MapNumbering NumberingOf(const GlobalMap& map) {
  MapNumbering numbering;
  for (const Submap& submap : map.submaps) {
    numbering.first_id = std::min(numbering.first_id, submap.id);
    numbering.last_id = std::max(numbering.last_id, submap.id);
    for (const int scan : submap.scan_indices) {
      numbering.first_scan = std::min(numbering.first_scan, scan);
      numbering.last_scan = std::max(numbering.last_scan, scan);
    }
  }
  if (numbering.last_scan < 0) numbering.first_scan = 0;
  return numbering;
}

}  // namespace keyplace
