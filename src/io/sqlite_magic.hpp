#pragma once
// The 16 bytes every SQLite database file starts with (a keyplace map is one): the log reader,
// the map loader and `keyplace info` recognise a map by the same test.

#include <cstddef>
#include <cstring>
#include <string_view>

namespace keyplace {

// "SQLite format 3" and its terminating zero byte.
inline constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

inline bool StartsWithSqliteMagic(const void* bytes, std::size_t size) {
  return size >= kSqliteMagic.size() &&
         std::memcmp(bytes, kSqliteMagic.data(), kSqliteMagic.size()) == 0;
}

}  // namespace keyplace
