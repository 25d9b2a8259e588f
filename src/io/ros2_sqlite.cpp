// ReadSqliteMessages: a rosbag2 sqlite3 storage file (tables topics(id, name, type,
// serialization_format, ...) and messages(id, topic_id, timestamp, data)), opened read-only and
// immutable (no journal, no lock files beside a bag that may lie on a read-only disk), with the
// connection hardened as for map files (io/sqlite_hardening.hpp): the file may come from anywhere.

#include <sqlite3.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/ros2_storage.hpp"
#include "io/sqlite_hardening.hpp"
#include "io/sqlite_magic.hpp"

namespace keyplace {
namespace {

// A message larger than this is damage (a 10^5-beam scan is 400 kB).
constexpr std::uint64_t kMaxBlobBytes = 256U << 20U;
// Reading the fixture bag (528 kB, 450 messages) takes about 0.05 instructions per byte; a
// bag's messages are read once, by their id.
constexpr std::uint64_t kInstructionsPerFileByte = 64;

struct CloseDatabase {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct FinalizeStatement {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Database = std::unique_ptr<sqlite3, CloseDatabase>;
using Statement = std::unique_ptr<sqlite3_stmt, FinalizeStatement>;

// "file:" URI of a path, with the characters URIs reserve escaped.
std::string FileUri(const std::string& path) {
  std::string uri = "file:";
  for (const char c : path) {
    if (c == '%' || c == '?' || c == '#') {
      static constexpr char kHex[] = "0123456789abcdef";
      const auto byte = static_cast<unsigned char>(c);
      uri += '%';
      uri += kHex[byte >> 4U];
      uri += kHex[byte & 15U];
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

// The columns keyplace reads, per table; each must be an ordinary stored column.
struct RequiredTable {
  const char* name;
  std::vector<const char*> columns;
};
const std::vector<RequiredTable>& RequiredTables() {
  static const std::vector<RequiredTable> tables = {
      {"topics", {"id", "name", "type", "serialization_format"}},
      {"messages", {"id", "topic_id", "timestamp", "data"}}};
  return tables;
}

class SqliteBag {
 public:
  explicit SqliteBag(const std::string& path) : path_(path) {
    std::error_code error;
    const std::uint64_t file_bytes = std::filesystem::file_size(path, error);
    if (error) {
      throw std::invalid_argument(path + ": cannot read the size of the sqlite3 file (" +
                                  error.message() + ")");
    }
    CheckHeader(file_bytes);
    sqlite3* raw = nullptr;
    const int status = sqlite3_open_v2(FileUri(path).c_str(), &raw,
                                       SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
    db_.reset(raw);
    if (status != SQLITE_OK) Fail("cannot open the sqlite3 file");
    if (!HardenReadOnlyConnection(db_.get(), file_bytes, kMaxBlobBytes, kInstructionsPerFileByte,
                                  budget_)) {
      Fail("cannot configure SQLite");
    }
  }

  StorageWalk Walk(const StorageVisitor& visitor) {
    CheckTables();
    CheckPages();
    StorageWalk walk;
    walk.time_ordered = true;
    std::map<sqlite3_int64, StorageTopic> topics;
    Statement topic_rows =
        Prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id");
    while (Step(topic_rows)) {
      StorageTopic topic{Text(topic_rows, 1), Text(topic_rows, 2), Text(topic_rows, 3)};
      walk.topics.push_back(topic);
      topics[sqlite3_column_int64(topic_rows.get(), 0)] = std::move(topic);
    }
    // Messages in (timestamp, id) order, the order rosbag2 plays them. The order is made here
    // from the stamps and ids alone (16 bytes a message) rather than by SQLite's sorter, which
    // would copy every blob into temporary files; each blob is then read by its id, the table's
    // primary key (CheckColumns), once: CheckPages made sure no two rows share a page.
    std::vector<std::pair<sqlite3_int64, sqlite3_int64>> order;  // (timestamp, id)
    Statement stamps = Prepare("SELECT timestamp, id FROM messages");
    while (Step(stamps)) {
      // SQLite converts any value to an integer when asked; text read as 0 (a stamp at 1970).
      const int type = sqlite3_column_type(stamps.get(), 0);
      if (type != SQLITE_INTEGER) {
        throw std::invalid_argument(
            path_ + ": message id " + std::to_string(sqlite3_column_int64(stamps.get(), 1)) +
            ": messages.timestamp is " + TypeName(type) + ", not an integer (nanoseconds)");
      }
      order.emplace_back(sqlite3_column_int64(stamps.get(), 0),
                         sqlite3_column_int64(stamps.get(), 1));
    }
    std::sort(order.begin(), order.end());
    Statement message = Prepare("SELECT topic_id, data FROM messages WHERE id = ?");
    for (const auto& [stamp_ns, id] : order) {
      sqlite3_reset(message.get());
      sqlite3_bind_int64(message.get(), 1, id);
      if (!Step(message)) Fail("message id " + std::to_string(id) + " vanished");
      if (sqlite3_column_type(message.get(), 0) != SQLITE_INTEGER) {
        throw std::invalid_argument(
            path_ + ": message id " + std::to_string(id) + ": messages.topic_id is " +
            TypeName(sqlite3_column_type(message.get(), 0)) + ", not an integer");
      }
      const sqlite3_int64 topic_id = sqlite3_column_int64(message.get(), 0);
      const auto topic = topics.find(topic_id);
      if (topic == topics.end()) {
        Fail("a message of topic id " + std::to_string(topic_id) +
             ", which the topics table does not hold");
      }
      const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(message.get(), 1));
      const int size = sqlite3_column_bytes(message.get(), 1);
      visitor({topic->second, static_cast<std::uint64_t>(stamp_ns < 0 ? 0 : stamp_ns), data,
               static_cast<std::size_t>(size)});
    }
    return walk;
  }

 private:
  [[noreturn]] void Fail(const std::string& why) const {
    if (db_ && StepBudgetUsedUp(db_.get())) {
      throw std::invalid_argument(path_ + ": " + why +
                                  ": reading needed more SQLite steps than a rosbag2 file of "
                                  "this size can (hostile or damaged file)");
    }
    const char* detail = db_ ? sqlite3_errmsg(db_.get()) : "out of memory";
    throw std::invalid_argument(path_ + ": " + why + " (sqlite: " + detail + ")");
  }

  // What the 100-byte header says, before SQLite reads anything: a recording cut short (a full
  // disk, a power loss) leaves fewer pages than the header counts, and SQLite would only say
  // "malformed" at the first page missing (its b-trees are not read in part); a write-ahead-log
  // file beside the bag holds messages the file does not, which an immutable read would drop.
  void CheckHeader(std::uint64_t file_bytes) const {
    unsigned char header[kSqliteHeaderBytes] = {};
    std::ifstream in(path_, std::ios::binary);
    in.read(reinterpret_cast<char*>(header), sizeof header);
    if (in.gcount() != static_cast<std::streamsize>(sizeof header) ||
        !StartsWithSqliteMagic(header, sizeof header)) {
      return;  // not SQLite: SQLite says so
    }
    const SqliteHeaderSize size = ReadSqliteHeaderSize(header);
    if (size.page_bytes < 512 || size.page_bytes > 65536 ||
        (size.page_bytes & (size.page_bytes - 1)) != 0) {
      throw std::invalid_argument(path_ + ": damaged sqlite3 file: page size " +
                                  std::to_string(size.page_bytes) + " in its SQLite header");
    }
    const std::uint64_t header_bytes = std::uint64_t{size.pages} * size.page_bytes;
    if (header_bytes > file_bytes) {
      throw std::invalid_argument(
          path_ + ": cut off at byte " + std::to_string(file_bytes) +
          ": its SQLite header counts " + std::to_string(size.pages) + " pages of " +
          std::to_string(size.page_bytes) + " bytes (" + std::to_string(header_bytes) +
          " bytes); an sqlite3 bag cut short cannot be read in part (a recording stopped by a "
          "full disk or power loss: recover what SQLite can with `sqlite3 FILE .recover`)");
    }
    constexpr unsigned char kWriteAheadLog = 2;
    std::error_code error;
    const std::string wal = path_ + "-wal";
    if (header[18] == kWriteAheadLog && std::filesystem::is_regular_file(wal, error) &&
        std::filesystem::file_size(wal, error) > 0 && !error) {
      throw std::invalid_argument(
          path_ + ": its write-ahead log " + wal +
          " holds messages not yet in the file (a recording that did not end cleanly); open the "
          "bag once with sqlite3 (`sqlite3 FILE 'PRAGMA wal_checkpoint;'`) to move them into it");
    }
  }

  // Pages shared by two rows (or cycles of overflow pages) cost no SQLite steps to follow, so the
  // step budget cannot bound them: a 10 MB file could make every small row point at the same
  // blob as long as the file. quick_check finds them, in one pass over the file.
  void CheckPages() {
    Statement check = Prepare("PRAGMA quick_check(1)");
    if (!Step(check) || Text(check, 0) != "ok") {
      throw std::invalid_argument(path_ + ": damaged sqlite3 file: SQLite's quick_check says '" +
                                  Text(check, 0) + "' (a hostile or damaged file, not read)");
    }
  }

  [[noreturn]] void NotRosbag2(const std::string& why) const {
    throw std::invalid_argument(path_ + ": not a rosbag2 sqlite3 file: " + why);
  }

  // topics and messages must be ordinary tables (a view or a virtual table would run a query or
  // a module of the file's choosing) whose columns keyplace reads are stored, not generated.
  void CheckTables() {
    std::vector<std::pair<std::string, std::string>> objects;  // (type, sql) per required table
    for (const RequiredTable& table : RequiredTables()) {
      Statement object = Prepare("SELECT type, sql FROM sqlite_master WHERE name = ?");
      sqlite3_bind_text(object.get(), 1, table.name, -1, SQLITE_STATIC);
      if (!Step(object)) NotRosbag2("it lacks the tables topics and messages");
      objects.emplace_back(Text(object, 0), Text(object, 1));
    }
    for (std::size_t k = 0; k < objects.size(); ++k) {
      const auto& [type, sql] = objects[k];
      const RequiredTable& table = RequiredTables()[k];
      if (type != "table" || sql.rfind("CREATE TABLE", 0) != 0) {
        NotRosbag2(std::string("'") + table.name + "' is a " +
                   (type == "table" ? std::string("virtual table") : type) +
                   ", not an ordinary table (a hostile or damaged file, not read further)");
      }
      CheckColumns(table);
    }
  }

  struct ColumnFacts {
    int hidden = 0;       // 0 stored, 1 hidden, 2/3 generated
    int primary_key = 0;  // position in the primary key, 0 if not in it
  };

  void CheckColumns(const RequiredTable& table) {
    std::map<std::string, ColumnFacts> columns;
    int primary_key_columns = 0;
    Statement rows = Prepare(std::string("PRAGMA table_xinfo(") + table.name + ")");
    while (Step(rows)) {
      const ColumnFacts facts{sqlite3_column_int(rows.get(), 6), sqlite3_column_int(rows.get(), 5)};
      columns[Text(rows, 1)] = facts;
      primary_key_columns += facts.primary_key != 0 ? 1 : 0;
    }
    for (const char* column : table.columns) {
      const auto found = columns.find(column);
      if (found == columns.end()) {
        NotRosbag2(std::string("table ") + table.name + " has no column " + column);
      }
      if (found->second.hidden != 0) {
        NotRosbag2(std::string("column ") + table.name + "." + column +
                   " is hidden or generated, not stored (a hostile or damaged file, not read "
                   "further)");
      }
    }
    // Each message is looked up by its id: it must be the whole primary key, as rosbag2 writes
    // it, or every lookup would scan the table.
    if (std::string(table.name) == "messages" &&
        (columns.at("id").primary_key != 1 || primary_key_columns != 1)) {
      NotRosbag2("messages.id is not the table's primary key");
    }
  }

  Statement Prepare(const std::string& sql) {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      Fail("not a rosbag2 sqlite3 file: cannot run '" + sql + "'");
    }
    return Statement(raw);
  }

  bool Step(const Statement& statement) {
    const int status = sqlite3_step(statement.get());
    if (status == SQLITE_ROW) return true;
    if (status == SQLITE_DONE) return false;
    Fail("cannot read the database");
  }

  static const char* TypeName(int type) {
    switch (type) {
      case SQLITE_INTEGER:
        return "an integer";
      case SQLITE_FLOAT:
        return "a real number";
      case SQLITE_TEXT:
        return "text";
      case SQLITE_BLOB:
        return "a blob";
      default:
        return "null";
    }
  }

  static std::string Text(const Statement& statement, int column) {
    const unsigned char* text = sqlite3_column_text(statement.get(), column);
    return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
  }

  const std::string& path_;
  StepBudget budget_;  // before db_: the connection's progress handler points at it
  Database db_;
};

}  // namespace

StorageWalk ReadSqliteMessages(const std::string& path, const StorageVisitor& visitor) {
  return SqliteBag(path).Walk(visitor);
}

}  // namespace keyplace
