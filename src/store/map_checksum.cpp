#include "store/map_checksum.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

#include "common/fnv1a64.hpp"
#include "store/map_schema.hpp"

namespace keyplace {

std::string MapContentChecksum(sqlite3* db) {
  Fnv1a64 hash;
  for (const MapTableKey& table : kMapTables) {
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

}  // namespace keyplace
