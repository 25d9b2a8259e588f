#pragma once
// The 16 bytes every SQLite database file starts with (a keyplace map is one): the log reader,
// the map loader and `keyplace info` recognise a map by the same test.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace keyplace {

// "SQLite format 3" and its terminating zero byte.
inline constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

inline bool StartsWithSqliteMagic(const void* bytes, std::size_t size) {
  return size >= kSqliteMagic.size() &&
         std::memcmp(bytes, kSqliteMagic.data(), kSqliteMagic.size()) == 0;
}

// What a database file's 100-byte header (sqlite.org/fileformat.html) says about its length.
struct SqliteHeaderSize {
  std::uint32_t page_bytes = 0;  // 512..65536 in a sound file
  std::uint32_t pages = 0;       // 0 when the header does not say
};

inline constexpr std::size_t kSqliteHeaderBytes = 100;

inline SqliteHeaderSize ReadSqliteHeaderSize(const unsigned char* header) {
  const auto big_endian = [header](int offset, int count) {
    std::uint32_t value = 0;
    for (int k = 0; k < count; ++k) value = (value << 8U) | header[offset + k];
    return value;
  };
  SqliteHeaderSize size;
  const std::uint32_t page_field = big_endian(16, 2);
  size.page_bytes = page_field == 1 ? 65536 : page_field;
  // The page count is valid only when written with the current change counter.
  if (big_endian(92, 4) == big_endian(24, 4)) size.pages = big_endian(28, 4);
  return size;
}

}  // namespace keyplace
