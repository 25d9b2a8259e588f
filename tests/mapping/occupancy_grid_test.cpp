// The occupancy grid a navigation stack loads (issue 16): walls occupied, the inside free, the
// outside unknown, and the map_server files placing each of them where map_server will.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/mapping/map_server.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

// The rectangular room 2 < x < 12, -1 < y < 5 (world frame) with a square pillar 9 < x < 9.6,
// 0 < y < 0.6 in it, scanned over 360 degrees.
constexpr double kRoomMinX = 2.0;
constexpr double kRoomMaxX = 12.0;
constexpr double kRoomMinY = -1.0;
constexpr double kRoomMaxY = 5.0;
const Eigen::Vector2d kPillarMin(9.0, 0.0);
const Eigen::Vector2d kPillarMax(9.6, 0.6);

// Distance along `direction` from `from` to the pillar's boundary, or infinity (slab method).
double PillarDistance(const Eigen::Vector2d& from, const Eigen::Vector2d& direction) {
  double enter = 0.0;
  double leave = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(direction[axis]) < 1e-12) {
      if (from[axis] < kPillarMin[axis] || from[axis] > kPillarMax[axis]) return leave;
      continue;
    }
    double t0 = (kPillarMin[axis] - from[axis]) / direction[axis];
    double t1 = (kPillarMax[axis] - from[axis]) / direction[axis];
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
  }
  return enter <= leave && enter > 0.0 ? enter : std::numeric_limits<double>::infinity();
}

LaserScan RectangleRoomScan(const Pose2& T_world_laser) {
  LaserScan scan;
  scan.max_range_m = 40.0;
  const int beams = 720;
  for (int k = 0; k < beams; ++k) {
    const double bearing_rad = -M_PI + 2.0 * M_PI * k / beams;
    const double world_rad = bearing_rad + T_world_laser.theta;
    const Eigen::Vector2d direction(std::cos(world_rad), std::sin(world_rad));
    double range_m = PillarDistance(T_world_laser.translation(), direction);
    const double walls[2][2] = {{kRoomMinX, kRoomMaxX}, {kRoomMinY, kRoomMaxY}};
    for (int axis = 0; axis < 2; ++axis) {
      if (std::abs(direction[axis]) < 1e-12) continue;
      for (const double wall : walls[axis]) {
        const double t = (wall - T_world_laser.translation()[axis]) / direction[axis];
        if (t > 0) range_m = std::min(range_m, t);
      }
    }
    scan.ranges_m.push_back(range_m);
    scan.angles_rad.push_back(bearing_rad);
    scan.valid.push_back(1);
  }
  return scan;
}

struct Room {
  std::vector<LaserScan> scans;
  std::vector<Pose2> T_world_robot;
  std::vector<const LaserScan*> Pointers() const {
    std::vector<const LaserScan*> pointers;
    for (const auto& scan : scans) pointers.push_back(&scan);
    return pointers;
  }
};

// Twelve scans along a path through the room, from a robot whose laser sits 0.3 m ahead of its
// centre.
Room ScannedRoom() {
  Room room;
  const Pose2 T_robot_laser(0.3, 0.0, 0.0);
  for (int k = 0; k < 12; ++k) {
    const Pose2 robot(3.5 + 0.6 * k, 0.2 + 0.3 * k, 0.2 + 0.9 * k);
    LaserScan scan = RectangleRoomScan(robot * T_robot_laser);
    scan.T_robot_laser = T_robot_laser;
    room.scans.push_back(scan);
    room.T_world_robot.push_back(robot);
  }
  return room;
}

CellState StateAt(const OccupancyGrid& grid, const OccupancyGridConfig& config, double x_m,
                  double y_m) {
  int column = 0;
  int row = 0;
  if (!grid.CellOf({x_m, y_m}, column, row)) return CellState::kUnknown;
  return grid.State(column, row, config);
}

TEST(OccupancyGrid, WallsAreOccupiedTheInsideFreeTheOutsideUnknown) {
  const Room room = ScannedRoom();
  const OccupancyGridConfig config;
  const OccupancyGrid grid = BuildOccupancyGrid(room.Pointers(), room.T_world_robot, config);
  // The grid covers the room and one cell more, no further.
  EXPECT_NEAR(grid.origin_m.x(), kRoomMinX - config.resolution_m, 1e-6);
  EXPECT_NEAR(grid.origin_m.y(), kRoomMinY - config.resolution_m, 1e-6);
  EXPECT_NEAR(grid.width * config.resolution_m, kRoomMaxX - kRoomMinX + 3 * config.resolution_m,
              config.resolution_m);
  // Every wall cell, along all four walls (corners aside), is occupied: the beams that graze
  // a wall on their way to its next cells do not free it. A beam ends exactly on the wall line,
  // so its cell is the one on either side of the line; the cell beyond that is never occupied.
  const auto wall_at = [&](double x_m, double y_m, double normal_x, double normal_y) {
    const double d = 0.02;
    const bool occupied =
        StateAt(grid, config, x_m - d * normal_x, y_m - d * normal_y) == CellState::kOccupied ||
        StateAt(grid, config, x_m + d * normal_x, y_m + d * normal_y) == CellState::kOccupied;
    const double beyond = 0.08;
    const bool thin = StateAt(grid, config, x_m - beyond * normal_x, y_m - beyond * normal_y) !=
                          CellState::kOccupied &&
                      StateAt(grid, config, x_m + beyond * normal_x, y_m + beyond * normal_y) !=
                          CellState::kOccupied;
    return occupied && thin;
  };
  int wall_cells = 0;
  for (double x = kRoomMinX + 0.2; x < kRoomMaxX - 0.2; x += 0.05) {
    const bool behind_pillar = x > kPillarMin.x() - 0.6 && x < kPillarMax.x() + 1.0;
    if (!behind_pillar) {
      EXPECT_TRUE(wall_at(x, kRoomMinY, 0.0, 1.0)) << x;
    }
    EXPECT_TRUE(wall_at(x, kRoomMaxY, 0.0, 1.0)) << x;
    wall_cells += 2;
  }
  for (double y = kRoomMinY + 0.2; y < kRoomMaxY - 0.2; y += 0.05) {
    EXPECT_TRUE(wall_at(kRoomMinX, y, 1.0, 0.0)) << y;
    EXPECT_TRUE(wall_at(kRoomMaxX, y, 1.0, 0.0)) << y;
    wall_cells += 2;
  }
  EXPECT_GT(wall_cells, 500);
  // The inside is free (0.2 m from the walls, 1 m from the pillar), the pillar's inside unknown
  // and its faces occupied.
  int free_cells = 0;
  for (double x = kRoomMinX + 0.2; x < kRoomMaxX - 0.2; x += 0.37) {
    for (double y = kRoomMinY + 0.2; y < kRoomMaxY - 0.2; y += 0.37) {
      if (x > kPillarMin.x() - 1.0 && x < kPillarMax.x() + 1.0 && y < kPillarMax.y() + 1.0) {
        continue;
      }
      EXPECT_EQ(StateAt(grid, config, x, y), CellState::kFree) << x << ", " << y;
      ++free_cells;
    }
  }
  EXPECT_GT(free_cells, 300);
  EXPECT_EQ(StateAt(grid, config, 9.3, 0.3), CellState::kUnknown);
  EXPECT_TRUE(wall_at(9.3, kPillarMax.y(), 0.0, 1.0));
  EXPECT_TRUE(wall_at(kPillarMin.x(), 0.3, 1.0, 0.0));
}

TEST(OccupancyGrid, MapServerFilesPutEveryCellWhereMapServerReadsIt) {
  const Room room = ScannedRoom();
  const OccupancyGridConfig config;
  const OccupancyGrid grid = BuildOccupancyGrid(room.Pointers(), room.T_world_robot, config);
  const std::string yaml = testing::MakeTempDir("grid") + "/room.yaml";
  WriteMapServerMap(grid, config, yaml);
  const MapServerMap map = ReadMapServerMap(yaml);
  EXPECT_EQ(map.image_path, MapServerImagePath(yaml));
  EXPECT_EQ(map.width, grid.width);
  EXPECT_EQ(map.height, grid.height);
  EXPECT_DOUBLE_EQ(map.resolution_m, config.resolution_m);
  EXPECT_DOUBLE_EQ(map.origin_x_m, grid.origin_m.x());
  EXPECT_DOUBLE_EQ(map.origin_y_m, grid.origin_m.y());
  EXPECT_EQ(map.negate, 0);
  EXPECT_EQ(map.mode, "trinary");
  // map_server's rule: world (x, y) is pixel column (x - ox) / res and image row
  // height - 1 - (y - oy) / res (the image's first row is the top of the map).
  const auto occupancy = [&](double x_m, double y_m) {
    const int column = static_cast<int>(std::floor((x_m - map.origin_x_m) / map.resolution_m));
    const int row = static_cast<int>(std::floor((y_m - map.origin_y_m) / map.resolution_m));
    return map.Occupancy(column, map.height - 1 - row);
  };
  // Walls as map_server sees them (either cell at the wall line; see above).
  const auto wall = [&](double x_m, double y_m, double normal_x, double normal_y) {
    return std::max(occupancy(x_m - 0.02 * normal_x, y_m - 0.02 * normal_y),
                    occupancy(x_m + 0.02 * normal_x, y_m + 0.02 * normal_y));
  };
  EXPECT_GT(wall(7.0, kRoomMaxY, 0.0, 1.0), map.occupied_thresh);  // top
  EXPECT_GT(wall(7.0, kRoomMinY, 0.0, 1.0), map.occupied_thresh);  // bottom
  EXPECT_GT(wall(kRoomMinX, 3.0, 1.0, 0.0), map.occupied_thresh);  // left
  EXPECT_LT(occupancy(7.0, 4.5), map.free_thresh);
  EXPECT_LT(occupancy(2.5, 0.0), map.free_thresh);
  const double unknown = occupancy(9.3, 0.3);  // inside the pillar
  EXPECT_FALSE(unknown > map.occupied_thresh || unknown < map.free_thresh);
}

// The grid's own thresholds choose each cell's pixel; the YAML keeps the thresholds that decode
// the pixels as written. With free_thresh 0.25 in the YAML, map_server would read every unknown
// pixel (0.196) as free.
TEST(OccupancyGrid, TheYamlDecodesThePixelsWhateverTheGridThresholds) {
  const Room room = ScannedRoom();
  OccupancyGridConfig config;
  config.free_thresh = 0.25;
  config.occupied_thresh = 0.6;
  const OccupancyGrid grid = BuildOccupancyGrid(room.Pointers(), room.T_world_robot, config);
  const std::string yaml = testing::MakeTempDir("grid") + "/thresholds.yaml";
  WriteMapServerMap(grid, config, yaml);
  const MapServerMap map = ReadMapServerMap(yaml);
  EXPECT_DOUBLE_EQ(map.free_thresh, kMapServerFreeThresh);
  EXPECT_DOUBLE_EQ(map.occupied_thresh, kMapServerOccupiedThresh);
  std::size_t unknown = 0;
  for (int row = 0; row < map.height; ++row) {
    for (int column = 0; column < map.width; ++column) {
      const double occupancy = map.Occupancy(column, row);
      const bool free = occupancy < map.free_thresh;
      const bool occupied = occupancy > map.occupied_thresh;
      const CellState state = grid.State(column, map.height - 1 - row, config);
      EXPECT_EQ(free, state == CellState::kFree) << column << ", " << row;
      EXPECT_EQ(occupied, state == CellState::kOccupied) << column << ", " << row;
      unknown += state == CellState::kUnknown;
    }
  }
  EXPECT_GT(unknown, 0U);  // the pillar's inside at least
}

TEST(OccupancyGrid, AGlitchOfKilometresIsAnErrorNotAGigabyteGrid) {
  Room room = ScannedRoom();
  room.T_world_robot[1] = Pose2(5000.0, 5000.0, 1.4);
  try {
    BuildOccupancyGrid(room.Pointers(), room.T_world_robot, OccupancyGridConfig{});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("grid.max_cells"), std::string::npos) << error.what();
  }
  room.T_world_robot.pop_back();
  EXPECT_THROW(BuildOccupancyGrid(room.Pointers(), room.T_world_robot, OccupancyGridConfig{}),
               std::invalid_argument);  // 12 scans, 11 poses
}

TEST(OccupancyGrid, InvalidConfigsAreRefusedByName) {
  OccupancyGridConfig config;
  config.free_thresh = 0.7;
  try {
    Validate(config);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("free_thresh"), std::string::npos) << error.what();
  }
  config = {};
  config.hit_probability = 0.4;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = {};
  config.resolution_m = std::nan("");
  EXPECT_THROW(Validate(config), std::invalid_argument);
  EXPECT_NO_THROW(Validate(OccupancyGridConfig{}));
}

TEST(MapServer, BadFilesAreNamedErrors) {
  const std::string dir = testing::MakeTempDir("mapserver");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name, std::ios::binary) << text;
    return dir + "/" + name;
  };
  const auto expect_error = [](const std::string& yaml, const std::string& fragment) {
    try {
      ReadMapServerMap(yaml);
      FAIL() << "no exception for " << yaml;
    } catch (const std::exception& error) {
      EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
    }
  };
  write("ok.pgm", std::string("P5\n2 2\n255\n") + std::string(4, '\xfe'));
  expect_error(write("no_res.yaml",
                     "image: ok.pgm\norigin: [0, 0, 0]\nnegate: 0\n"
                     "occupied_thresh: 0.65\nfree_thresh: 0.196\n"),
               "missing key 'resolution'");
  expect_error(write("origin.yaml",
                     "image: ok.pgm\nresolution: 0.05\norigin: [0, 0]\nnegate: 0\n"
                     "occupied_thresh: 0.65\nfree_thresh: 0.196\n"),
               "origin must be [x, y, yaw]");
  write("short.pgm", std::string("P5\n4 4\n255\n") + std::string(5, '\0'));
  expect_error(write("short.yaml",
                     "image: short.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                     "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"),
               "4 x 4 pixels declared, 5 bytes");
  // Issue 31: files read whole were not bounded (`image: /dev/zero` read 2 GB, then bad_alloc).
  const std::string keys =
      "resolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n"
      "free_thresh: 0.196\n";
  expect_error(write("zero.yaml", "image: /dev/zero\n" + keys),
               "/dev/zero: not a binary PGM image (magic P5)");
  write("huge.pgm", "P5\n20000 20000\n255\n");
  expect_error(write("huge.yaml", "image: huge.pgm\n" + keys),
               "huge.pgm: 20000 x 20000 pixels, more than the 268435456 (16384 x 16384)");
  expect_error("/dev/zero", "/dev/zero: larger than 1 MiB, the limit of a map YAML");
  expect_error(write("twice.yaml", "image: ok.pgm\nimage: short.pgm\n" + keys),
               "twice.yaml:2: the key 'image' is given twice");
  const MapServerMap ok =
      ReadMapServerMap(write("ok.yaml",
                             "image: ok.pgm\nresolution: 0.05\norigin: [1.5, -2, 0]\nnegate: 0\n"
                             "occupied_thresh: 0.65\nfree_thresh: 0.196\n"));
  EXPECT_EQ(ok.width, 2);
  EXPECT_NEAR(ok.Occupancy(1, 1), 1.0 / 255.0, 1e-12);
}

}  // namespace
}  // namespace keyplace
