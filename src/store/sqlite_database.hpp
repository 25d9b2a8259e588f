#pragma once
// Internal: an SQLite connection and statement whose errors name the map file they belong to.

#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace keyplace {

class Database {
 public:
  Database(const std::string& filename, int flags, std::string display_path)
      : display_path_(std::move(display_path)) {
    if (sqlite3_open_v2(filename.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw std::runtime_error(display_path_ + ": cannot open map file: " + message);
    }
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  [[noreturn]] void Fail(const std::string& what) const {
    if (sqlite3_errcode(db_) == SQLITE_INTERRUPT) {
      throw std::runtime_error(display_path_ + ": " + what +
                               ": reading needed more SQLite steps than a map file of this size "
                               "can (hostile or damaged file)");
    }
    throw std::runtime_error(display_path_ + ": " + what + ": " + sqlite3_errmsg(db_));
  }

  void Execute(const char* sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
      const std::string message = error != nullptr ? error : "unknown error";
      sqlite3_free(error);
      throw std::runtime_error(display_path_ + ": " + message);
    }
  }

  sqlite3* get() const { return db_; }
  const std::string& display_path() const { return display_path_; }

 private:
  sqlite3* db_ = nullptr;
  std::string display_path_;
};

class Statement {
 public:
  Statement(const Database& db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db.get(), sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) {
      db.Fail("cannot prepare '" + sql + "'");
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& Bind(int index, double value) {
    Check(sqlite3_bind_double(statement_, index, value));
    return *this;
  }
  Statement& Bind(int index, std::int64_t value) {
    Check(sqlite3_bind_int64(statement_, index, value));
    return *this;
  }
  Statement& Bind(int index, int value) { return Bind(index, static_cast<std::int64_t>(value)); }
  Statement& Bind(int index, const std::string& value) {
    Check(sqlite3_bind_text(statement_, index, value.c_str(), static_cast<int>(value.size()),
                            SQLITE_TRANSIENT));
    return *this;
  }
  Statement& BindBlob(int index, const void* data, std::size_t size) {
    Check(sqlite3_bind_blob(statement_, index, data, static_cast<int>(size), SQLITE_TRANSIENT));
    return *this;
  }

  // Runs an INSERT/UPDATE to completion and resets for the next row.
  void Run() {
    if (sqlite3_step(statement_) != SQLITE_DONE) db_.Fail("write failed");
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }

  // Next result row of a query; false at the end.
  bool Step() {
    const int code = sqlite3_step(statement_);
    if (code == SQLITE_ROW) return true;
    if (code == SQLITE_DONE) return false;
    db_.Fail("read failed (truncated or corrupt map file?)");
  }

  int Type(int column) const { return sqlite3_column_type(statement_, column); }
  double Double(int column) const { return sqlite3_column_double(statement_, column); }
  std::int64_t Int(int column) const { return sqlite3_column_int64(statement_, column); }
  std::string Text(int column) const {
    const auto* text = sqlite3_column_text(statement_, column);
    return text != nullptr ? reinterpret_cast<const char*>(text) : "";
  }
  // The bytes stay valid until the next Step.
  std::pair<const unsigned char*, std::size_t> Bytes(int column) const {
    const auto* data = static_cast<const unsigned char*>(sqlite3_column_blob(statement_, column));
    const int size = sqlite3_column_bytes(statement_, column);
    return {data, data != nullptr ? static_cast<std::size_t>(size) : 0};
  }

 private:
  void Check(int code) const {
    if (code != SQLITE_OK) db_.Fail("cannot bind a value");
  }
  const Database& db_;
  sqlite3_stmt* statement_ = nullptr;
};

}  // namespace keyplace
