#include "io/file_fingerprint.hpp"

#include <zlib.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace keyplace {

std::string FileFingerprint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  uLong crc = crc32(0L, Z_NULL, 0);
  unsigned long long size = 0;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<uInt>(in.gcount());
    if (got == 0) break;
    crc = crc32(crc, reinterpret_cast<const Bytef*>(buffer.data()), got);
    size += got;
  }
  if (in.bad()) throw std::runtime_error(path + ": read error");
  char text[64];
  std::snprintf(text, sizeof(text), "crc32:%08lx:%llu", crc, size);
  return text;
}

}  // namespace keyplace
