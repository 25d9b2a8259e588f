#include "io/file_fingerprint.hpp"

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace keyplace {

std::string FormatFingerprint(std::uint32_t crc32, std::uint64_t bytes) {
  char text[64];
  std::snprintf(text, sizeof(text), "crc32:%08lx:%llu", static_cast<unsigned long>(crc32),
                static_cast<unsigned long long>(bytes));
  return text;
}

std::string FileFingerprint(const std::string& path) { return FilesFingerprint({path}); }

std::string FilesFingerprint(const std::vector<std::string>& paths) {
  uLong crc = crc32(0L, Z_NULL, 0);
  std::uint64_t size = 0;
  std::vector<char> buffer(1 << 16);
  for (const std::string& path : paths) {
    std::error_code error;
    if (std::filesystem::exists(path, error) && !std::filesystem::is_regular_file(path, error)) {
      throw std::runtime_error(path +
                               ": not a regular file: its fingerprint is taken while it is "
                               "read (CarmenLog::fingerprint)");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open file");
    while (in) {
      in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      const auto got = static_cast<uInt>(in.gcount());
      if (got == 0) break;
      crc = crc32(crc, reinterpret_cast<const Bytef*>(buffer.data()), got);
      size += got;
    }
    if (in.bad()) throw std::runtime_error(path + ": read error");
  }
  return FormatFingerprint(static_cast<std::uint32_t>(crc), size);
}

}  // namespace keyplace
