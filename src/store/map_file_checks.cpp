#include "store/map_file_checks.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "io/sqlite_hardening.hpp"
#include "io/sqlite_magic.hpp"
#include "store/map_schema.hpp"

namespace keyplace {
namespace {

// Instructions a load may spend per byte of file: loading the bundled FR079 map (1.5 MB) takes
// 0.37 M instructions, 0.24 per byte (SQLite's integrity check is one instruction).
constexpr std::uint64_t kInstructionsPerFileByte = 64;

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
    db.Execute(kMapSchema);
    ReferenceSchema schema;
    schema.objects = ReadSchemaObjects(db);
    for (const MapTableKey& table : kMapTables)
      schema.columns[table.name] = ReadColumns(db, table.name);
    return schema;
  }();
  return reference;
}

bool IsMapTable(const std::string& name) {
  return std::any_of(kMapTables.begin(), kMapTables.end(),
                     [&](const MapTableKey& table) { return name == table.name; });
}

}  // namespace

// The parts of the SQLite header (sqlite.org/fileformat.html) that keep a damaged or truncated
// file from reaching SQLite, and files in write-ahead-log mode from creating -wal / -shm files.
MapFileFacts CheckMapFileHeader(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw std::runtime_error(path + ": map file not found");
  }
  // SQLite seeks through the file, and the checks read it more than once: a pipe cannot do that.
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(path +
                             ": map files must be regular files (not a pipe, FIFO or device); "
                             "copy it to a file first");
  }
  MapFileFacts facts;
  facts.bytes = std::filesystem::file_size(path, error);
  if (error) throw std::runtime_error(path + ": cannot read the map file's size");
  std::array<unsigned char, kSqliteHeaderBytes> header{};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(header.data()), header.size());
  if (in.gcount() != static_cast<std::streamsize>(header.size()) ||
      !StartsWithSqliteMagic(header.data(), header.size())) {
    throw std::runtime_error(path + ": not a keyplace map file (not an SQLite database)");
  }
  const SqliteHeaderSize header_size = ReadSqliteHeaderSize(header.data());
  facts.page_bytes = header_size.page_bytes;
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
  const std::uint32_t header_pages = header_size.pages;
  if (header_pages != 0 && std::uint64_t{header_pages} * facts.page_bytes != facts.bytes) {
    throw std::runtime_error(path + ": truncated or damaged map file: its header counts " +
                             std::to_string(header_pages) + " pages of " +
                             std::to_string(facts.page_bytes) + " bytes, the file holds " +
                             std::to_string(facts.bytes) + " bytes");
  }
  return facts;
}

// An SQLite URI that opens `path` read-only and immutable: no lock, no journal and no -wal/-shm
// file is read or created, so a hot journal beside a map cannot make a read write the map.
std::string ImmutableMapUri(const std::string& path) {
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

// Settings made before the schema is first read, so that no part of a hostile file runs:
// views and triggers disabled, functions in the schema untrusted, no writes, bounded values.
void HardenMapConnection(Database& db, std::uint64_t file_bytes, StepBudget& budget) {
  if (!HardenReadOnlyConnection(db.get(), file_bytes, 1'000'000'000, kInstructionsPerFileByte,
                                budget)) {
    db.Fail("cannot configure SQLite");
  }
}

void CheckMapSchema(const Database& db) {
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
  constexpr const char* hint =
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
  for (const MapTableKey& table : kMapTables) {
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

void CheckMapIntegrity(const Database& db) {
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

}  // namespace keyplace
