#pragma once
// Map files (.kpm): a GlobalMap in an SQLite database with a versioned schema.

#include <string>

#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

constexpr int kMapFileSchemaVersion = 1;

/// Writes `map` to `path` through a temporary file in the same folder that is renamed over
/// `path` once complete. Throws std::runtime_error naming the path on failure; an existing file
/// at `path` is then left untouched.
void SaveMap(const GlobalMap& map, const std::string& path);

/// Reads a map file. Throws std::runtime_error naming the path and the problem when the file is
/// missing, not a keyplace map, of another schema version, truncated or corrupt.
GlobalMap LoadMap(const std::string& path);

}  // namespace keyplace
