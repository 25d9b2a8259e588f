#pragma once
// Internal: the settings of an SQLite connection to a file keyplace reads but did not write (or
// cannot trust: a map file, a rosbag2 sqlite3 storage file), made before the file's schema is
// first read, so that nothing a damaged or hostile file holds ever runs.

#include <sqlite3.h>

#include <cstdint>

namespace keyplace {

/// Counts SQLite's progress calls of one connection; past max_calls every statement stops with
/// SQLITE_INTERRUPT.
struct StepBudget {
  std::uint64_t calls = 0;
  std::uint64_t max_calls = 0;
};

/// Views and triggers disabled, functions in the schema untrusted, extensions off, no writes
/// (query_only), no value longer than the file or `max_value_bytes` (64 KiB at least), no attached
/// databases, and a budget of virtual-machine instructions proportional to the file's size
/// (`instructions_per_file_byte`, at least 10 M): a safety net that ends a runaway query should a
/// schema check ever let one through. `budget` must outlive the connection's statements. Returns
/// false when SQLite refused a setting; the caller reports sqlite3_errmsg with the file's name.
bool HardenReadOnlyConnection(sqlite3* handle, std::uint64_t file_bytes,
                              std::uint64_t max_value_bytes,
                              std::uint64_t instructions_per_file_byte, StepBudget& budget);

/// Whether the connection's last statement stopped because it used up its StepBudget.
inline bool StepBudgetUsedUp(sqlite3* handle) {
  return sqlite3_errcode(handle) == SQLITE_INTERRUPT;
}

}  // namespace keyplace
