#pragma once
// Internal: the tables of a map file, shared by the writer, the schema check and the checksum.

#include <array>

namespace keyplace {

// What SaveMap creates; the loader accepts exactly this (src/store/map_file_checks.cpp).
inline constexpr const char* kMapSchema = R"sql(
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE config (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE submaps (
  id INTEGER PRIMARY KEY,
  overlap REAL NOT NULL,
  distribution REAL NOT NULL,
  forced INTEGER NOT NULL,
  occupancy_cell_m REAL NOT NULL,
  occupancy_cells INTEGER NOT NULL,
  occupancy BLOB NOT NULL        -- zlib-compressed int32 (i, j) pairs, little endian
);
CREATE TABLE poses (
  submap_id INTEGER NOT NULL REFERENCES submaps(id),
  seq INTEGER NOT NULL,
  scan_index INTEGER NOT NULL,
  x REAL NOT NULL, y REAL NOT NULL, theta REAL NOT NULL,  -- T_world_robot
  PRIMARY KEY (submap_id, seq)
);
CREATE TABLE keypoints (
  submap_id INTEGER NOT NULL REFERENCES submaps(id),
  seq INTEGER NOT NULL,
  x REAL NOT NULL, y REAL NOT NULL, orientation REAL NOT NULL,  -- submap frame
  scale REAL NOT NULL,
  level INTEGER NOT NULL,
  scan_index INTEGER NOT NULL,
  stability REAL NOT NULL,
  occurrences INTEGER NOT NULL,
  descriptor BLOB NOT NULL,      -- 48 float32, little endian, phi-major
  PRIMARY KEY (submap_id, seq)
);
)sql";

// The tables in checksum order, with the primary key that orders their rows.
struct MapTableKey {
  const char* name;
  const char* order_by;
};
inline constexpr std::array<MapTableKey, 5> kMapTables = {{{"meta", "key"},
                                                           {"config", "key"},
                                                           {"submaps", "id"},
                                                           {"poses", "submap_id, seq"},
                                                           {"keypoints", "submap_id, seq"}}};

}  // namespace keyplace
