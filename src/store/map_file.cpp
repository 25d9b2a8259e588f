#include "keyplace/store/map_file.hpp"

#include <sqlite3.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "io/atomic_file.hpp"
#include "store/map_checksum.hpp"

namespace keyplace {
namespace {

constexpr const char* kFormatName = "keyplace-map";
// Version 1 has the same tables and no content checksum; it is still read.
constexpr int kOldestReadableVersion = 1;

constexpr const char* kSchema = R"sql(
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
struct TableKey {
  const char* name;
  const char* order_by;
};
constexpr std::array<TableKey, 5> kTables = {{{"meta", "key"},
                                              {"config", "key"},
                                              {"submaps", "id"},
                                              {"poses", "submap_id, seq"},
                                              {"keypoints", "submap_id, seq"}}};

// deflate expands at most 1032:1 (a 258-byte match per ~2-bit code); zlib adds 6 bytes.
constexpr std::uint64_t kMaxDeflateRatio = 1032;
// SQLite calls the progress handler every this many virtual-machine instructions.
constexpr int kInstructionsPerProgressCall = 1000;
// Instructions a load may spend per byte of file, and at least: a safety net that ends a runaway
// query should the schema check ever let one through. Loading the bundled FR079 map (1.5 MB)
// takes 0.37 M instructions, 0.24 per byte (SQLite's integrity check is one instruction).
constexpr std::uint64_t kInstructionsPerFileByte = 64;
constexpr std::uint64_t kMinInstructions = 10'000'000;

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

// Little-endian packing (the only byte order keyplace runs on; checked at compile time).
static_assert(sizeof(float) == 4, "float32 expected");

std::vector<unsigned char> PackOccupancy(const OccupancySummary& occupancy) {
  std::vector<std::int32_t> raw;
  raw.reserve(occupancy.cells.size() * 2);
  for (const auto& cell : occupancy.cells) {
    raw.push_back(cell.x());
    raw.push_back(cell.y());
  }
  const auto raw_bytes = static_cast<uLong>(raw.size() * sizeof(std::int32_t));
  uLongf packed_size = compressBound(raw_bytes);
  std::vector<unsigned char> packed(packed_size);
  if (compress2(packed.data(), &packed_size, reinterpret_cast<const Bytef*>(raw.data()), raw_bytes,
                6) != Z_OK) {
    throw std::runtime_error("occupancy compression failed");
  }
  packed.resize(packed_size);
  return packed;
}

class Fnv1a64 {
 public:
  void Bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < size; ++k) {
      state_ ^= bytes[k];
      state_ *= kPrime;
    }
  }
  // Fixed width and byte order, so that the checksum does not depend on the machine.
  void Uint64(std::uint64_t value) {
    std::array<unsigned char, 8> little_endian{};
    for (std::size_t k = 0; k < little_endian.size(); ++k) {
      little_endian[k] = static_cast<unsigned char>(value >> (8 * k));
    }
    Bytes(little_endian.data(), little_endian.size());
  }
  std::uint64_t value() const { return state_; }

 private:
  static constexpr std::uint64_t kOffsetBasis = 14695981039346656037ULL;
  static constexpr std::uint64_t kPrime = 1099511628211ULL;
  std::uint64_t state_ = kOffsetBasis;
};

std::string Hex64(std::uint64_t value) {
  std::array<char, 17> text{};
  std::snprintf(text.data(), text.size(), "%016llx", static_cast<unsigned long long>(value));
  return text.data();
}

// ---------------------------------------------------------------------------------------------
// Reading. Everything in the file is checked before it is used: the SQLite header against the
// file size, the schema against the one SaveMap writes (so that no view, trigger or virtual
// table of a hostile file is ever run), SQLite's integrity check, the version, the checksum, the
// stored configuration, and then every value and blob of every row.

std::uint32_t BigEndian(const unsigned char* bytes, int count) {
  std::uint32_t value = 0;
  for (int k = 0; k < count; ++k) value = (value << 8) | bytes[k];
  return value;
}

struct FileFacts {
  std::uint64_t bytes = 0;
  std::uint32_t page_bytes = 0;
};

// The parts of the SQLite header (sqlite.org/fileformat.html) that keep a damaged or truncated
// file from reaching SQLite, and files in write-ahead-log mode from creating -wal / -shm files.
FileFacts CheckFileHeader(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(path + ": map file not found (or not a regular file)");
  }
  FileFacts facts;
  facts.bytes = std::filesystem::file_size(path, error);
  if (error) throw std::runtime_error(path + ": cannot read the map file's size");
  std::array<unsigned char, 100> header{};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(header.data()), header.size());
  if (in.gcount() != static_cast<std::streamsize>(header.size()) ||
      std::memcmp(header.data(), "SQLite format 3", 16) != 0) {
    throw std::runtime_error(path + ": not a keyplace map file (not an SQLite database)");
  }
  const std::uint32_t page_field = BigEndian(&header[16], 2);
  facts.page_bytes = page_field == 1 ? 65536 : page_field;
  if (facts.page_bytes < 512 || (facts.page_bytes & (facts.page_bytes - 1)) != 0) {
    throw std::runtime_error(path + ": damaged map file: page size " +
                             std::to_string(facts.page_bytes) + " in the SQLite header");
  }
  if (header[18] != 1 || header[19] != 1) {
    throw std::runtime_error(path +
                             ": not a map file keyplace wrote: SQLite file format versions " +
                             std::to_string(header[18]) + "/" + std::to_string(header[19]) +
                             " (keyplace writes 1/1, rollback journal; 2/2 is write-ahead log)");
  }
  if (facts.bytes % facts.page_bytes != 0) {
    throw std::runtime_error(
        path + ": truncated or damaged map file: " + std::to_string(facts.bytes) +
        " bytes is not a whole number of " + std::to_string(facts.page_bytes) + "-byte pages");
  }
  const std::uint32_t change_counter = BigEndian(&header[24], 4);
  const std::uint32_t header_pages = BigEndian(&header[28], 4);
  const std::uint32_t valid_for = BigEndian(&header[92], 4);
  // The page count in the header is valid only when written with the current change counter.
  if (valid_for == change_counter && header_pages != 0 &&
      std::uint64_t{header_pages} * facts.page_bytes != facts.bytes) {
    throw std::runtime_error(path + ": truncated or damaged map file: its header counts " +
                             std::to_string(header_pages) + " pages of " +
                             std::to_string(facts.page_bytes) + " bytes, the file holds " +
                             std::to_string(facts.bytes) + " bytes");
  }
  return facts;
}

// An SQLite URI that opens `path` read-only and immutable: no lock, no journal and no -wal/-shm
// file is read or created, so a hot journal beside a map cannot make a read write the map.
std::string ImmutableUri(const std::string& path) {
  static constexpr std::string_view kPlain = "/-._~";
  std::string uri = "file://";  // empty authority, then the absolute path
  for (const char c : std::filesystem::absolute(path).string()) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte >= 'a' && byte <= 'z') || (byte >= 'A' && byte <= 'Z') ||
        (byte >= '0' && byte <= '9') || kPlain.find(c) != std::string_view::npos) {
      uri += c;
    } else {
      std::array<char, 4> escaped{};
      std::snprintf(escaped.data(), escaped.size(), "%%%02X", byte);
      uri += escaped.data();
    }
  }
  return uri + "?immutable=1";
}

struct StepBudget {
  std::uint64_t calls = 0;
  std::uint64_t max_calls = 0;
};

int CountSteps(void* budget_pointer) {
  auto* budget = static_cast<StepBudget*>(budget_pointer);
  return ++budget->calls > budget->max_calls ? 1 : 0;
}

// Settings made before the schema is first read, so that no part of a hostile file runs:
// views and triggers disabled, functions in the schema untrusted, no writes, bounded values.
void HardenConnection(Database& db, std::uint64_t file_bytes, StepBudget& budget) {
  sqlite3* handle = db.get();
  for (const auto& [option, value] :
       {std::pair{SQLITE_DBCONFIG_ENABLE_VIEW, 0}, std::pair{SQLITE_DBCONFIG_ENABLE_TRIGGER, 0},
        std::pair{SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0}, std::pair{SQLITE_DBCONFIG_DEFENSIVE, 1},
        std::pair{SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION, 0}}) {
    if (sqlite3_db_config(handle, option, value, nullptr) != SQLITE_OK) {
      db.Fail("cannot configure SQLite");
    }
  }
  // No value read from a file can be longer than the file.
  const auto max_length = static_cast<int>(
      std::min<std::uint64_t>(std::max<std::uint64_t>(file_bytes, 1 << 16), 1'000'000'000));
  sqlite3_limit(handle, SQLITE_LIMIT_LENGTH, max_length);
  sqlite3_limit(handle, SQLITE_LIMIT_ATTACHED, 0);
  sqlite3_limit(handle, SQLITE_LIMIT_WORKER_THREADS, 0);
  sqlite3_limit(handle, SQLITE_LIMIT_COLUMN, 100);
  sqlite3_limit(handle, SQLITE_LIMIT_EXPR_DEPTH, 100);
  sqlite3_limit(handle, SQLITE_LIMIT_COMPOUND_SELECT, 10);
  budget.max_calls = std::max(kMinInstructions, kInstructionsPerFileByte * file_bytes) /
                     kInstructionsPerProgressCall;
  sqlite3_progress_handler(handle, kInstructionsPerProgressCall, CountSteps, &budget);
  db.Execute("PRAGMA query_only = ON; PRAGMA trusted_schema = OFF; PRAGMA cell_size_check = ON;");
}

struct SchemaObject {
  std::string type;
  std::string name;
  std::string table;
  std::string sql;
  bool operator==(const SchemaObject& other) const {
    return std::tie(type, name, table, sql) ==
           std::tie(other.type, other.name, other.table, other.sql);
  }
};

struct Column {
  std::string name;
  std::string type;
  std::int64_t not_null = 0;
  std::int64_t primary_key = 0;
  std::int64_t hidden = 0;  // 2 and 3: generated columns
  bool operator==(const Column& other) const {
    return std::tie(name, type, not_null, primary_key, hidden) ==
           std::tie(other.name, other.type, other.not_null, other.primary_key, other.hidden);
  }
};

std::vector<SchemaObject> ReadSchemaObjects(const Database& db) {
  std::vector<SchemaObject> objects;
  Statement query(db, "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name");
  while (query.Step()) {
    objects.push_back({query.Text(0), query.Text(1), query.Text(2), query.Text(3)});
  }
  return objects;
}

// Only called for names of kTables after they were found to be ordinary tables: a view's or a
// virtual table's columns would need its query or module.
std::vector<Column> ReadColumns(const Database& db, const std::string& table) {
  std::vector<Column> columns;
  Statement query(db, "PRAGMA table_xinfo(" + table + ")");
  while (query.Step()) {
    columns.push_back({query.Text(1), query.Text(2), query.Int(3), query.Int(5), query.Int(6)});
  }
  return columns;
}

std::string Describe(const std::vector<Column>& columns) {
  std::string text;
  for (const Column& column : columns) {
    if (!text.empty()) text += ", ";
    text += column.name + " " + column.type;
    if (column.not_null != 0) text += " NOT NULL";
    if (column.primary_key != 0) text += " PRIMARY KEY";
    if (column.hidden != 0) text += " (hidden or generated)";
  }
  return text;
}

// The schema SaveMap writes, read back from an in-memory database built from kSchema: the
// expectation is the writer's own text, never a second copy of it.
struct ReferenceSchema {
  std::vector<SchemaObject> objects;
  std::map<std::string, std::vector<Column>> columns;
};

const ReferenceSchema& Reference() {
  static const ReferenceSchema reference = [] {
    Database db(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_MEMORY, "(map schema)");
    db.Execute(kSchema);
    ReferenceSchema schema;
    schema.objects = ReadSchemaObjects(db);
    for (const TableKey& table : kTables) schema.columns[table.name] = ReadColumns(db, table.name);
    return schema;
  }();
  return reference;
}

bool IsMapTable(const std::string& name) {
  return std::any_of(kTables.begin(), kTables.end(),
                     [&](const TableKey& table) { return name == table.name; });
}

void CheckSchema(const Database& db) {
  const std::string& path = db.display_path();
  const ReferenceSchema& reference = Reference();
  const std::vector<SchemaObject> objects = ReadSchemaObjects(db);
  const auto found = [&](const std::string& name) {
    return std::find_if(objects.begin(), objects.end(),
                        [&](const SchemaObject& object) { return object.name == name; });
  };
  if (found("meta") == objects.end()) {
    throw std::runtime_error(path + ": not a keyplace map file (no table meta)");
  }
  const std::string hint =
      " (a keyplace map holds only the tables meta, config, submaps, poses and keypoints and "
      "their primary-key indexes: a hostile or damaged file, not read further)";
  for (const SchemaObject& object : objects) {
    if (IsMapTable(object.name)) {
      if (object.type != "table") {
        throw std::runtime_error(path + ": '" + object.name + "' is a " + object.type +
                                 ", not a table" + hint);
      }
      if (object.sql.rfind("CREATE TABLE", 0) != 0) {
        throw std::runtime_error(path + ": table '" + object.name +
                                 "' is a virtual table, not an ordinary table" + hint);
      }
    } else if (std::find(reference.objects.begin(), reference.objects.end(), object) ==
               reference.objects.end()) {
      throw std::runtime_error(path + ": unexpected " + object.type + " '" + object.name + "'" +
                               hint);
    }
  }
  for (const TableKey& table : kTables) {
    if (found(table.name) == objects.end()) {
      throw std::runtime_error(path + ": table '" + std::string(table.name) + "' is missing");
    }
    const std::vector<Column> columns = ReadColumns(db, table.name);
    const std::vector<Column>& expected = reference.columns.at(table.name);
    if (columns != expected) {
      throw std::runtime_error(path + ": table '" + std::string(table.name) + "' has columns (" +
                               Describe(columns) + "), expected (" + Describe(expected) + ")");
    }
  }
  // Same columns, but constraints, defaults or collations may still differ: compare the text.
  for (const SchemaObject& object : reference.objects) {
    const auto it = found(object.name);
    if (it == objects.end() || !(*it == object)) {
      throw std::runtime_error(path + ": " + object.type + " '" + object.name +
                               "' is not defined as keyplace defines it" + hint);
    }
  }
}

void CheckIntegrity(const Database& db) {
  Statement check(db, "PRAGMA integrity_check(10)");
  std::string problems;
  while (check.Step()) {
    const std::string line = check.Text(0);
    if (line == "ok") continue;
    problems += (problems.empty() ? "" : "; ") + line;
  }
  if (!problems.empty()) {
    throw std::runtime_error(db.display_path() +
                             ": damaged map file: SQLite integrity check failed: " + problems);
  }
}

template <typename Integer>
bool ParseInteger(const std::string& text, Integer& value) {
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  return !text.empty() && result.ec == std::errc() && result.ptr == end;
}

// One row of a query, with the checks every value goes through: its storage class, finite
// numbers, integer ranges; an error names the file, table, row id and column.
class Row {
 public:
  Row(const Statement& query, const std::string& path, const char* table)
      : query_(query), path_(path), table_(table), rowid_(query.Int(0)) {}

  [[noreturn]] void Fail(const char* column, const std::string& problem) const {
    throw std::runtime_error(path_ + ": table " + table_ + ", row " + std::to_string(rowid_) +
                             ", column " + column + ": " + problem);
  }

  double Real(int index, const char* column) const {
    if (query_.Type(index) != SQLITE_FLOAT) Fail(column, "not a real number");
    const double value = query_.Double(index);
    if (!std::isfinite(value)) Fail(column, "not a finite number (" + std::to_string(value) + ")");
    return value;
  }
  std::int64_t Integer(int index, const char* column, std::int64_t min, std::int64_t max) const {
    if (query_.Type(index) != SQLITE_INTEGER) Fail(column, "not an integer");
    const std::int64_t value = query_.Int(index);
    if (value < min || value > max) {
      Fail(column, std::to_string(value) + " outside [" + std::to_string(min) + ", " +
                       std::to_string(max) + "]");
    }
    return value;
  }
  int Int(int index, const char* column) const {
    return static_cast<int>(Integer(index, column, 0, std::numeric_limits<int>::max()));
  }
  std::pair<const unsigned char*, std::size_t> Blob(int index, const char* column) const {
    if (query_.Type(index) != SQLITE_BLOB) Fail(column, "not a blob");
    return query_.Bytes(index);
  }
  std::string Text(int index, const char* column) const {
    if (query_.Type(index) != SQLITE_TEXT) Fail(column, "not text");
    return query_.Text(index);
  }

 private:
  const Statement& query_;
  const std::string& path_;
  const char* table_;
  std::int64_t rowid_;
};

// Streams the zlib blob into cells, checking as it goes, so that a blob that expands beyond its
// declared cells or repeats a cell (a zlib bomb is a long run of equal bytes) stops at once
// instead of after allocating what it expands to. SaveMap writes the cells of G row by row, so
// they are strictly increasing in (j, i).
std::vector<Eigen::Vector2i> InflateOccupancy(const Row& row, const unsigned char* packed,
                                              std::size_t packed_bytes,
                                              std::int64_t declared_cells) {
  constexpr std::size_t kCellBytes = 2 * sizeof(std::int32_t);
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) row.Fail("occupancy", "cannot start zlib");
  struct EndInflate {
    z_stream* stream;
    ~EndInflate() { inflateEnd(stream); }
  } end_inflate{&stream};
  stream.next_in = const_cast<Bytef*>(packed);  // zlib's API is not const-correct
  stream.avail_in = static_cast<uInt>(packed_bytes);
  std::vector<Eigen::Vector2i> cells;
  std::array<unsigned char, 8192 * kCellBytes> buffer{};
  std::size_t pending = 0;  // bytes of an incomplete cell at the front of the buffer
  for (;;) {
    stream.next_out = buffer.data() + pending;
    stream.avail_out = static_cast<uInt>(buffer.size() - pending);
    const int code = inflate(&stream, Z_NO_FLUSH);
    if (code != Z_OK && code != Z_STREAM_END) {
      row.Fail("occupancy", std::string("corrupt zlib data (") +
                                (stream.msg != nullptr ? stream.msg : "zlib error") + ")");
    }
    const std::size_t filled = buffer.size() - stream.avail_out;
    std::size_t offset = 0;
    for (; offset + kCellBytes <= filled; offset += kCellBytes) {
      if (static_cast<std::int64_t>(cells.size()) == declared_cells) {
        row.Fail("occupancy", "holds more than the " + std::to_string(declared_cells) +
                                  " cells of occupancy_cells");
      }
      std::array<std::int32_t, 2> ij{};
      std::memcpy(ij.data(), buffer.data() + offset, kCellBytes);
      if (!cells.empty()) {
        const Eigen::Vector2i& last = cells.back();
        if (ij[1] < last.y() || (ij[1] == last.y() && ij[0] <= last.x())) {
          row.Fail("occupancy", "cell " + std::to_string(cells.size()) + " (" +
                                    std::to_string(ij[0]) + ", " + std::to_string(ij[1]) +
                                    ") repeats or precedes the one before it (cells are stored "
                                    "once each, row by row)");
        }
      }
      cells.emplace_back(ij[0], ij[1]);
    }
    pending = filled - offset;
    std::memmove(buffer.data(), buffer.data() + offset, pending);
    if (code == Z_STREAM_END) break;
    if (filled == pending && stream.avail_in == 0) row.Fail("occupancy", "zlib data end early");
  }
  if (pending != 0) row.Fail("occupancy", "not a whole number of cells");
  if (stream.avail_in != 0) row.Fail("occupancy", "bytes after the end of the zlib data");
  if (static_cast<std::int64_t>(cells.size()) != declared_cells) {
    row.Fail("occupancy", "holds " + std::to_string(cells.size()) +
                              " cells, occupancy_cells says " + std::to_string(declared_cells));
  }
  return cells;
}

class MapReader {
 public:
  MapReader(const std::string& path, std::vector<std::string>* passed, int* schema_version)
      : path_(path), passed_(passed), schema_version_(schema_version) {}

  GlobalMap Read() {
    const FileFacts facts = CheckFileHeader(path_);
    file_bytes_ = facts.bytes;
    Passed("SQLite header: " + std::to_string(facts.bytes) + " bytes, " +
           std::to_string(facts.page_bytes) + "-byte pages, rollback journal");
    Database db(ImmutableUri(path_), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, path_);
    HardenConnection(db, file_bytes_, budget_);
    CheckSchema(db);
    Passed(
        "schema: the tables meta, config, submaps, poses and keypoints with their columns and "
        "declared types, no view, trigger or other object");
    CheckIntegrity(db);
    Passed("SQLite integrity_check: ok");
    GlobalMap map;
    const int version = ReadMeta(db, map);
    Passed("format " + std::string(kFormatName) + ", version " + std::to_string(version));
    CheckChecksum(db, version);
    ReadConfig(db, map);
    Passed("mapping configuration (table config) valid");
    ReadRows(db, map);
    return map;
  }

 private:
  void Passed(std::string what) {
    if (passed_ != nullptr) passed_->push_back(std::move(what));
  }
  [[noreturn]] void Fail(const std::string& problem) const {
    throw std::runtime_error(path_ + ": " + problem);
  }

  int ReadMeta(const Database& db, GlobalMap& map) {
    Statement query(db, "SELECT rowid, key, value FROM meta ORDER BY key");
    while (query.Step()) {
      const Row row(query, path_, "meta");
      meta_[row.Text(1, "key")] = row.Text(2, "value");
    }
    if (meta_["format"] != kFormatName) Fail("not a keyplace map file (meta format)");
    int version = 0;
    if (!ParseInteger(meta_["schema_version"], version) || version < kOldestReadableVersion) {
      Fail("unknown map schema version '" + meta_["schema_version"] + "'");
    }
    if (schema_version_ != nullptr) *schema_version_ = version;
    if (version > kMapFileSchemaVersion) {
      Fail("map schema version " + std::to_string(version) +
           " is not supported: written by a newer keyplace (this keyplace reads versions " +
           std::to_string(kOldestReadableVersion) + " to " + std::to_string(kMapFileSchemaVersion) +
           ")");
    }
    map.source_log = meta_["source_log"];
    map.source_hash = meta_["source_hash"];
    map.pose_source = meta_["pose_source"];
    map.configuration = meta_["configuration"];
    if (!ParseInteger(meta_["source_scans"], map.source_scans) ||
        !ParseInteger(meta_["source_keypoints"], map.source_keypoints)) {
      Fail("meta table lacks valid source_scans/source_keypoints");
    }
    return version;
  }

  void CheckChecksum(const Database& db, int version) {
    if (version < 2) {
      Passed("no content checksum: a version " + std::to_string(version) +
             " map, written before checksums (keyplace map writes one)");
      return;
    }
    const auto stored = meta_.find(kMapChecksumKey);
    if (stored == meta_.end()) Fail("damaged map file: no content checksum in table meta");
    std::string computed;
    try {
      computed = MapContentChecksum(db.get());
    } catch (const std::runtime_error& error) {
      Fail(std::string("cannot compute the content checksum: ") + error.what());
    }
    if (computed != stored->second) {
      Fail("content checksum mismatch (stored " + stored->second + ", content " + computed +
           "): the map was changed or damaged after keyplace wrote it");
    }
    Passed("content checksum " + computed);
  }

  void ReadConfig(const Database& db, GlobalMap& map) {
    std::map<std::string, std::string> config;
    Statement query(db, "SELECT rowid, key, value FROM config ORDER BY key");
    while (query.Step()) {
      const Row row(query, path_, "config");
      config[row.Text(1, "key")] = row.Text(2, "value");
    }
    try {
      ApplyKeyValues(config, map.config);
    } catch (const std::invalid_argument& error) {
      Fail(std::string("table config: ") + error.what());
    }
  }

  // Rows of `table` checked against what a file of this size can hold, before any allocation
  // sized by them (a record takes at least a few bytes of a page).
  std::size_t CountRows(const Database& db, const char* table) const {
    Statement query(db, std::string("SELECT count(*) FROM ") + table);
    const std::uint64_t rows = query.Step() ? static_cast<std::uint64_t>(query.Int(0)) : 0;
    if (rows > file_bytes_ / 4) {
      Fail(std::string("table ") + table + " counts " + std::to_string(rows) +
           " rows, more than a file of " + std::to_string(file_bytes_) + " bytes can hold");
    }
    return static_cast<std::size_t>(rows);
  }

  void ReadRows(const Database& db, GlobalMap& map) {
    constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
    map.submaps.reserve(CountRows(db, "submaps"));
    const std::size_t pose_rows = CountRows(db, "poses");
    const std::size_t keypoint_rows = CountRows(db, "keypoints");
    std::map<std::int64_t, std::size_t> index_of_id;
    std::uint64_t occupancy_cells = 0;
    {
      Statement query(db,
                      "SELECT id, overlap, distribution, forced, occupancy_cell_m, "
                      "occupancy_cells, occupancy FROM submaps ORDER BY id");
      while (query.Step()) {
        const Row row(query, path_, "submaps");
        Submap submap;
        submap.id = row.Int(0, "id");
        submap.overlap = row.Real(1, "overlap");
        submap.distribution = row.Real(2, "distribution");
        submap.forced = row.Integer(3, "forced", 0, 1) != 0;
        submap.occupancy.cell_size_m = row.Real(4, "occupancy_cell_m");
        if (submap.occupancy.cell_size_m < kMinCellSizeM ||
            submap.occupancy.cell_size_m > kMaxCellSizeM) {
          row.Fail("occupancy_cell_m", "outside [0.01, 10] m");
        }
        const std::int64_t cells =
            row.Integer(5, "occupancy_cells", 0, std::numeric_limits<std::int64_t>::max());
        // Checked before inflating: the cells are those of the submap's grid G, and what the
        // blob could expand to at zlib's best.
        if (cells > map.config.max_grid_cells) {
          row.Fail("occupancy_cells", std::to_string(cells) +
                                          " cells, more than the grid of a submap holds "
                                          "(max_grid_cells = " +
                                          std::to_string(map.config.max_grid_cells) + ")");
        }
        const auto [packed, packed_bytes] = row.Blob(6, "occupancy");
        if (static_cast<std::uint64_t>(cells) * 8 > kMaxDeflateRatio * (packed_bytes + 1)) {
          row.Fail("occupancy_cells",
                   std::to_string(cells) + " cells (" + std::to_string(cells * 8) +
                       " bytes) cannot come from a " + std::to_string(packed_bytes) +
                       "-byte zlib blob (zlib expands at most 1032:1)");
        }
        submap.occupancy.cells = InflateOccupancy(row, packed, packed_bytes, cells);
        occupancy_cells += submap.occupancy.cells.size();
        index_of_id[submap.id] = map.submaps.size();
        map.submaps.push_back(std::move(submap));
      }
    }
    const auto submap_of = [&](const Row& row, std::int64_t id) -> Submap& {
      const auto it = index_of_id.find(id);
      if (it == index_of_id.end()) row.Fail("submap_id", "no submap " + std::to_string(id));
      return map.submaps[it->second];
    };
    const auto check_seq = [](const Row& row, std::int64_t seq, std::size_t expected) {
      if (seq != static_cast<std::int64_t>(expected)) {
        row.Fail("seq", std::to_string(seq) + ", expected " + std::to_string(expected) +
                            " (a row is missing or repeated)");
      }
    };
    {
      Statement query(db,
                      "SELECT rowid, submap_id, seq, scan_index, x, y, theta FROM poses "
                      "ORDER BY submap_id, seq");
      while (query.Step()) {
        const Row row(query, path_, "poses");
        Submap& submap = submap_of(row, row.Integer(1, "submap_id", 0, kIntMax));
        check_seq(row, row.Integer(2, "seq", 0, kIntMax), submap.poses.size());
        submap.scan_indices.push_back(row.Int(3, "scan_index"));
        submap.poses.emplace_back(row.Real(4, "x"), row.Real(5, "y"), row.Real(6, "theta"));
      }
    }
    {
      Statement query(db,
                      "SELECT rowid, submap_id, seq, x, y, orientation, scale, level, scan_index, "
                      "stability, occurrences, descriptor FROM keypoints ORDER BY submap_id, seq");
      while (query.Step()) {
        const Row row(query, path_, "keypoints");
        Submap& submap = submap_of(row, row.Integer(1, "submap_id", 0, kIntMax));
        check_seq(row, row.Integer(2, "seq", 0, kIntMax), submap.keypoints.size());
        StableKeypoint keypoint;
        keypoint.position_m = {row.Real(3, "x"), row.Real(4, "y")};
        keypoint.orientation_rad = row.Real(5, "orientation");
        keypoint.scale_m = row.Real(6, "scale");
        keypoint.scale_level = row.Int(7, "level");
        keypoint.scan_index = row.Int(8, "scan_index");
        const double stability = row.Real(9, "stability");
        if (std::abs(stability) > std::numeric_limits<float>::max()) {
          row.Fail("stability", "beyond float range");
        }
        keypoint.stability = static_cast<float>(stability);
        keypoint.occurrences = row.Int(10, "occurrences");
        const auto [descriptor, descriptor_bytes] = row.Blob(11, "descriptor");
        if (descriptor_bytes != sizeof(keypoint.descriptor)) {
          row.Fail("descriptor", std::to_string(descriptor_bytes) + " bytes, expected " +
                                     std::to_string(sizeof(keypoint.descriptor)) + " (" +
                                     std::to_string(keypoint.descriptor.size()) + " float32)");
        }
        std::memcpy(keypoint.descriptor.data(), descriptor, descriptor_bytes);
        for (std::size_t bin = 0; bin < keypoint.descriptor.size(); ++bin) {
          if (!std::isfinite(keypoint.descriptor[bin])) {
            row.Fail("descriptor", "bin " + std::to_string(bin) + " is not a finite number");
          }
        }
        submap.keypoints.push_back(keypoint);
      }
    }
    for (const Submap& submap : map.submaps) {
      if (submap.poses.empty()) {
        Fail("submap " + std::to_string(submap.id) + " has no poses");
      }
    }
    Passed(std::to_string(map.submaps.size()) + " submaps, " + std::to_string(pose_rows) +
           " poses, " + std::to_string(keypoint_rows) + " keypoints, " +
           std::to_string(occupancy_cells) +
           " occupancy cells: every value finite and in range, every blob of its size");
  }

  const std::string& path_;
  std::vector<std::string>* passed_;
  int* schema_version_;
  std::uint64_t file_bytes_ = 0;
  StepBudget budget_;
  std::map<std::string, std::string> meta_;
};

// ---------------------------------------------------------------------------------------------
// Writing.

void WriteAll(Database& db, const GlobalMap& map) {
  db.Execute("PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;");
  db.Execute("BEGIN;");
  db.Execute(kSchema);
  Statement meta(db, "INSERT INTO meta (key, value) VALUES (?, ?)");
  {
    const std::vector<std::pair<std::string, std::string>> entries = {
        {"format", kFormatName},
        {"schema_version", std::to_string(kMapFileSchemaVersion)},
        {"source_log", map.source_log},
        {"source_hash", map.source_hash},
        {"pose_source", map.pose_source},
        {"source_scans", std::to_string(map.source_scans)},
        {"source_keypoints", std::to_string(map.source_keypoints)},
        {"configuration", map.configuration},
    };
    for (const auto& [key, value] : entries) meta.Bind(1, key).Bind(2, value).Run();
    Statement config(db, "INSERT INTO config (key, value) VALUES (?, ?)");
    for (const auto& [key, value] : ToKeyValues(map.config))
      config.Bind(1, key).Bind(2, value).Run();
  }
  Statement submap_row(db,
                       "INSERT INTO submaps (id, overlap, distribution, forced, occupancy_cell_m, "
                       "occupancy_cells, occupancy) VALUES (?, ?, ?, ?, ?, ?, ?)");
  Statement pose_row(db,
                     "INSERT INTO poses (submap_id, seq, scan_index, x, y, theta) "
                     "VALUES (?, ?, ?, ?, ?, ?)");
  Statement keypoint_row(db,
                         "INSERT INTO keypoints (submap_id, seq, x, y, orientation, scale, level, "
                         "scan_index, stability, occurrences, descriptor) "
                         "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const Submap& submap : map.submaps) {
    if (submap.poses.size() != submap.scan_indices.size()) {
      throw std::runtime_error(db.display_path() + ": submap " + std::to_string(submap.id) +
                               " has " + std::to_string(submap.poses.size()) + " poses for " +
                               std::to_string(submap.scan_indices.size()) + " scans");
    }
    const std::vector<unsigned char> occupancy = PackOccupancy(submap.occupancy);
    submap_row.Bind(1, submap.id)
        .Bind(2, submap.overlap)
        .Bind(3, submap.distribution)
        .Bind(4, submap.forced ? 1 : 0)
        .Bind(5, submap.occupancy.cell_size_m)
        .Bind(6, static_cast<std::int64_t>(submap.occupancy.cells.size()))
        .BindBlob(7, occupancy.data(), occupancy.size())
        .Run();
    for (std::size_t k = 0; k < submap.poses.size(); ++k) {
      pose_row.Bind(1, submap.id)
          .Bind(2, static_cast<std::int64_t>(k))
          .Bind(3, submap.scan_indices[k])
          .Bind(4, submap.poses[k].x)
          .Bind(5, submap.poses[k].y)
          .Bind(6, submap.poses[k].theta)
          .Run();
    }
    for (std::size_t k = 0; k < submap.keypoints.size(); ++k) {
      const StableKeypoint& keypoint = submap.keypoints[k];
      keypoint_row.Bind(1, submap.id)
          .Bind(2, static_cast<std::int64_t>(k))
          .Bind(3, keypoint.position_m.x())
          .Bind(4, keypoint.position_m.y())
          .Bind(5, keypoint.orientation_rad)
          .Bind(6, keypoint.scale_m)
          .Bind(7, keypoint.scale_level)
          .Bind(8, keypoint.scan_index)
          .Bind(9, static_cast<double>(keypoint.stability))
          .Bind(10, keypoint.occurrences)
          .BindBlob(11, keypoint.descriptor.data(), sizeof(keypoint.descriptor))
          .Run();
    }
  }
  // Computed from the rows as written, by the same code that checks them on reading.
  std::string checksum;
  try {
    checksum = MapContentChecksum(db.get());
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(db.display_path() + ": " + error.what());
  }
  meta.Bind(1, std::string(kMapChecksumKey)).Bind(2, checksum).Run();
  db.Execute("COMMIT;");
}

}  // namespace

std::string MapContentChecksum(sqlite3* db) {
  Fnv1a64 hash;
  for (const TableKey& table : kTables) {
    std::string sql = std::string("SELECT * FROM ") + table.name;
    if (std::string_view(table.name) == "meta") {
      sql += " WHERE key <> '" + std::string(kMapChecksumKey) + "'";
    }
    sql += std::string(" ORDER BY ") + table.order_by;
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("table ") + table.name + ": " + sqlite3_errmsg(db));
    }
    struct Finalize {
      sqlite3_stmt* statement;
      ~Finalize() { sqlite3_finalize(statement); }
    } finalize{statement};
    hash.Bytes(table.name, std::strlen(table.name) + 1);
    std::uint64_t rows = 0;
    int code = SQLITE_ROW;
    while ((code = sqlite3_step(statement)) == SQLITE_ROW) {
      ++rows;
      const int columns = sqlite3_column_count(statement);
      for (int column = 0; column < columns; ++column) {
        const int type = sqlite3_column_type(statement, column);
        hash.Uint64(static_cast<std::uint64_t>(type));
        if (type == SQLITE_INTEGER) {
          hash.Uint64(static_cast<std::uint64_t>(sqlite3_column_int64(statement, column)));
        } else if (type == SQLITE_FLOAT) {
          const double value = sqlite3_column_double(statement, column);
          std::uint64_t bits = 0;
          std::memcpy(&bits, &value, sizeof(bits));
          hash.Uint64(bits);
        } else if (type == SQLITE_TEXT || type == SQLITE_BLOB) {
          const void* data = type == SQLITE_TEXT
                                 ? static_cast<const void*>(sqlite3_column_text(statement, column))
                                 : sqlite3_column_blob(statement, column);
          const auto size = static_cast<std::size_t>(sqlite3_column_bytes(statement, column));
          hash.Uint64(size);
          if (size > 0) hash.Bytes(data, size);
        }
      }
    }
    if (code != SQLITE_DONE) {
      throw std::runtime_error(std::string("table ") + table.name + ": " + sqlite3_errmsg(db));
    }
    hash.Uint64(rows);
  }
  return "fnv1a64:" + Hex64(hash.value());
}

void SaveMap(const GlobalMap& map, const std::string& path) {
  const std::string temporary = TemporaryPathFor(path);
  std::error_code ignored;
  std::filesystem::remove(temporary, ignored);
  try {
    {
      Database db(temporary, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, path);
      // No journal and no syncing while writing: the file is new, and CommitTemporary syncs it
      // whole before the rename makes it the map.
      WriteAll(db, map);
    }
    CommitTemporary(temporary, path);
  } catch (...) {
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

GlobalMap LoadMap(const std::string& path) { return MapReader(path, nullptr, nullptr).Read(); }

MapFileCheck CheckMapFile(const std::string& path) {
  MapFileCheck check;
  try {
    check.map = MapReader(path, &check.passed, &check.schema_version).Read();
  } catch (const std::exception& error) {
    check.problem = error.what();
  }
  return check;
}

}  // namespace keyplace
