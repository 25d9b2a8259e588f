#include "keyplace/localization/map_search.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "keyplace/place/dense_check.hpp"

namespace keyplace {
namespace {

// Rotations searched: every 2 degrees. A beam 20 m out moves by 0.7 m over a step, but the walls
// near the robot still fit within a cell or two, enough to rank the right pose first; the answer
// only has to agree with others within FixPolicy::agree_deg.
constexpr int kRotations = kMapSearchRotations;
// The field's sigma in cells and its reach (3 sigma, rounded up).
constexpr double kSigmaCells = 1.5;
constexpr int kReachCells = 5;
// The top level of the pyramid: boxes of 2^7 = 128 cells (12.8 m on 0.1 m cells) at most.
constexpr int kMaxLevel = 7;
// The field's cells: twice the map's occupancy cells (0.2 m). A search is a few times cheaper
// than on 0.1 m cells, and the pose needs only to agree with others within FixPolicy::agree_m.
constexpr double kFieldCellsPerOccupancyCell = 2.0;
// Beams searched: one per 0.2 m square of the window (robot frame), at most this many, evenly
// spread over the window's (cost is linear in them).
constexpr double kThinningM = 0.2;
constexpr std::size_t kMaxPoints = 150;
// Poses scoring less are not answers: fewer than half of the beams near a wall.
constexpr double kMinScore = 0.5;
std::uint8_t Closeness(double distance_cells) {
  const double value =
      std::exp(-distance_cells * distance_cells / (2.0 * kSigmaCells * kSigmaCells));
  return static_cast<std::uint8_t>(std::lround(255.0 * value));
}

}  // namespace

MapField::MapField(const std::vector<Place>& places, const std::vector<char>& use) {
  std::vector<Eigen::Vector2i> cells;
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (!use.empty() && !use[p]) continue;
    const Place& place = places[p];
    if (place.occupancy_cells.empty() || !(place.occupancy_cell_m > 0.0)) continue;
    if (cells.empty()) cell_m_ = kFieldCellsPerOccupancyCell * place.occupancy_cell_m;
    AppendCellsInFrame(place.occupancy_cells, place.occupancy_cell_m, place.T_world_place, cell_m_,
                       cells);
  }
  if (cells.empty()) return;
  Eigen::Vector2i low = cells.front();
  Eigen::Vector2i high = cells.front();
  for (const Eigen::Vector2i& cell : cells) {
    low = low.cwiseMin(cell);
    high = high.cwiseMax(cell);
  }
  low -= Eigen::Vector2i::Constant(kReachCells);
  high += Eigen::Vector2i::Constant(kReachCells);
  width_ = high.x() - low.x() + 1;
  height_ = high.y() - low.y() + 1;
  // Cell c of the world covers [c, c + 1) cells: a robot in grid cell (x, y) stands at its centre.
  origin_ = (low.cast<double>() + Eigen::Vector2d::Constant(0.5)) * cell_m_;

  std::vector<std::uint8_t> field(static_cast<std::size_t>(width_) * height_, 0);
  std::vector<std::uint8_t> kernel;
  for (int dy = -kReachCells; dy <= kReachCells; ++dy) {
    for (int dx = -kReachCells; dx <= kReachCells; ++dx) {
      kernel.push_back(Closeness(std::hypot(dx, dy)));
    }
  }
  constexpr int kSide = 2 * kReachCells + 1;
  for (const Eigen::Vector2i& world_cell : cells) {
    const Eigen::Vector2i cell = world_cell - low;
    for (int dy = -kReachCells; dy <= kReachCells; ++dy) {
      std::uint8_t* row = &field[static_cast<std::size_t>(cell.y() + dy) * width_];
      const std::uint8_t* kernel_row = &kernel[static_cast<std::size_t>(dy + kReachCells) * kSide];
      for (int dx = -kReachCells; dx <= kReachCells; ++dx) {
        std::uint8_t& value = row[cell.x() + dx];
        value = std::max(value, kernel_row[dx + kReachCells]);
      }
    }
  }
  levels_.push_back(std::move(field));
  while (static_cast<int>(levels_.size()) <= kMaxLevel &&
         (1 << levels_.size()) <= std::max(width_, height_)) {
    const std::vector<std::uint8_t>& below = levels_.back();
    const int half = 1 << (levels_.size() - 1);
    std::vector<std::uint8_t> level(below.size(), 0);
    const auto at = [&](int x, int y) -> std::uint8_t {
      return x < width_ && y < height_ ? below[static_cast<std::size_t>(y) * width_ + x] : 0;
    };
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        level[static_cast<std::size_t>(y) * width_ + x] = std::max(
            std::max(at(x, y), at(x + half, y)), std::max(at(x, y + half), at(x + half, y + half)));
      }
    }
    levels_.push_back(std::move(level));
  }
}

float MapField::Bound(const Rotation& rotation, int x, int y, int level, float floor) const {
  const std::vector<std::uint8_t>& values = levels_[static_cast<std::size_t>(level)];
  const int reach = (1 << level) - 1;  // the box's translations reach this many cells further
  const int count = static_cast<int>(rotation.offsets.size());
  const float scale = 1.0F / (255.0F * static_cast<float>(count));
  // The sum stays at or below the floor once the points left could not lift it above.
  const int floor_sum = static_cast<int>(std::floor(floor * 255.0F * static_cast<float>(count)));
  int sum = 0;
  for (int k = 0; k < count; ++k) {
    if ((k & 15) == 0 && sum + 255 * (count - k) <= floor_sum) {
      return static_cast<float>(sum + 255 * (count - k)) * scale;
    }
    const Eigen::Vector2i& offset = rotation.offsets[static_cast<std::size_t>(k)];
    int column = x + offset.x();
    int row = y + offset.y();
    if (column + reach < 0 || row + reach < 0 || column >= width_ || row >= height_) continue;
    // A point left of or below the grid for the box's first translations enters it for its
    // later ones: the maxima from the edge cover them.
    column = std::max(column, 0);
    row = std::max(row, 0);
    sum += values[static_cast<std::size_t>(row) * width_ + column];
  }
  return static_cast<float>(sum) * scale;
}

void MapField::Branch(const std::vector<Rotation>& rotations, std::vector<Node>& nodes, int level,
                      float& floor, const Visit& visit, long long& count) const {
  std::sort(nodes.begin(), nodes.end(), [](const Node& a, const Node& b) {
    return a.bound > b.bound ||
           (a.bound == b.bound && std::tie(a.rotation, a.y, a.x) < std::tie(b.rotation, b.y, b.x));
  });
  for (const Node& node : nodes) {
    if (node.bound <= floor) return;
    if (level == 0) {
      visit(node, floor);
      continue;
    }
    const int half = 1 << (level - 1);
    std::vector<Node> children;
    for (const int dy : {0, half}) {
      for (const int dx : {0, half}) {
        if (node.x + dx >= width_ || node.y + dy >= height_) continue;
        Node child{0.0F, node.rotation, node.x + dx, node.y + dy};
        child.bound = Bound(rotations[static_cast<std::size_t>(child.rotation)], child.x, child.y,
                            level - 1, floor);
        ++count;
        if (child.bound > floor) children.push_back(child);
      }
    }
    Branch(rotations, children, level - 1, floor, visit, count);
  }
}

std::vector<MapField::Rotation> MapField::Rotations(
    const std::vector<Eigen::Vector2d>& points_robot) const {
  std::vector<Rotation> rotations(kRotations);
  for (int k = 0; k < kRotations; ++k) {
    Rotation& rotation = rotations[static_cast<std::size_t>(k)];
    rotation.index = k;
    rotation.theta_rad = 2.0 * M_PI * k / kRotations;
    const Eigen::Rotation2Dd turn(rotation.theta_rad);
    for (const Eigen::Vector2d& point : points_robot) {
      const Eigen::Vector2d cells = turn * point / cell_m_;
      rotation.offsets.emplace_back(static_cast<int>(std::lround(cells.x())),
                                    static_cast<int>(std::lround(cells.y())));
    }
  }
  return rotations;
}

bool MapField::Distinct(const std::vector<Rotation>& rotations, const Node& a,
                        const Node& b) const {
  const int turn = std::abs(rotations[static_cast<std::size_t>(a.rotation)].index -
                            rotations[static_cast<std::size_t>(b.rotation)].index);
  const double turn_deg = 360.0 * std::min(turn, kRotations - turn) / kRotations;
  const double shift_m = cell_m_ * std::hypot(a.x - b.x, a.y - b.y);
  return shift_m > kMapSearchDistinctM || turn_deg > kMapSearchDistinctDeg;
}

MapSearchResult MapField::Search(const std::vector<Eigen::Vector2d>& points_robot, double min_score,
                                 double min_margin) const {
  MapSearchResult result;
  if (empty() || points_robot.empty()) return result;
  const std::vector<Rotation> rotations = Rotations(points_robot);
  const int top = static_cast<int>(levels_.size()) - 1;
  const int step = 1 << top;
  std::vector<Node> roots;
  for (int k = 0; k < static_cast<int>(rotations.size()); ++k) {
    for (int y = 0; y < height_; y += step) {
      for (int x = 0; x < width_; x += step) {
        roots.push_back({Bound(rotations[static_cast<std::size_t>(k)], x, y, top, -1.0F), k, x, y});
      }
    }
  }
  result.nodes = static_cast<long long>(roots.size());

  std::optional<Node> best;
  float floor = static_cast<float>(min_score);
  std::vector<Node> nodes = roots;
  Branch(
      rotations, nodes, top, floor,
      [&best](const Node& node, float& at_least) {
        best = node;
        at_least = node.bound;
      },
      result.nodes);
  if (!best) return result;
  result.score = best->bound;
  const double theta = rotations[static_cast<std::size_t>(best->rotation)].theta_rad;
  const Eigen::Vector2d position = origin_ + cell_m_ * Eigen::Vector2d(best->x, best->y);
  result.T_world_robot = Pose2(position.x(), position.y(), std::remainder(theta, 2.0 * M_PI));

  // A distinct pose within the margin of the best: only boxes that could hold one are searched,
  // and the first found ends the search.
  std::optional<Node> runner_up;
  floor = std::max(static_cast<float>(min_score), best->bound - static_cast<float>(min_margin));
  nodes = roots;
  Branch(
      rotations, nodes, top, floor,
      [&](const Node& node, float& at_least) {
        if (!Distinct(rotations, node, *best)) return;
        runner_up = node;
        at_least = 2.0F;  // above every bound: the search stops
      },
      result.nodes);
  result.found = !runner_up;
  result.runner_up = runner_up ? runner_up->bound : 0.0;
  return result;
}

MapSearch::MapSearch(double window_m, double min_margin)
    : window_m_(window_m), min_margin_(min_margin) {}

void MapSearch::AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id) {
  if (window_m_ <= 0.0) return;
  if (!recent_.empty()) {
    odometry_m_ += TranslationNorm(Between(recent_.back().T_odom_robot, T_odom_robot));
  }
  recent_.push_back({T_odom_robot, DenseScanPoints(scan).endpoints_m, scan_id, odometry_m_});
  // Keep the scans of the last window_m, and the one before them: the window spans window_m.
  while (recent_.size() > 2 && odometry_m_ - recent_[1].odometry_m >= window_m_) {
    recent_.pop_front();
  }
}

void MapSearch::Reset() {
  recent_.clear();
  odometry_m_ = 0.0;
  searched_at_m_ = 0.0;
}

const MapField& MapSearch::FieldFor(const PlaceRecognizer& recognizer,
                                    const std::vector<char>& use) {
  if (!field_ || field_recognizer_ != &recognizer || use != field_use_) {
    field_ = std::make_shared<const MapField>(recognizer.places(), use);
    field_use_ = use;
    field_recognizer_ = &recognizer;
  }
  return *field_;
}

std::optional<LocalizationResult> MapSearch::Search(const PlaceRecognizer& recognizer,
                                                    const QueryExclusion& exclusion) {
  if (window_m_ <= 0.0 || recent_.empty()) return std::nullopt;
  if (odometry_m_ - recent_.front().odometry_m < window_m_) return std::nullopt;
  if (odometry_m_ - searched_at_m_ < window_m_ && searched_at_m_ > 0.0) return std::nullopt;
  searched_at_m_ = odometry_m_;

  const Pose2 T_odom_latest = recent_.back().T_odom_robot;
  const Pose2 T_latest_odom = T_odom_latest.inverse();
  std::vector<Eigen::Vector2d> points;
  std::unordered_set<long long> taken;
  std::vector<int> scan_ids;
  for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
    scan_ids.push_back(it->scan_id);
    const Pose2 T_latest_robot = T_latest_odom * it->T_odom_robot;
    for (const Eigen::Vector2d& endpoint : it->endpoints_robot) {
      const Eigen::Vector2d point = T_latest_robot * endpoint;
      const long long key = (static_cast<long long>(std::floor(point.x() / kThinningM)) << 32) ^
                            static_cast<long long>(std::floor(point.y() / kThinningM) + (1 << 30));
      if (taken.insert(key).second) points.push_back(point);
    }
  }
  std::reverse(scan_ids.begin(), scan_ids.end());
  if (points.size() > kMaxPoints) {
    std::vector<Eigen::Vector2d> thinned;
    const double stride = static_cast<double>(points.size()) / kMaxPoints;
    for (std::size_t k = 0; k < kMaxPoints; ++k) {
      thinned.push_back(points[static_cast<std::size_t>(k * stride)]);
    }
    points = std::move(thinned);
  }
  std::vector<char> use;
  if (exclusion) {
    for (const Place& place : recognizer.places()) use.push_back(!exclusion(place, scan_ids));
  }
  const MapField& field = FieldFor(recognizer, use);
  const MapSearchResult found = field.Search(points, kMinScore, min_margin_);
  if (!found.found) return std::nullopt;

  LocalizationResult answer;
  answer.found = true;
  answer.confidence = std::clamp(found.score - found.runner_up, 0.0, 1.0);
  answer.T_world_robot = found.T_world_robot;
  answer.T_world_odom = found.T_world_robot * T_latest_odom;
  answer.scans = recent_.size();
  answer.scan_ids = scan_ids;
  answer.T_odom_origin = recent_.front().T_odom_robot;
  const double cell_m = field.cell_m();
  const double step_rad = 2.0 * M_PI / kRotations;
  answer.match.estimated_pose_covariance =
      Eigen::Vector3d(cell_m * cell_m, cell_m * cell_m, step_rad * step_rad).asDiagonal();
  return answer;
}

}  // namespace keyplace
