#include "keyplace/mapping/map_server.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/config_fields.hpp"
#include "io/atomic_file.hpp"
#include "io/bounded_read.hpp"
#include "io/yaml_document.hpp"

namespace keyplace {
namespace {

// A YAML double-quoted scalar: a file name may hold ':' or '#'.
std::string DoubleQuoted(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') quoted.push_back('\\');
    quoted.push_back(c);
  }
  return quoted + "\"";
}

std::uint8_t PixelOf(CellState state) {
  switch (state) {
    case CellState::kOccupied:
      return kMapServerOccupied;
    case CellState::kFree:
      return kMapServerFree;
    case CellState::kUnknown:
      break;
  }
  return kMapServerUnknown;
}

void WriteImage(const OccupancyGrid& grid, const OccupancyGridConfig& config,
                const std::string& path) {
  const std::vector<std::uint8_t> pixels = MapServerImage(grid, config);
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "P5\n# keyplace occupancy grid, " << grid.resolution_m << " m per pixel\n"
        << grid.width << ' ' << grid.height << "\n255\n";
    out.write(reinterpret_cast<const char*>(pixels.data()),
              static_cast<std::streamsize>(pixels.size()));
  });
}

[[noreturn]] void Fail(const std::string& path, const std::string& problem) {
  throw std::invalid_argument(path + ": " + problem);
}

// The next whitespace-separated header token of a PGM, skipping '#' comments.
std::string HeaderToken(const std::string& bytes, std::size_t& at) {
  while (at < bytes.size()) {
    if (bytes[at] == '#') {
      while (at < bytes.size() && bytes[at] != '\n') ++at;
    } else if (std::isspace(static_cast<unsigned char>(bytes[at])) != 0) {
      ++at;
    } else {
      break;
    }
  }
  const std::size_t start = at;
  while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at])) == 0) ++at;
  return bytes.substr(start, at - start);
}

int HeaderNumber(const std::string& bytes, std::size_t& at, const std::string& path,
                 const char* field) {
  const std::string token = HeaderToken(bytes, at);
  if (token.empty() || token.size() > 6 ||
      token.find_first_not_of("0123456789") != std::string::npos) {
    Fail(path,
         std::string("PGM header field ") + field + " is '" + token + "', not a number below 10^6");
  }
  return std::stoi(token);
}

// The header is read from the first kMaxPgmHeaderBytes, then exactly the pixels it declares (at
// most kMaxMapServerPixels): /dev/zero or a huge file is never read whole (it was, 2 GB, then
// std::bad_alloc).
void ReadImage(MapServerMap& map) {
  const std::string& path = map.image_path;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the map image");
  std::string bytes(kMaxPgmHeaderBytes, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  std::size_t at = 0;
  if (HeaderToken(bytes, at) != "P5") Fail(path, "not a binary PGM image (magic P5)");
  map.width = HeaderNumber(bytes, at, path, "width");
  map.height = HeaderNumber(bytes, at, path, "height");
  if (HeaderNumber(bytes, at, path, "maxval") != 255) Fail(path, "maxval must be 255 (8 bits)");
  ++at;  // the single whitespace after maxval
  if (at >= bytes.size() && bytes.size() == kMaxPgmHeaderBytes) {
    Fail(path, "a PGM header longer than " + std::to_string(kMaxPgmHeaderBytes) + " bytes");
  }
  const std::size_t count =
      static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height);
  if (count > kMaxMapServerPixels) {
    Fail(path, std::to_string(map.width) + " x " + std::to_string(map.height) +
                   " pixels, more than the " + std::to_string(kMaxMapServerPixels) +
                   " (16384 x 16384) keyplace reads");
  }
  if (bytes.size() < at + count) {
    const std::size_t present = bytes.size();
    bytes.resize(at + count);
    in.read(bytes.data() + present, static_cast<std::streamsize>(at + count - present));
    bytes.resize(present + static_cast<std::size_t>(in.gcount()));
  }
  if (bytes.size() < at + count) {
    Fail(path, std::to_string(map.width) + " x " + std::to_string(map.height) +
                   " pixels declared, " +
                   std::to_string(bytes.size() > at ? bytes.size() - at : 0) +
                   " bytes of pixels present");
  }
  map.pixels.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                    bytes.begin() + static_cast<std::ptrdiff_t>(at + count));
}

template <typename Value>
Value Required(const YAML::Node& root, const char* key, const std::string& path) {
  const YAML::Node node = root[key];
  if (!node) Fail(path, std::string("missing key '") + key + "'");
  try {
    return node.as<Value>();
  } catch (const YAML::Exception&) {
    Fail(path,
         "line " + std::to_string(node.Mark().line + 1) + ": key '" + key + "' has the wrong type");
  }
}

}  // namespace

std::vector<std::uint8_t> MapServerImage(const OccupancyGrid& grid,
                                         const OccupancyGridConfig& config) {
  std::vector<std::uint8_t> pixels;
  pixels.reserve(static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height));
  for (int row = grid.height - 1; row >= 0; --row) {  // the image's first row is the top
    for (int column = 0; column < grid.width; ++column) {
      pixels.push_back(PixelOf(grid.State(column, row, config)));
    }
  }
  return pixels;
}

std::string MapServerImagePath(const std::string& yaml_path) {
  return std::filesystem::path(yaml_path).replace_extension(".pgm").string();
}

void WriteMapServerMap(const OccupancyGrid& grid, const OccupancyGridConfig& config,
                       const std::string& yaml_path) {
  if (grid.width <= 0 || grid.height <= 0) {
    throw std::invalid_argument(yaml_path + ": the occupancy grid is empty (no beam was traced)");
  }
  const std::string image_path = MapServerImagePath(yaml_path);
  WriteImage(grid, config, image_path);
  WriteFileAtomically(yaml_path, [&](std::ostream& out) {
    // The image is named relative to the YAML, so the pair can be moved together.
    out << "image: " << DoubleQuoted(std::filesystem::path(image_path).filename().string())
        << "\nmode: trinary\nresolution: " << FormatConfigDouble(grid.resolution_m) << "\norigin: ["
        << FormatConfigDouble(grid.origin_m.x()) << ", " << FormatConfigDouble(grid.origin_m.y())
        << ", 0.0]\nnegate: 0\noccupied_thresh: " << FormatConfigDouble(kMapServerOccupiedThresh)
        << "\nfree_thresh: " << FormatConfigDouble(kMapServerFreeThresh) << "\n";
  });
}

double MapServerMap::Occupancy(int column, int image_row) const {
  const double value =
      pixels[static_cast<std::size_t>(image_row) * static_cast<std::size_t>(width) +
             static_cast<std::size_t>(column)];
  return negate != 0 ? value / 255.0 : (255.0 - value) / 255.0;
}

MapServerMap ReadMapServerMap(const std::string& yaml_path) {
  const YAML::Node root =
      LoadYamlDocument(ReadWholeFile(yaml_path, kMaxMapServerYamlBytes, "map YAML"), yaml_path);
  if (!root.IsMap()) Fail(yaml_path, "not a YAML mapping of map_server keys");
  MapServerMap map;
  const auto image = Required<std::string>(root, "image", yaml_path);
  const std::filesystem::path image_path(image);
  map.image_path = image_path.is_absolute()
                       ? image
                       : (std::filesystem::path(yaml_path).parent_path() / image_path).string();
  map.resolution_m = Required<double>(root, "resolution", yaml_path);
  if (!(map.resolution_m > 0.0)) Fail(yaml_path, "resolution must be positive");
  const auto origin = Required<std::vector<double>>(root, "origin", yaml_path);
  if (origin.size() != 3) Fail(yaml_path, "origin must be [x, y, yaw]");
  map.origin_x_m = origin[0];
  map.origin_y_m = origin[1];
  map.origin_yaw_rad = origin[2];
  map.negate = Required<int>(root, "negate", yaml_path);
  map.occupied_thresh = Required<double>(root, "occupied_thresh", yaml_path);
  map.free_thresh = Required<double>(root, "free_thresh", yaml_path);
  if (root["mode"]) map.mode = Required<std::string>(root, "mode", yaml_path);
  ReadImage(map);
  return map;
}

}  // namespace keyplace
