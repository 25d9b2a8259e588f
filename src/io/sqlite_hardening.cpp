#include "io/sqlite_hardening.hpp"

#include <algorithm>
#include <initializer_list>
#include <utility>

namespace keyplace {
namespace {

// SQLite calls the progress handler every this many virtual-machine instructions.
constexpr int kInstructionsPerProgressCall = 1000;
constexpr std::uint64_t kMinInstructions = 10'000'000;

int CountSteps(void* budget_pointer) {
  auto* budget = static_cast<StepBudget*>(budget_pointer);
  return ++budget->calls > budget->max_calls ? 1 : 0;
}

}  // namespace

bool HardenReadOnlyConnection(sqlite3* handle, std::uint64_t file_bytes,
                              std::uint64_t max_value_bytes,
                              std::uint64_t instructions_per_file_byte, StepBudget& budget) {
  for (const auto& [option, value] :
       {std::pair{SQLITE_DBCONFIG_ENABLE_VIEW, 0}, std::pair{SQLITE_DBCONFIG_ENABLE_TRIGGER, 0},
        std::pair{SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0}, std::pair{SQLITE_DBCONFIG_DEFENSIVE, 1},
        std::pair{SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION, 0}}) {
    if (sqlite3_db_config(handle, option, value, nullptr) != SQLITE_OK) return false;
  }
  // No value read from a file can be longer than the file (64 KiB leave room for values the
  // queries make).
  const std::uint64_t max_length = std::min<std::uint64_t>(
      {std::max<std::uint64_t>(file_bytes, 1 << 16), max_value_bytes, 1'000'000'000});
  sqlite3_limit(handle, SQLITE_LIMIT_LENGTH, static_cast<int>(max_length));
  sqlite3_limit(handle, SQLITE_LIMIT_ATTACHED, 0);
  sqlite3_limit(handle, SQLITE_LIMIT_WORKER_THREADS, 0);
  sqlite3_limit(handle, SQLITE_LIMIT_COLUMN, 100);
  sqlite3_limit(handle, SQLITE_LIMIT_EXPR_DEPTH, 100);
  sqlite3_limit(handle, SQLITE_LIMIT_COMPOUND_SELECT, 10);
  budget.calls = 0;
  budget.max_calls = std::max(kMinInstructions, instructions_per_file_byte * file_bytes) /
                     kInstructionsPerProgressCall;
  sqlite3_progress_handler(handle, kInstructionsPerProgressCall, CountSteps, &budget);
  return sqlite3_exec(handle,
                      "PRAGMA query_only = ON; PRAGMA trusted_schema = OFF; "
                      "PRAGMA cell_size_check = ON;",
                      nullptr, nullptr, nullptr) == SQLITE_OK;
}

}  // namespace keyplace
