#include "keyplace/localization/map_search.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <system_error>
#include <tuple>
#include <unordered_set>
#include <utility>

#include <Eigen/Geometry>

#include "keyplace/place/dense_check.hpp"

namespace keyplace {
namespace {

// Turns searched: every 2 degrees. A beam 20 m out moves by 0.7 m over a step, but the walls
// near the robot still fit within a cell or two, enough to rank the right pose first; the answer
// only has to agree with others within FixPolicy::agree_deg.
constexpr int kRotations = kMapSearchRotations;
// The field's sigma in cells and its reach (3 sigma, rounded up).
constexpr double kSigmaCells = 1.5;
constexpr int kReachCells = 5;
// The top level of the pyramid: boxes of 2^7 = 128 cells (25.6 m on 0.2 m cells) at most.
constexpr int kMaxLevel = 7;
// The field's cells: twice the map's occupancy cells (0.2 m). A search costs about half of one
// on 0.1 m cells, and the pose needs only to agree with others within FixPolicy::agree_m.
constexpr double kFieldCellsPerOccupancyCell = 2.0;
// Beams searched: one per 0.2 m square of the window (robot frame), at most this many, evenly
// spread over the window's (the cost is linear in them).
constexpr double kThinningM = 0.2;
constexpr std::size_t kMaxPoints = 150;
// Poses scoring no more are not answers: half of the beams far from every wall.
constexpr double kMinScore = 0.5;
// A scan this close to the window's newest (odometry), in position and heading, adds nothing to
// it: a robot standing still keeps one scan, not one per 25 ms. A robot turning on the spot keeps
// one per 2 degrees, and the window at most this many.
constexpr double kStillM = 0.05;
constexpr double kStillRad = 2.0 * M_PI / 180.0;
constexpr std::size_t kMaxWindowScans = 400;
// MapField::Refine: steps from half a cell and half a turn step, halved this often (down to a
// sixteenth: 1.25 cm and 0.125 degrees on 0.2 m cells), in at most this many rounds (each moves
// or halves; about 3 moves per step size are usual).
constexpr int kRefineHalvings = 4;
constexpr int kMaxRefineRounds = 64;

std::uint8_t Closeness(double distance_cells) {
  const double value =
      std::exp(-distance_cells * distance_cells / (2.0 * kSigmaCells * kSigmaCells));
  return static_cast<std::uint8_t>(std::lround(255.0 * value));
}

// The square of kThinningM holding a point, as one key (offset so that both halves are positive).
std::uint64_t ThinningKey(const Eigen::Vector2d& point_m) {
  const auto cell = [](double metres) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(metres / kThinningM)) +
                                      (std::int64_t{1} << 30));
  };
  return (cell(point_m.x()) << 32) | cell(point_m.y());
}

}  // namespace

MapField::Cells MapField::OccupiedCells(const std::vector<Place>& places,
                                        const std::vector<char>& use) {
  if (!use.empty() && use.size() != places.size()) {
    throw std::invalid_argument("MapField: `use` must hold one flag per place (or none)");
  }
  Cells cells;
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (!use.empty() && !use[p]) continue;
    const Place& place = places[p];
    if (place.occupancy_cells.empty() || !(place.occupancy_cell_m > 0.0)) continue;
    if (cells.world_cells.empty()) {
      cells.cell_m = kFieldCellsPerOccupancyCell * place.occupancy_cell_m;
    }
    AppendCellsInFrame(place.occupancy_cells, place.occupancy_cell_m, place.T_world_place,
                       cells.cell_m, cells.world_cells);
  }
  return cells;
}

MapField::MapField(const std::vector<Place>& places, const std::vector<char>& use)
    : MapField(OccupiedCells(places, use)) {}

MapField::MapField(const Cells& cells) : cell_m_(cells.cell_m) {
  if (cells.world_cells.empty()) return;
  BuildField(cells.world_cells);
  if (empty()) return;
  BuildPyramid();
}

void MapField::BuildField(const std::vector<Eigen::Vector2i>& world_cells) {
  Eigen::Vector2i low = world_cells.front();
  Eigen::Vector2i high = world_cells.front();
  for (const Eigen::Vector2i& cell : world_cells) {
    low = low.cwiseMin(cell);
    high = high.cwiseMax(cell);
  }
  low -= Eigen::Vector2i::Constant(kReachCells);
  high += Eigen::Vector2i::Constant(kReachCells);
  const std::int64_t width_cells = std::int64_t{high.x()} - low.x() + 1;
  const std::int64_t height_cells = std::int64_t{high.y()} - low.y() + 1;
  const auto width = static_cast<std::size_t>(width_cells);
  const auto height = static_cast<std::size_t>(height_cells);
  if (width * height > kMapSearchMaxCells) return;
  width_ = static_cast<int>(width);
  height_ = static_cast<int>(height);
  // Cell c of the world covers [c, c + 1) cells: a robot in grid cell (x, y) stands at its centre.
  origin_ = (low.cast<double>() + Eigen::Vector2d::Constant(0.5)) * cell_m_;

  constexpr int kSide = 2 * kReachCells + 1;
  std::array<std::uint8_t, static_cast<std::size_t>(kSide * kSide)> kernel{};
  for (int dy = -kReachCells; dy <= kReachCells; ++dy) {
    for (int dx = -kReachCells; dx <= kReachCells; ++dx) {
      const int index = (dy + kReachCells) * kSide + dx + kReachCells;
      kernel[static_cast<std::size_t>(index)] = Closeness(std::hypot(dx, dy));
    }
  }
  std::vector<std::uint8_t> field(width * height, 0);
  for (const Eigen::Vector2i& world_cell : world_cells) {
    const Eigen::Vector2i cell = world_cell - low;
    for (int dy = -kReachCells; dy <= kReachCells; ++dy) {
      std::uint8_t* row = &field[static_cast<std::size_t>(cell.y() + dy) * width];
      const std::uint8_t* kernel_row = &kernel[static_cast<std::size_t>(dy + kReachCells) * kSide];
      for (int dx = -kReachCells; dx <= kReachCells; ++dx) {
        std::uint8_t& value = row[cell.x() + dx];
        value = std::max(value, kernel_row[dx + kReachCells]);
      }
    }
  }
  levels_.push_back(std::move(field));
}

void MapField::BuildPyramid() {
  while (static_cast<int>(levels_.size()) <= kMaxLevel &&
         (1 << levels_.size()) <= std::max(width_, height_)) {
    const std::vector<std::uint8_t>& below = levels_.back();
    const int half = 1 << (levels_.size() - 1);
    const auto at = [&](int x, int y) -> std::uint8_t {
      return x < width_ && y < height_ ? below[static_cast<std::size_t>(y) * width_ + x] : 0;
    };
    std::vector<std::uint8_t> level(below.size(), 0);
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        level[static_cast<std::size_t>(y) * width_ + x] = std::max(
            std::max(at(x, y), at(x + half, y)), std::max(at(x, y + half), at(x + half, y + half)));
      }
    }
    levels_.push_back(std::move(level));
  }
}

double MapField::ScoreAt(const std::vector<Eigen::Vector2d>& points_robot,
                         const Pose2& T_world_robot) const {
  if (empty() || points_robot.empty()) return 0.0;
  const std::vector<std::uint8_t>& field = levels_.front();
  int sum = 0;
  for (const Eigen::Vector2d& point : points_robot) {
    const Eigen::Vector2d cell = (T_world_robot * point - origin_) / cell_m_;
    const auto column = static_cast<int>(std::floor(cell.x() + 0.5));
    const auto row = static_cast<int>(std::floor(cell.y() + 0.5));
    if (column < 0 || row < 0 || column >= width_ || row >= height_) continue;
    sum += field[static_cast<std::size_t>(row) * width_ + column];
  }
  return static_cast<double>(sum) / (255.0 * static_cast<double>(points_robot.size()));
}

double MapField::InterpolatedScoreAt(const std::vector<Eigen::Vector2d>& points_robot,
                                     const Pose2& T_world_robot) const {
  if (empty() || points_robot.empty()) return 0.0;
  const std::vector<std::uint8_t>& field = levels_.front();
  const auto value = [&](int column, int row) -> double {
    if (column < 0 || row < 0 || column >= width_ || row >= height_) return 0.0;
    return field[static_cast<std::size_t>(row) * width_ + column];
  };
  double sum = 0.0;
  for (const Eigen::Vector2d& point : points_robot) {
    const Eigen::Vector2d cell = (T_world_robot * point - origin_) / cell_m_;
    const double column = std::floor(cell.x());
    const double row = std::floor(cell.y());
    // Off the field (closeness 0), or not a number: skipped before the conversion to int, which
    // would be undefined for either.
    if (!(column >= -1.0 && row >= -1.0 && column < width_ && row < height_)) continue;
    const double fx = cell.x() - column;
    const double fy = cell.y() - row;
    const auto x = static_cast<int>(column);
    const auto y = static_cast<int>(row);
    sum += (1.0 - fy) * ((1.0 - fx) * value(x, y) + fx * value(x + 1, y)) +
           fy * ((1.0 - fx) * value(x, y + 1) + fx * value(x + 1, y + 1));
  }
  return sum / (255.0 * static_cast<double>(points_robot.size()));
}

Pose2 MapField::Refine(const std::vector<Eigen::Vector2d>& points_robot,
                       const Pose2& T_world_robot) const {
  const double turn_step_rad = 2.0 * M_PI / kRotations;
  Pose2 best = T_world_robot;
  double best_score = InterpolatedScoreAt(points_robot, best);
  double step_m = cell_m_ / 2.0;
  double step_rad = turn_step_rad / 2.0;
  int halvings = 0;
  for (int round = 0; halvings < kRefineHalvings && round < kMaxRefineRounds; ++round) {
    Pose2 next = best;
    double next_score = best_score;
    for (int dt = -1; dt <= 1; ++dt) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dt == 0) continue;
          const Pose2 pose(best.x + dx * step_m, best.y + dy * step_m, best.theta + dt * step_rad);
          // Within the grid's cell and turn step: beyond them the search scored the poses.
          if (std::hypot(pose.x - T_world_robot.x, pose.y - T_world_robot.y) > cell_m_ ||
              std::abs(std::remainder(pose.theta - T_world_robot.theta, 2.0 * M_PI)) >
                  turn_step_rad) {
            continue;
          }
          const double score = InterpolatedScoreAt(points_robot, pose);
          if (score > next_score) {
            next = pose;
            next_score = score;
          }
        }
      }
    }
    if (next_score > best_score) {
      best = next;
      best_score = next_score;
    } else {
      step_m /= 2.0;
      step_rad /= 2.0;
      ++halvings;
    }
  }
  return best;
}

float MapField::Bound(const Offsets& offsets, int x, int y, int level) const {
  const std::vector<std::uint8_t>& values = levels_[static_cast<std::size_t>(level)];
  const int reach = (1 << level) - 1;  // the box's translations reach this many cells further
  const float scale = 1.0F / (255.0F * static_cast<float>(offsets.size()));
  int sum = 0;
  for (const Eigen::Vector2i& offset : offsets) {
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

void MapField::Branch(const std::vector<Offsets>& rotations, Node* nodes, std::size_t count,
                      int level, float& floor_score, const Visit& visit, long long& scored,
                      const std::atomic<bool>* stop) const {
  std::sort(nodes, nodes + count, [](const Node& a, const Node& b) {
    return a.bound > b.bound ||
           (a.bound == b.bound && std::tie(a.rotation, a.y, a.x) < std::tie(b.rotation, b.y, b.x));
  });
  for (std::size_t n = 0; n < count; ++n) {
    const Node& node = nodes[n];
    if (node.bound <= floor_score) return;
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) return;
    if (level == 0) {
      visit(node, floor_score);
      continue;
    }
    const int half = 1 << (level - 1);
    std::array<Node, 4> children;
    std::size_t kept = 0;
    for (const int dy : {0, half}) {
      for (const int dx : {0, half}) {
        if (node.x + dx >= width_ || node.y + dy >= height_) continue;
        Node child{0.0F, node.rotation, node.x + dx, node.y + dy};
        child.bound =
            Bound(rotations[static_cast<std::size_t>(child.rotation)], child.x, child.y, level - 1);
        ++scored;
        if (child.bound > floor_score) children[kept++] = child;
      }
    }
    Branch(rotations, children.data(), kept, level - 1, floor_score, visit, scored, stop);
  }
}

std::vector<MapField::Offsets> MapField::Rotations(
    const std::vector<Eigen::Vector2d>& points_robot) const {
  std::vector<Offsets> rotations(kRotations);
  for (int k = 0; k < kRotations; ++k) {
    const Eigen::Rotation2Dd turn(2.0 * M_PI * k / kRotations);
    for (const Eigen::Vector2d& point : points_robot) {
      const Eigen::Vector2d cells = turn * point / cell_m_;
      rotations[static_cast<std::size_t>(k)].emplace_back(static_cast<int>(std::lround(cells.x())),
                                                          static_cast<int>(std::lround(cells.y())));
    }
  }
  return rotations;
}

bool MapField::Distinct(const Node& a, const Node& b) const {
  const int turn = std::abs(a.rotation - b.rotation);
  const double turn_deg = 360.0 * std::min(turn, kRotations - turn) / kRotations;
  const double shift_m = cell_m_ * std::hypot(a.x - b.x, a.y - b.y);
  return shift_m > kMapSearchDistinctM || turn_deg > kMapSearchDistinctDeg;
}

MapSearchResult MapField::Search(const std::vector<Eigen::Vector2d>& points_robot, double min_score,
                                 double min_margin, const std::atomic<bool>* stop) const {
  MapSearchResult result;
  if (empty() || points_robot.empty()) return result;
  const std::vector<Offsets> rotations = Rotations(points_robot);
  const int top = static_cast<int>(levels_.size()) - 1;
  const int step_cells = 1 << top;
  std::vector<Node> roots;
  for (int k = 0; k < kRotations; ++k) {
    for (int y = 0; y < height_; y += step_cells) {
      for (int x = 0; x < width_; x += step_cells) {
        roots.push_back({Bound(rotations[static_cast<std::size_t>(k)], x, y, top), k, x, y});
      }
    }
  }
  result.nodes = static_cast<long long>(roots.size());

  std::optional<Node> best;
  float floor_score = static_cast<float>(min_score);
  std::vector<Node> nodes = roots;
  Branch(
      rotations, nodes.data(), nodes.size(), top, floor_score,
      [&best](const Node& node, float& at_least) {
        best = node;
        at_least = node.bound;
      },
      result.nodes, stop);
  const auto stopped = [stop] { return stop != nullptr && stop->load(); };
  if (!best || stopped()) return result;
  result.score = best->bound;
  const Eigen::Vector2d position = origin_ + cell_m_ * Eigen::Vector2d(best->x, best->y);
  result.T_world_robot =
      Pose2(position.x(), position.y(),
            std::remainder(2.0 * M_PI * best->rotation / kRotations, 2.0 * M_PI));

  // A distinct pose within the margin of the best, whatever it scores: only boxes that could hold
  // one are searched, and the first found ends the search.
  std::optional<Node> rival;
  floor_score = best->bound - static_cast<float>(min_margin);
  nodes = roots;
  Branch(
      rotations, nodes.data(), nodes.size(), top, floor_score,
      [&](const Node& node, float& at_least) {
        if (!Distinct(node, *best)) return;
        rival = node;
        at_least = 2.0F;  // above every bound: the search stops
      },
      result.nodes, stop);
  result.found = !rival && !stopped();
  result.rival_score = rival ? rival->bound : 0.0;
  return result;
}

MapSearch::MapSearch(double window_m, double every_m, double min_margin, bool background)
    : window_m_(window_m), every_m_(every_m), min_margin_(min_margin), background_(background) {}

void MapSearch::RunningSlot::Stop() {
  if (!search) return;
  search->stop->store(true);
  search->future.wait();
  search.reset();
}

void MapSearch::Cancel() { StopSearch(true); }

void MapSearch::StopSearch(bool keep_field) {
  if (!running_.search) return;
  Running stopped = std::move(*running_.search);
  running_.search.reset();
  searched_at_m_ = stopped.launched_at_m;
  stopped.stop->store(true);
  if (!keep_field) {
    stopped.future.wait();
    return;
  }
  // The search checks its stop only once its field is built: the wait is for the rest of that
  // build, and the field then serves the next search of the same places.
  try {
    Searched searched = stopped.future.get();
    if (searched.field) {
      field_ = std::move(searched.field);
      field_key_ = std::move(stopped.key);
    }
  } catch (...) {
    // A stopped search is dropped unanswered, whatever ended it; a search of the same places
    // builds the field again and meets the same failure there.
  }
}

void MapSearch::AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id) {
  if (window_m_ <= 0.0) return;
  if (last_T_odom_robot_) {
    odometry_m_ += TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
  }
  last_T_odom_robot_ = T_odom_robot;
  if (!recent_.empty()) {
    const Pose2 moved = Between(recent_.back().T_odom_robot, T_odom_robot);
    if (TranslationNorm(moved) < kStillM && std::abs(moved.theta) < kStillRad) return;
  }
  recent_.push_back(
      {T_odom_robot, DenseScanPoints(scan).endpoints_m, scan_id, odometry_m_, scans_kept_++});
  // Keep the scans of the last window_m, and the one before them: the window spans window_m.
  while (recent_.size() > 2 && odometry_m_ - recent_[1].odometry_m >= window_m_) {
    recent_.pop_front();
  }
  while (recent_.size() > kMaxWindowScans) recent_.pop_front();
}

void MapSearch::Reset(bool forget_field) {
  Cancel();
  recent_.clear();
  last_T_odom_robot_.reset();
  odometry_m_ = 0.0;
  searched_at_m_.reset();
  if (forget_field) {
    field_.reset();
    field_key_ = FieldKey{};
  }
}

MapSearch::Window MapSearch::CurrentWindow() const {
  Window window;
  window.T_odom_newest = recent_.back().T_odom_robot;
  window.T_odom_oldest = recent_.front().T_odom_robot;
  window.scans = recent_.size();
  window.first_number = recent_.front().number;
  window.last_number = recent_.back().number;
  const Pose2 T_newest_odom = window.T_odom_newest.inverse();
  std::vector<Eigen::Vector2d> points;
  std::unordered_set<std::uint64_t> taken;
  // Newest first: where squares are shared, the newest scan's beam stands for them.
  for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
    const Pose2 T_newest_robot = T_newest_odom * it->T_odom_robot;
    for (const Eigen::Vector2d& endpoint : it->endpoints_robot) {
      const Eigen::Vector2d point = T_newest_robot * endpoint;
      if (taken.insert(ThinningKey(point)).second) points.push_back(point);
    }
  }
  for (const Recent& recent : recent_) window.scan_ids.push_back(recent.scan_id);
  if (points.size() <= kMaxPoints) {
    window.points_robot = std::move(points);
    return window;
  }
  const double stride = static_cast<double>(points.size()) / kMaxPoints;
  for (std::size_t k = 0; k < kMaxPoints; ++k) {
    window.points_robot.push_back(
        points[static_cast<std::size_t>(static_cast<double>(k) * stride)]);
  }
  return window;
}

std::optional<LocalizationResult> MapSearch::Search(const PlaceRecognizer& recognizer,
                                                    const QueryExclusion& exclusion) {
  // A search begun for another map (or places) than this call's would answer for the wrong one.
  // Its field is not kept: the map it was built for is the one most likely destroyed next, and
  // a recognizer made at the same address would take it for its own.
  if (running_.search && &recognizer != running_.search->key.recognizer) StopSearch(false);
  if (running_.search) {
    if (!search_ended()) return std::nullopt;
    // Out of the slot before get(), which rethrows what the search threw: no search is left
    // running either way.
    Running ended = std::move(*running_.search);
    running_.search.reset();
    searched_at_m_ = ended.launched_at_m;
    return TakeAnswer(ended.future.get(), ended.window, std::move(ended.key));
  }
  if (window_m_ <= 0.0 || recent_.empty()) return std::nullopt;
  // Every every_m, the first as soon as the robot has moved every_m: a window too short to tell
  // places apart gives no answer (the margin), and one that can should not wait for window_m.
  if (odometry_m_ - searched_at_m_.value_or(0.0) < every_m_) return std::nullopt;

  Window window = CurrentWindow();
  FieldKey key{&recognizer, {}};
  if (exclusion) {
    for (const Place& place : recognizer.places()) {
      key.use.push_back(!exclusion(place, window.scan_ids));
    }
  }
  // A field of other places is built with the search, on its thread in the background: a scan
  // does not wait for it (under an exclusion, as in protocol (a) of `keyplace relocalize`, the
  // places allowed change with the window). Their cells are read here: the recognizer may change
  // once the search is stopped.
  std::shared_ptr<const MapField> field = key == field_key_ ? field_ : nullptr;
  std::shared_ptr<const MapField::Cells> cells;
  if (!field) {
    cells = std::make_shared<const MapField::Cells>(
        MapField::OccupiedCells(recognizer.places(), key.use));
    ++fields_built_;
  }
  const auto search = [field, cells, points = window.points_robot,
                       margin = min_margin_](const std::atomic<bool>* stop) {
    const auto start = std::chrono::steady_clock::now();
    Searched result;
    result.field = field ? field : std::make_shared<const MapField>(*cells);
    result.result = result.field->Search(points, kMinScore, margin, stop);
    if (result.result.found) {
      result.T_world_robot = result.field->Refine(points, result.result.T_world_robot);
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  if (background_) {
    const auto stop = std::make_shared<std::atomic<bool>>(false);
    try {
      std::future<Searched> future =
          std::async(std::launch::async, [search, stop] { return search(stop.get()); });
      running_.search =
          Running{std::move(window), std::move(key), stop, std::move(future), odometry_m_};
      return std::nullopt;
    } catch (const std::system_error&) {
      // No thread to be had: the search runs here, late rather than never.
    }
  }
  searched_at_m_ = odometry_m_;
  return TakeAnswer(search(nullptr), window, std::move(key));
}

std::optional<LocalizationResult> MapSearch::TakeAnswer(const Searched& searched,
                                                        const Window& window, FieldKey key) {
  field_ = searched.field;
  field_key_ = std::move(key);
  ++searches_;
  search_s_ += searched.seconds;
  if (!searched.result.found) return std::nullopt;
  LocalizationResult answer;
  answer.found = true;
  // No distinct pose comes within the margin: that margin is what the answer is sure of.
  answer.confidence = min_margin_;
  answer.T_world_odom = searched.T_world_robot * window.T_odom_newest.inverse();
  answer.T_world_robot =
      last_T_odom_robot_ ? answer.T_world_odom * *last_T_odom_robot_ : searched.T_world_robot;
  answer.scans = window.scans;
  answer.scan_ids = window.scan_ids;
  answer.T_odom_origin = window.T_odom_oldest;
  answer.window_first_scan = window.first_number;
  answer.window_last_scan = window.last_number;
  // The grid's resolution, kept though the pose is refined: the refinement's centimetre on a
  // simulated hall (MapSearch.FindsWhereTheBeamsFitInAnOpenHall) is not what a real map's walls
  // and a window's odometry drift allow, and nothing measured yet says by how much to shrink it.
  const double step_rad = 2.0 * M_PI / kRotations;
  const double cell_m = searched.field->cell_m();
  answer.match.estimated_pose_covariance =
      Eigen::Vector3d(cell_m * cell_m, cell_m * cell_m, step_rad * step_rad).asDiagonal();
  return answer;
}

}  // namespace keyplace
