#include "keyplace/store/map_file.hpp"

#include <sqlite3.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"

namespace keyplace {
namespace {

constexpr const char* kFormatName = "keyplace-map";

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

class Database {
 public:
  Database(const std::string& path, int flags, std::string display_path)
      : display_path_(std::move(display_path)) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
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
  Statement(const Database& db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db.get(), sql, -1, &statement_, nullptr) != SQLITE_OK) {
      db.Fail(std::string("cannot prepare '") + sql + "'");
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

  double Double(int column) const { return sqlite3_column_double(statement_, column); }
  std::int64_t Int(int column) const { return sqlite3_column_int64(statement_, column); }
  std::string Text(int column) const {
    const auto* text = sqlite3_column_text(statement_, column);
    return text != nullptr ? reinterpret_cast<const char*>(text) : "";
  }
  std::vector<unsigned char> Blob(int column) const {
    const auto* data = static_cast<const unsigned char*>(sqlite3_column_blob(statement_, column));
    const int size = sqlite3_column_bytes(statement_, column);
    return data != nullptr ? std::vector<unsigned char>(data, data + size)
                           : std::vector<unsigned char>();
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

std::vector<Eigen::Vector2i> UnpackOccupancy(const std::vector<unsigned char>& packed,
                                             std::int64_t cell_count, const std::string& where) {
  if (cell_count < 0 || cell_count > (1LL << 28)) {
    throw std::runtime_error(where + ": implausible occupancy cell count");
  }
  std::vector<std::int32_t> raw(static_cast<std::size_t>(cell_count) * 2);
  uLongf raw_bytes = static_cast<uLongf>(raw.size() * sizeof(std::int32_t));
  const uLongf expected = raw_bytes;
  if (!packed.empty() || cell_count > 0) {
    if (uncompress(reinterpret_cast<Bytef*>(raw.data()), &raw_bytes, packed.data(),
                   static_cast<uLong>(packed.size())) != Z_OK ||
        raw_bytes != expected) {
      throw std::runtime_error(where + ": corrupt occupancy data");
    }
  }
  std::vector<Eigen::Vector2i> cells;
  cells.reserve(static_cast<std::size_t>(cell_count));
  for (std::size_t k = 0; k + 1 < raw.size(); k += 2) cells.emplace_back(raw[k], raw[k + 1]);
  return cells;
}

void WriteAll(Database& db, const GlobalMap& map) {
  db.Execute("PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;");
  db.Execute("BEGIN;");
  db.Execute(kSchema);
  {
    Statement meta(db, "INSERT INTO meta (key, value) VALUES (?, ?)");
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
  db.Execute("COMMIT;");
}

}  // namespace

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

GlobalMap LoadMap(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error(path + ": map file not found");
  }
  Database db(path, SQLITE_OPEN_READONLY, path);
  GlobalMap map;
  std::map<std::string, std::string> meta;
  try {
    Statement query(db, "SELECT key, value FROM meta");
    while (query.Step()) meta[query.Text(0)] = query.Text(1);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(path + ": not a keyplace map file (" + error.what() + ")");
  }
  if (meta["format"] != kFormatName) throw std::runtime_error(path + ": not a keyplace map file");
  if (meta["schema_version"] != std::to_string(kMapFileSchemaVersion)) {
    throw std::runtime_error(path + ": map schema version " + meta["schema_version"] +
                             " is not supported (this keyplace reads version " +
                             std::to_string(kMapFileSchemaVersion) + ")");
  }
  {
    Statement check(db, "PRAGMA quick_check");
    while (check.Step()) {
      if (check.Text(0) != "ok") {
        throw std::runtime_error(path + ": corrupt map file: " + check.Text(0));
      }
    }
  }
  map.source_log = meta["source_log"];
  map.source_hash = meta["source_hash"];
  map.pose_source = meta["pose_source"];
  map.configuration = meta["configuration"];
  try {
    map.source_scans = std::stoull(meta.at("source_scans"));
    map.source_keypoints = std::stoull(meta.at("source_keypoints"));
  } catch (const std::exception&) {
    throw std::runtime_error(path + ": meta table lacks source_scans/source_keypoints");
  }
  {
    std::map<std::string, std::string> config;
    Statement query(db, "SELECT key, value FROM config");
    while (query.Step()) config[query.Text(0)] = query.Text(1);
    try {
      ApplyKeyValues(config, map.config);
    } catch (const std::invalid_argument& error) {
      throw std::runtime_error(path + ": " + error.what());
    }
  }
  std::map<std::int64_t, std::size_t> index_of_id;
  {
    Statement query(db,
                    "SELECT id, overlap, distribution, forced, occupancy_cell_m, occupancy_cells, "
                    "occupancy FROM submaps ORDER BY id");
    while (query.Step()) {
      Submap submap;
      submap.id = static_cast<int>(query.Int(0));
      submap.overlap = query.Double(1);
      submap.distribution = query.Double(2);
      submap.forced = query.Int(3) != 0;
      submap.occupancy.cell_size_m = query.Double(4);
      submap.occupancy.cells = UnpackOccupancy(query.Blob(6), query.Int(5),
                                               path + ": submap " + std::to_string(submap.id));
      index_of_id[submap.id] = map.submaps.size();
      map.submaps.push_back(std::move(submap));
    }
  }
  const auto submap_of = [&](std::int64_t id, const char* table) -> Submap& {
    const auto it = index_of_id.find(id);
    if (it == index_of_id.end()) {
      throw std::runtime_error(path + ": " + table + " row refers to missing submap " +
                               std::to_string(id));
    }
    return map.submaps[it->second];
  };
  {
    Statement query(db,
                    "SELECT submap_id, scan_index, x, y, theta FROM poses ORDER BY submap_id, seq");
    while (query.Step()) {
      Submap& submap = submap_of(query.Int(0), "poses");
      submap.scan_indices.push_back(static_cast<int>(query.Int(1)));
      submap.poses.emplace_back(query.Double(2), query.Double(3), query.Double(4));
    }
  }
  {
    Statement query(db,
                    "SELECT submap_id, x, y, orientation, scale, level, scan_index, stability, "
                    "occurrences, descriptor FROM keypoints ORDER BY submap_id, seq");
    while (query.Step()) {
      Submap& submap = submap_of(query.Int(0), "keypoints");
      StableKeypoint keypoint;
      keypoint.position_m = {query.Double(1), query.Double(2)};
      keypoint.orientation_rad = query.Double(3);
      keypoint.scale_m = query.Double(4);
      keypoint.scale_level = static_cast<int>(query.Int(5));
      keypoint.scan_index = static_cast<int>(query.Int(6));
      keypoint.stability = static_cast<float>(query.Double(7));
      keypoint.occurrences = static_cast<int>(query.Int(8));
      const std::vector<unsigned char> descriptor = query.Blob(9);
      if (descriptor.size() != sizeof(keypoint.descriptor)) {
        throw std::runtime_error(path + ": keypoint of submap " + std::to_string(submap.id) +
                                 " has a descriptor of " + std::to_string(descriptor.size()) +
                                 " bytes, expected " + std::to_string(sizeof(keypoint.descriptor)));
      }
      std::memcpy(keypoint.descriptor.data(), descriptor.data(), descriptor.size());
      submap.keypoints.push_back(keypoint);
    }
  }
  for (const Submap& submap : map.submaps) {
    if (submap.poses.empty()) {
      throw std::runtime_error(path + ": submap " + std::to_string(submap.id) + " has no poses");
    }
  }
  return map;
}

}  // namespace keyplace
