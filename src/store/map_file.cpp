#include "keyplace/store/map_file.hpp"

#include <sqlite3.h>
#include <zlib.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/bounded_read.hpp"
#include "keyplace/config/config.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "store/map_checksum.hpp"
#include "store/map_file_checks.hpp"
#include "store/map_schema.hpp"
#include "store/sqlite_database.hpp"

namespace keyplace {
namespace {

constexpr const char* kFormatName = "keyplace-map";
// Version 1 has the same tables and no content checksum; it is still read.
constexpr int kOldestReadableVersion = 1;

// Positions of poses and keypoints: the log readers' bound (CarmenReadOptions::max_coordinate_m,
// also the bags' reader), so that a map holds no place its inputs could not.
const double kMaxCoordinateM = CarmenReadOptions{}.max_coordinate_m;

// deflate expands at most 1032:1 (a 258-byte match per ~2-bit code); zlib adds 6 bytes.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

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

// ---------------------------------------------------------------------------------------------
// Reading. Everything in the file is checked before it is used: the SQLite header against the
// file size, the schema against the one SaveMap writes (so that no view, trigger or virtual
// table of a hostile file is ever run), SQLite's integrity check, the version, the checksum, the
// stored configuration, and then every value and blob of every row. The checks before the first
// row is read are in map_file_checks.cpp.

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
  // A position within the bound the log readers put on coordinates (CarmenReadOptions): a map
  // is made from them, so anything farther was written by something else.
  double Coordinate(int index, const char* column) const {
    const double value = Real(index, column);
    if (!(std::abs(value) <= kMaxCoordinateM)) {
      Fail(column, std::to_string(value) + " m lies beyond +-" + std::to_string(kMaxCoordinateM) +
                       " m (the bound of the log readers)");
    }
    return value;
  }
  double Angle(int index, const char* column) const {
    const double value = Real(index, column);
    if (!(std::abs(value) <= 2.0 * M_PI)) {
      Fail(column, std::to_string(value) + " rad is not an angle in [-2 pi, 2 pi]");
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
    const MapFileFacts facts = CheckMapFileHeader(path_);
    file_bytes_ = facts.bytes;
    Passed("SQLite header: " + std::to_string(facts.bytes) + " bytes, " +
           std::to_string(facts.page_bytes) + "-byte pages, rollback journal");
    Database db(ImmutableMapUri(path_), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, path_);
    HardenMapConnection(db, file_bytes_, budget_);
    CheckMapSchema(db);
    Passed(
        "schema: the tables meta, config, submaps, poses and keypoints with their columns and "
        "declared types, no view, trigger or other object");
    CheckMapIntegrity(db);
    Passed("SQLite integrity_check: ok");
    GlobalMap map;
    const int version = ReadMeta(db, map);
    Passed("format " + std::string(kFormatName) + ", version " + std::to_string(version));
    CheckChecksum(db, version);
    ReadConfig(db, map);
    Passed("mapping configuration (table config) valid");
    CheckRecordedConfiguration(map);
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
      ApplyStoredKeyValues(config, map.config);
    } catch (const std::invalid_argument& error) {
      Fail(std::string("table config: ") + error.what());
    }
  }

  // The whole configuration recorded as YAML (meta configuration) is checked as a --config file
  // would be, before any command uses or copies it (merge writes it into its result).
  void CheckRecordedConfiguration(const GlobalMap& map) {
    if (map.configuration.empty()) return;
    const std::string source = "recorded configuration (table meta)";
    if (map.configuration.size() > kMaxConfigFileBytes) {
      Fail(source + ": " + std::to_string(map.configuration.size()) + " bytes, more than the " +
           std::to_string(kMaxConfigFileBytes) + " of a configuration file");
    }
    try {
      Config whole;
      ApplyConfigYaml(map.configuration, source, whole);
    } catch (const std::invalid_argument& error) {
      Fail(error.what());
    }
    Passed("recorded configuration (table meta) valid");
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
    map.submaps.reserve(CountRows(db, "submaps"));
    const std::size_t pose_rows = CountRows(db, "poses");
    const std::size_t keypoint_rows = CountRows(db, "keypoints");
    const std::uint64_t occupancy_cells = ReadSubmaps(db, map);
    ReadPoses(db, map);
    ReadKeypoints(db, map);
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

  // The submaps table; returns the occupancy cells read.
  std::uint64_t ReadSubmaps(const Database& db, GlobalMap& map) {
    std::uint64_t occupancy_cells = 0;
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
        row.Fail("occupancy_cells", std::to_string(cells) + " cells (" + std::to_string(cells * 8) +
                                        " bytes) cannot come from a " +
                                        std::to_string(packed_bytes) +
                                        "-byte zlib blob (zlib expands at most 1032:1)");
      }
      submap.occupancy.cells = InflateOccupancy(row, packed, packed_bytes, cells);
      occupancy_cells += submap.occupancy.cells.size();
      index_of_id_[submap.id] = map.submaps.size();
      map.submaps.push_back(std::move(submap));
    }
    return occupancy_cells;
  }

  void ReadPoses(const Database& db, GlobalMap& map) {
    Statement query(db,
                    "SELECT rowid, submap_id, seq, scan_index, x, y, theta FROM poses "
                    "ORDER BY submap_id, seq");
    while (query.Step()) {
      const Row row(query, path_, "poses");
      Submap& submap = SubmapOf(row, map, row.Integer(1, "submap_id", 0, kIntMax));
      CheckSeq(row, row.Integer(2, "seq", 0, kIntMax), submap.poses.size());
      submap.scan_indices.push_back(row.Int(3, "scan_index"));
      submap.poses.emplace_back(row.Coordinate(4, "x"), row.Coordinate(5, "y"),
                                row.Angle(6, "theta"));
    }
  }

  void ReadKeypoints(const Database& db, GlobalMap& map) {
    Statement query(db,
                    "SELECT rowid, submap_id, seq, x, y, orientation, scale, level, scan_index, "
                    "stability, occurrences, descriptor FROM keypoints ORDER BY submap_id, seq");
    while (query.Step()) {
      const Row row(query, path_, "keypoints");
      Submap& submap = SubmapOf(row, map, row.Integer(1, "submap_id", 0, kIntMax));
      CheckSeq(row, row.Integer(2, "seq", 0, kIntMax), submap.keypoints.size());
      StableKeypoint keypoint;
      keypoint.position_m = {row.Coordinate(3, "x"), row.Coordinate(4, "y")};
      keypoint.orientation_rad = row.Angle(5, "orientation");
      keypoint.scale_m = row.Real(6, "scale");
      if (!(keypoint.scale_m > 0.0)) row.Fail("scale", "not positive");
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
      CheckHistogram(row, keypoint.descriptor);
      submap.keypoints.push_back(keypoint);
    }
  }

  // A descriptor is a histogram: finite bins >= 0 (the descriptor index's bound H <= 2 chi2 holds
  // for those only) that sum to 1 (BetaGridDescriptor normalises them; all zeros is no histogram).
  static void CheckHistogram(const Row& row, const BetaGridDescriptor& descriptor) {
    double sum = 0.0;
    for (std::size_t bin = 0; bin < descriptor.size(); ++bin) {
      if (!std::isfinite(descriptor[bin])) {
        row.Fail("descriptor", "bin " + std::to_string(bin) + " is not a finite number");
      }
      // Histograms: the descriptor index's bound (H <= 2 chi2) holds for bins >= 0 only.
      if (descriptor[bin] < 0.0f) {
        row.Fail("descriptor", "bin " + std::to_string(bin) + " is negative");
      }
      sum += descriptor[bin];
    }
    // float rounding of 100 bins that sum to 1 stays far below 1e-3.
    if (!(std::abs(sum - 1.0) <= 1e-3)) {
      row.Fail("descriptor", "bins sum to " + std::to_string(sum) + ", not 1 (not a histogram)");
    }
  }

  Submap& SubmapOf(const Row& row, GlobalMap& map, std::int64_t id) const {
    const auto it = index_of_id_.find(id);
    if (it == index_of_id_.end()) row.Fail("submap_id", "no submap " + std::to_string(id));
    return map.submaps[it->second];
  }

  static void CheckSeq(const Row& row, std::int64_t seq, std::size_t expected) {
    if (seq != static_cast<std::int64_t>(expected)) {
      row.Fail("seq", std::to_string(seq) + ", expected " + std::to_string(expected) +
                          " (a row is missing or repeated)");
    }
  }

  const std::string& path_;
  std::vector<std::string>* passed_;
  int* schema_version_;
  std::uint64_t file_bytes_ = 0;
  StepBudget budget_;
  std::map<std::string, std::string> meta_;
  std::map<std::int64_t, std::size_t> index_of_id_;  // submap id -> index in map.submaps
  static constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
};

// ---------------------------------------------------------------------------------------------
// Writing.

void WriteAll(Database& db, const GlobalMap& map) {
  db.Execute("PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;");
  db.Execute("BEGIN;");
  db.Execute(kMapSchema);
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
  try {
    return MapReader(path, nullptr, nullptr).Read();
  } catch (const std::bad_alloc&) {
    // The loader bounds every count and blob by the file's size, so this is a map too large for
    // the memory left, not a hostile file: say which file, not a bare std::bad_alloc.
    std::error_code error;
    const auto bytes = std::filesystem::file_size(path, error);
    throw std::runtime_error(path + ": out of memory while loading the map" +
                             (error ? std::string() : " (" + std::to_string(bytes) + " bytes)"));
  }
}

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
