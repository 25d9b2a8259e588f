#pragma once
// Internal: the checks LoadMap makes before it reads a row of a map file, so that nothing a
// damaged or hostile file holds (a view, a trigger, an endless query) is ever run, and the file
// is never written. docs/RELIABILITY.md lists them.

#include <cstdint>
#include <string>

#include "io/sqlite_hardening.hpp"
#include "store/sqlite_database.hpp"

namespace keyplace {

struct MapFileFacts {
  std::uint64_t bytes = 0;
  std::uint32_t page_bytes = 0;
};

/// The SQLite header against the file: magic, page size, rollback-journal format (a
/// write-ahead-log file would make readers create -wal/-shm files), size a whole number of pages
/// and equal to the header's page count. Throws std::runtime_error naming the path.
MapFileFacts CheckMapFileHeader(const std::string& path);

/// The URI that opens `path` read-only and immutable (with SQLITE_OPEN_READONLY | SQLITE_OPEN_URI).
std::string ImmutableMapUri(const std::string& path);

/// Before the schema is first read: HardenReadOnlyConnection with no value longer than the file
/// and 64 steps per byte of file.
void HardenMapConnection(Database& db, std::uint64_t file_bytes, StepBudget& budget);

/// sqlite_master holds exactly the tables SaveMap writes (ordinary tables, their columns and
/// declared types, their very CREATE text) and their primary-key indexes, nothing else. Throws
/// std::runtime_error naming the path and the object.
void CheckMapSchema(const Database& db);

/// PRAGMA integrity_check; throws std::runtime_error with its first problems.
void CheckMapIntegrity(const Database& db);

}  // namespace keyplace
