#pragma once
// Map files (.kpm): a GlobalMap in an SQLite database with a versioned, checksummed schema.

#include <string>
#include <vector>

#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

/// Version 2 adds a content checksum to version 1; both are read (docs/RELIABILITY.md).
constexpr int kMapFileSchemaVersion = 2;

/// Writes `map` to `path` through a temporary file in the same folder that is renamed over
/// `path` once complete. Throws std::runtime_error naming the path on failure; an existing file
/// at `path` is then left untouched.
void SaveMap(const GlobalMap& map, const std::string& path);

/// Reads a map file without ever writing to it. Before any query the SQLite header is checked
/// against the file size and the schema against the one SaveMap writes (tables only, no views or
/// triggers); then SQLite's integrity check, the version, the content checksum, the stored
/// mapping configuration (validated as a user's), and every value and blob of every row. Throws
/// std::runtime_error naming the path and the problem (and the table, row and column of a bad
/// value) when the file is missing, not a keyplace map, of a newer version, damaged or hostile.
GlobalMap LoadMap(const std::string& path);

/// What LoadMap checked of one map file (keyplace info --check).
struct MapFileCheck {
  std::vector<std::string> passed;  // the checks that passed, in order, each with what it found
  std::string problem;              // empty when the map is valid, else LoadMap's error
  int schema_version = 0;           // 0 when the check stopped before reading it
  GlobalMap map;                    // the map, when valid

  bool ok() const { return problem.empty(); }
};

/// Runs LoadMap's checks on `path`, recording each; never throws for a bad file.
MapFileCheck CheckMapFile(const std::string& path);

}  // namespace keyplace
