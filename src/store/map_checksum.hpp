#pragma once
// Internal: the content checksum of a map file (meta row `content_checksum`, format version 2).

#include <sqlite3.h>

#include <string>

namespace keyplace {

constexpr const char* kMapChecksumKey = "content_checksum";

/// "fnv1a64:<16 hex digits>": FNV-1a (64 bit) over a canonical serialisation of every row of the
/// five map tables (meta without its checksum row, config, submaps, poses, keypoints), each in
/// primary-key order, every value with its SQLite storage class. Any single changed byte of a
/// value changes it. Throws std::runtime_error with SQLite's message when a table cannot be read.
std::string MapContentChecksum(sqlite3* db);

}  // namespace keyplace
