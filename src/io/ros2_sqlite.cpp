// ReadSqliteMessages: a rosbag2 sqlite3 storage file (tables topics(id, name, type,
// serialization_format, ...) and messages(id, topic_id, timestamp, data)), opened read-only and
// immutable (no journal, no lock files beside a bag that may lie on a read-only disk).

#include <sqlite3.h>

#include <map>
#include <memory>
#include <stdexcept>

#include "io/ros2_storage.hpp"

namespace keyplace {
namespace {

// A message larger than this is damage (a 10^5-beam scan is 400 kB).
constexpr int kMaxBlobBytes = 256 << 20;

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

class SqliteBag {
 public:
  explicit SqliteBag(const std::string& path) : path_(path) {
    sqlite3* raw = nullptr;
    const int status = sqlite3_open_v2(FileUri(path).c_str(), &raw,
                                       SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
    db_.reset(raw);
    if (status != SQLITE_OK) Fail("cannot open the sqlite3 file");
    sqlite3_limit(db_.get(), SQLITE_LIMIT_LENGTH, kMaxBlobBytes);
    sqlite3_db_config(db_.get(), SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
    sqlite3_db_config(db_.get(), SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
  }

  StorageWalk Walk(const StorageVisitor& visitor) {
    CheckTables();
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
    Statement messages =
        Prepare("SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id");
    while (Step(messages)) {
      const sqlite3_int64 topic_id = sqlite3_column_int64(messages.get(), 0);
      const auto topic = topics.find(topic_id);
      if (topic == topics.end()) {
        Fail("a message of topic id " + std::to_string(topic_id) +
             ", which the topics table does not hold");
      }
      const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(messages.get(), 2));
      const int size = sqlite3_column_bytes(messages.get(), 2);
      const sqlite3_int64 stamp_ns = sqlite3_column_int64(messages.get(), 1);
      visitor({topic->second, static_cast<std::uint64_t>(stamp_ns < 0 ? 0 : stamp_ns), data,
               static_cast<std::size_t>(size)});
    }
    return walk;
  }

 private:
  [[noreturn]] void Fail(const std::string& why) const {
    const char* detail = db_ ? sqlite3_errmsg(db_.get()) : "out of memory";
    throw std::invalid_argument(path_ + ": " + why + " (sqlite: " + detail + ")");
  }

  void CheckTables() {
    Statement tables = Prepare(
        "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN ('topics', "
        "'messages')");
    if (!Step(tables) || sqlite3_column_int(tables.get(), 0) != 2) {
      throw std::invalid_argument(path_ +
                                  ": not a rosbag2 sqlite3 file: it lacks the tables topics and "
                                  "messages");
    }
  }

  Statement Prepare(const char* sql) {
    sqlite3_stmt* raw = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql, -1, &raw, nullptr) != SQLITE_OK) {
      sqlite3_finalize(raw);
      Fail(std::string("not a rosbag2 sqlite3 file: cannot run '") + sql + "'");
    }
    return Statement(raw);
  }

  bool Step(const Statement& statement) {
    const int status = sqlite3_step(statement.get());
    if (status == SQLITE_ROW) return true;
    if (status == SQLITE_DONE) return false;
    Fail("cannot read the database");
  }

  std::string Text(const Statement& statement, int column) const {
    const unsigned char* text = sqlite3_column_text(statement.get(), column);
    return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
  }

  const std::string& path_;
  Database db_;
};

}  // namespace

StorageWalk ReadSqliteMessages(const std::string& path, const StorageVisitor& visitor) {
  return SqliteBag(path).Walk(visitor);
}

}  // namespace keyplace
