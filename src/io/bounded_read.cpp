#include "io/bounded_read.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace keyplace {
namespace {

std::string Size(std::size_t bytes) {
  if (bytes >= (std::size_t{1} << 20) && bytes % (std::size_t{1} << 20) == 0) {
    return std::to_string(bytes >> 20) + " MiB";
  }
  return std::to_string(bytes) + " bytes";
}

}  // namespace

std::string ReadWholeFile(const std::string& path, std::size_t max_bytes, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the " + what);
  std::string content;
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  while (in) {
    const std::size_t at = content.size();
    const std::size_t want = std::min(kBlock, max_bytes + 1 - at);
    content.resize(at + want);
    in.read(content.data() + at, static_cast<std::streamsize>(want));
    content.resize(at + static_cast<std::size_t>(in.gcount()));
    if (content.size() > max_bytes) {
      std::string message = path;
      message += ": larger than " + Size(max_bytes);
      message += ", the limit of a " + what;
      message += " (not read further; is it the right file?)";
      throw std::runtime_error(message);
    }
  }
  if (in.bad()) throw std::runtime_error(path + ": read error in the " + what);
  return content;
}

}  // namespace keyplace
