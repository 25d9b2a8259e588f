// The search of the whole map by the beams: it must find where the robot's last metres of scans
// fit when the keypoints say nothing, and say nothing itself where two places fit alike.

#include "keyplace/localization/map_search.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/place/dense_check.hpp"
#include "localization/simulated_drive.hpp"

namespace keyplace {
namespace {

using testing::DegToRad;
using testing::Drive;
using testing::Simulate;
using testing::SimulatedDrive;
using testing::TwoRooms;

const GlobalMap& Map() {
  static const GlobalMap map = testing::TwoRoomsMap();
  return map;
}

const PlaceRecognizer& Recognizer() {
  static const PlaceRecognizer recognizer(PlacesFromMap(Map()), PlaceRecognitionConfig{});
  return recognizer;
}

// The robot's odometry frame: where it woke up, unknown to the map.
const Pose2 kTWorldOdom(3.0, -1.0, 0.7);

bool Near(const Pose2& a, const Pose2& b, double within_m, double within_deg) {
  const Pose2 difference = Between(a, b);
  return TranslationNorm(difference) < within_m &&
         std::abs(difference.theta) < DegToRad(within_deg);
}

// Feeds `drive` to a MapSearch of window_m (searching every window_m) and returns its answers,
// by scan.
std::vector<std::optional<LocalizationResult>> Answers(const SimulatedDrive& drive,
                                                       double window_m) {
  MapSearch search(window_m, window_m, LocalizerConfig{}.map_search_margin);
  std::vector<std::optional<LocalizationResult>> answers;
  for (std::size_t i = 0; i < drive.scans.size(); ++i) {
    search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
    answers.push_back(search.Search(Recognizer(), {}));
  }
  return answers;
}

// A 30 x 20 m hall with two alcoves and six pillars, scanned every metre: what keypoints rarely
// recognise (docs/notes/open-halls.md), and where the walls alone tell every place apart.
std::vector<testing::Segment> OpenHall() {
  std::vector<testing::Segment> world = testing::Polygon({{0, 0},
                                                          {30, 0},
                                                          {30, 8},
                                                          {27, 8},
                                                          {27, 12},
                                                          {30, 12},
                                                          {30, 20},
                                                          {12, 20},
                                                          {12, 17},
                                                          {8, 17},
                                                          {8, 20},
                                                          {0, 20}});
  for (const Eigen::Vector2d& pillar :
       {Eigen::Vector2d(6, 5), Eigen::Vector2d(14, 6), Eigen::Vector2d(22, 4),
        Eigen::Vector2d(9, 13), Eigen::Vector2d(19, 14), Eigen::Vector2d(25, 16)}) {
    testing::Append(world,
                    testing::Polygon(
                        {pillar + Eigen::Vector2d(-0.3, -0.3), pillar + Eigen::Vector2d(0.3, -0.3),
                         pillar + Eigen::Vector2d(0.3, 0.3), pillar + Eigen::Vector2d(-0.3, 0.3)}));
  }
  return world;
}

// Scans of the hall about every metre along `waypoints` (true poses; keypoints by FLIRT), from
// a full-circle laser of 20 m.
SimulatedDrive HallDrive(const std::vector<Eigen::Vector2d>& waypoints, unsigned seed) {
  const std::vector<Pose2> dense = Drive(waypoints);  // 0.15 m steps
  std::vector<Pose2> sparse;
  for (std::size_t i = 0; i < dense.size(); i += 7) sparse.push_back(dense[i]);
  testing::ScanOptions options;
  options.max_range_m = 20.0;
  options.range_noise_m = 0.01;
  return Simulate(OpenHall(), sparse, seed, options);
}

const GlobalMap& HallMap() {
  static const GlobalMap map = [] {
    const SimulatedDrive mapping =
        HallDrive({{2, 2}, {28, 2}, {28, 18}, {2, 18}, {2, 4}, {15, 10}, {26, 10}}, 6);
    return BuildGlobalMap({mapping.scans, mapping.truth, mapping.keypoints}, MappingConfig{});
  }();
  return map;
}

// Another drive through the hall, on paths of its own.
SimulatedDrive HallQuery() { return HallDrive({{4, 15}, {16, 3}, {24, 8}, {20, 17}}, 7); }

// Searches every 2 m, the first once the robot has moved 2 m, over the scans of the last 5 m at
// most.
TEST(MapSearch, FindsWhereTheBeamsFitInAnOpenHall) {
  const PlaceRecognizer recognizer(PlacesFromMap(HallMap()), PlaceRecognitionConfig{});
  const SimulatedDrive drive = HallQuery();
  MapSearch search(5.0, 2.0, LocalizerConfig{}.map_search_margin);
  int found = 0;
  std::vector<double> path_m{0.0};
  std::optional<double> answered_at_m;
  std::optional<long long> last_window_scan;
  double sum_error_m = 0.0;
  double worst_error_m = 0.0;
  double worst_error_deg = 0.0;
  for (std::size_t i = 0; i < drive.scans.size(); ++i) {
    if (i > 0) {
      path_m.push_back(path_m.back() +
                       TranslationNorm(Between(drive.truth[i - 1], drive.truth[i])));
    }
    search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
    const std::optional<LocalizationResult> answer = search.Search(recognizer, {});
    if (!answer) continue;
    ++found;
    SCOPED_TRACE(i);
    EXPECT_GE(path_m[i] - answered_at_m.value_or(0.0), 2.0 - 1e-9);
    if (!answered_at_m) {
      EXPECT_LT(path_m[i], 5.0);  // not waiting for a whole window
    }
    answered_at_m = path_m[i];
    // The window: the scans of the last 5 m and the one before them (scans about 1 m apart).
    const double window_m = path_m[i] - path_m[static_cast<std::size_t>(answer->scan_ids.front())];
    EXPECT_LT(window_m, 5.0 + 1.2);
    if (path_m[i] >= 6.2) {
      EXPECT_GE(window_m, 5.0);
    }
    // The window's scans are numbered as kept; windows 2 m apart share scans (FixFilter does not
    // let such answers confirm each other).
    EXPECT_EQ(answer->window_last_scan - answer->window_first_scan + 1,
              static_cast<long long>(answer->scans));
    if (last_window_scan) {
      EXPECT_LT(answer->window_first_scan, *last_window_scan);
    }
    last_window_scan = answer->window_last_scan;
    EXPECT_TRUE(answer->found);
    EXPECT_DOUBLE_EQ(answer->confidence, LocalizerConfig{}.map_search_margin);
    const Pose2 error = Between(drive.truth[i], answer->T_world_robot);
    sum_error_m += TranslationNorm(error);
    worst_error_m = std::max(worst_error_m, TranslationNorm(error));
    worst_error_deg = std::max(worst_error_deg, std::abs(error.theta) * 180.0 / M_PI);
    // The map <- odometry correction carries the robot's pose (its error grows with the lever
    // arm from the odometry origin, so it is checked through the robot).
    EXPECT_TRUE(Near(answer->T_world_odom * (kTWorldOdom.inverse() * drive.truth[i]),
                     answer->T_world_robot, 1e-6, 1e-6));
    EXPECT_EQ(answer->scan_ids.back(), static_cast<int>(i));
  }
  // One search per 2 m of the 37 m drive, most of them finding the robot.
  ASSERT_GE(found, 10);
  // Refined between the search's 0.2 m cells and 2 degree turns (MapField::Refine). On the grid
  // alone: mean 0.076 m, worst 0.142 m and 1.0 degree; refined 0.007 m, 0.013 m and 0.09 degrees.
  EXPECT_LT(sum_error_m / found, 0.03);
  EXPECT_LT(worst_error_m, 0.05);
  EXPECT_LT(worst_error_deg, 0.5);
}

// Calls Search until a background search has ended and been taken, for at most 60 s.
std::optional<LocalizationResult> AwaitSearch(MapSearch& search,
                                              const PlaceRecognizer& recognizer) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (search.searching() && std::chrono::steady_clock::now() < give_up) {
    if (std::optional<LocalizationResult> answer = search.Search(recognizer, {})) return answer;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return std::nullopt;
}

// In the background the same searches run and find the same poses: an answer taken two scans
// after its search began still puts the odometry frame where it is, and the robot where it is
// now.
TEST(MapSearch, InTheBackgroundAnswersWithTheScanItIsTakenAt) {
  const PlaceRecognizer recognizer(PlacesFromMap(HallMap()), PlaceRecognitionConfig{});
  const SimulatedDrive drive = HallQuery();
  MapSearch inline_search(5.0, 5.0, LocalizerConfig{}.map_search_margin);
  MapSearch background(5.0, 5.0, LocalizerConfig{}.map_search_margin, true);
  std::vector<std::size_t> found_inline;
  std::vector<std::size_t> found_background;
  std::optional<std::size_t> take_at;
  for (std::size_t i = 0; i < drive.scans.size(); ++i) {
    const Pose2 T_odom_robot = kTWorldOdom.inverse() * drive.truth[i];
    inline_search.AddScan(drive.scans[i], T_odom_robot, static_cast<int>(i));
    background.AddScan(drive.scans[i], T_odom_robot, static_cast<int>(i));
    if (const std::optional<LocalizationResult> answer = inline_search.Search(recognizer, {})) {
      found_inline.push_back(i + 2);
    }
    std::optional<LocalizationResult> answer;
    if (!take_at) {
      answer = background.Search(recognizer, {});
      if (background.searching()) take_at = i + 2;
    } else if (i == *take_at) {
      answer = AwaitSearch(background, recognizer);
      take_at.reset();
    }
    if (!answer) continue;
    found_background.push_back(i);
    SCOPED_TRACE(i);
    EXPECT_TRUE(Near(answer->T_world_robot, drive.truth[i], 0.3, 3.5));
    EXPECT_EQ(answer->scan_ids.back() + 2, static_cast<int>(i));
  }
  EXPECT_FALSE(background.searching());
  EXPECT_EQ(background.searches(), inline_search.searches());
  EXPECT_EQ(found_background, found_inline);
  EXPECT_GE(found_inline.size(), 5U);
  EXPECT_GT(background.search_s(), 0.0);
}

// A search still running is stopped by Reset, uncounted, and not copied: the copy searches
// that window again.
TEST(MapSearch, ResetStopsABackgroundSearchAndACopySearchesAgain) {
  const PlaceRecognizer recognizer(PlacesFromMap(HallMap()), PlaceRecognitionConfig{});
  const SimulatedDrive drive = HallQuery();
  MapSearch search(5.0, 5.0, LocalizerConfig{}.map_search_margin, true);
  std::size_t i = 0;
  for (; i < drive.scans.size() && !search.searching(); ++i) {
    search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
    search.Search(recognizer, {});
  }
  ASSERT_TRUE(search.searching());
  ASSERT_LT(i, drive.scans.size());
  MapSearch copy = search;
  EXPECT_FALSE(copy.searching());
  EXPECT_TRUE(copy.background());
  EXPECT_FALSE(copy.Search(recognizer, {}).has_value());
  EXPECT_TRUE(copy.searching());  // the same window, due again
  search.Reset();
  EXPECT_FALSE(search.searching());
  EXPECT_EQ(search.searches(), 0);
  // After the reset the window starts again: nothing is due before another 5 m.
  search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
  EXPECT_FALSE(search.Search(recognizer, {}).has_value());
  EXPECT_FALSE(search.searching());
}

// The field of the places searched serves the next search of the same places, and only that:
// a search of other places (here none) builds theirs, and the first places' field is then built
// again. Reusing a field for other places would answer from places the exclusion forbids.
TEST(MapSearch, KeepsTheFieldOnlyForTheSamePlaces) {
  const PlaceRecognizer recognizer(PlacesFromMap(HallMap()), PlaceRecognitionConfig{});
  const SimulatedDrive drive = HallQuery();
  const QueryExclusion everything = [](const Place&, const std::vector<int>&) { return true; };
  MapSearch search(5.0, 2.0, LocalizerConfig{}.map_search_margin);
  // Which places each search may use (all, all, none, all) and the fields built after it.
  const std::vector<std::pair<bool, long long>> steps{{true, 1}, {true, 1}, {false, 2}, {true, 3}};
  std::size_t step = 0;
  for (std::size_t i = 0; i < drive.scans.size() && step < steps.size(); ++i) {
    search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
    const auto [all_places, built] = steps[step];
    const long long searches_before = search.searches();
    const std::optional<LocalizationResult> answer =
        search.Search(recognizer, all_places ? QueryExclusion{} : everything);
    if (search.searches() == searches_before) continue;
    SCOPED_TRACE(::testing::Message() << "search " << step << " at scan " << i);
    EXPECT_EQ(search.fields_built(), built);
    EXPECT_EQ(answer.has_value(), all_places);
    if (answer) {
      EXPECT_TRUE(Near(answer->T_world_robot, drive.truth[i], 0.3, 3.5));
    }
    ++step;
  }
  EXPECT_EQ(step, steps.size());
}

// A background search stopped by Cancel leaves the field it built to the next search of the same
// recognizer; a search for another recognizer stops the one running and searches its own map:
// here the hall's places moved 10 m east, where its answer must put the robot.
TEST(MapSearch, ACancelledSearchLeavesItsFieldAndAnotherMapSearchesItsOwn) {
  const PlaceRecognizer hall(PlacesFromMap(HallMap()), PlaceRecognitionConfig{});
  std::vector<Place> moved_places = PlacesFromMap(HallMap());
  const Pose2 T_moved_world(10.0, 0.0, 0.0);
  for (Place& place : moved_places) place.T_world_place = T_moved_world * place.T_world_place;
  const PlaceRecognizer moved(std::move(moved_places), PlaceRecognitionConfig{});
  const SimulatedDrive drive = HallQuery();
  MapSearch search(5.0, 2.0, LocalizerConfig{}.map_search_margin, true);
  std::size_t i = 0;
  const auto launch = [&](const PlaceRecognizer& recognizer) {
    for (; i < drive.scans.size() && !search.searching(); ++i) {
      search.AddScan(drive.scans[i], kTWorldOdom.inverse() * drive.truth[i], static_cast<int>(i));
      search.Search(recognizer, {});
    }
  };
  launch(hall);
  ASSERT_TRUE(search.searching());
  EXPECT_EQ(search.fields_built(), 1);
  search.Cancel();
  EXPECT_FALSE(search.searching());
  EXPECT_EQ(search.searches(), 0);
  launch(hall);
  ASSERT_TRUE(search.searching());
  EXPECT_EQ(search.fields_built(), 1);  // the cancelled search's field
  // Asked for the moved map, it stops the hall's search, and searches the moved map's field when
  // the next search is due.
  EXPECT_FALSE(search.Search(moved, {}).has_value());
  EXPECT_FALSE(search.searching());
  launch(moved);
  ASSERT_TRUE(search.searching());
  EXPECT_EQ(search.fields_built(), 2);
  const std::optional<LocalizationResult> answer = AwaitSearch(search, moved);
  ASSERT_TRUE(answer.has_value());
  EXPECT_EQ(search.searches(), 1);
  EXPECT_TRUE(Near(answer->T_world_robot, T_moved_world * drive.truth[i - 1], 0.3, 3.5));
}

// A search whose stop is raised finds nothing, where the same search unstopped finds the pose.
TEST(MapSearch, AStoppedSearchFindsNothing) {
  const MapField field(PlacesFromMap(HallMap()));
  const SimulatedDrive drive = HallQuery();
  std::vector<Eigen::Vector2d> points;
  for (std::size_t k = 10; k < 15; ++k) {
    const Pose2 T_latest_robot = Between(drive.truth[14], drive.truth[k]);
    for (const Eigen::Vector2d& endpoint : DenseScanPoints(drive.scans[k]).endpoints_m) {
      points.push_back(T_latest_robot * endpoint);
    }
  }
  const double margin = LocalizerConfig{}.map_search_margin;
  const MapSearchResult found = field.Search(points, 0.5, margin);
  ASSERT_TRUE(found.found);
  EXPECT_TRUE(Near(found.T_world_robot, drive.truth[14], 0.3, 3.5));
  const std::atomic<bool> stop(true);
  EXPECT_FALSE(field.Search(points, 0.5, margin, &stop).found);
}

TEST(MapSearch, SaysNothingInOneOfTwoIdenticalRooms) {
  // Round room B, a translated copy of room A: the beams fit both.
  const SimulatedDrive drive =
      Simulate(TwoRooms(), Drive({{12, -2}, {8, -2}, {8, 2}, {12, 2}, {12, -2}}), 4);
  for (const std::optional<LocalizationResult>& answer : Answers(drive, 5.0)) {
    EXPECT_FALSE(answer.has_value());
  }
  // The search itself: the best pose is in one of the rooms, and the other comes within the
  // margin.
  const MapField field(Recognizer().places());
  const std::vector<Eigen::Vector2d> points = DenseScanPoints(drive.scans[40]).endpoints_m;
  const MapSearchResult result = field.Search(points, 0.5, LocalizerConfig{}.map_search_margin);
  EXPECT_FALSE(result.found);
  EXPECT_GT(result.score, 0.8);
  EXPECT_GE(result.rival_score, result.score - LocalizerConfig{}.map_search_margin);
  const Pose2 truth = drive.truth[40];
  const Pose2 in_room_a(truth.x - 20.0, truth.y, truth.theta);
  EXPECT_TRUE(Near(result.T_world_robot, truth, 0.3, 3.0) ||
              Near(result.T_world_robot, in_room_a, 0.3, 3.0));
}

// The field of room A's first places alone: small enough to score every pose.
MapField FirstPlacesField() {
  const std::vector<Place>& places = Recognizer().places();
  std::vector<char> use(places.size(), 0);
  for (std::size_t p = 0; p < std::min<std::size_t>(3, places.size()); ++p) use[p] = 1;
  return MapField(places, use);
}

// The branch and bound finds the pose an exhaustive search over every turn and cell scores best,
// with beams that fall off the field at every edge for some of them.
TEST(MapSearch, FindsWhatScoringEveryPoseFinds) {
  const MapField field = FirstPlacesField();
  ASSERT_FALSE(field.empty());
  const SimulatedDrive drive = Simulate(TwoRooms(), Drive({{-12, -2}, {-8, -2}}), 8);
  const std::vector<Eigen::Vector2d> points = DenseScanPoints(drive.scans[10]).endpoints_m;
  double best = 0.0;
  for (int k = 0; k < kMapSearchRotations; ++k) {
    const double theta = 2.0 * M_PI * k / kMapSearchRotations;
    for (int y = 0; y < field.height(); ++y) {
      for (int x = 0; x < field.width(); ++x) {
        const Eigen::Vector2d at = field.origin() + field.cell_m() * Eigen::Vector2d(x, y);
        best = std::max(best, field.ScoreAt(points, Pose2(at.x(), at.y(), theta)));
      }
    }
  }
  const MapSearchResult result = field.Search(points, 0.3, 0.0);
  EXPECT_NEAR(result.score, best, 1e-6);
  EXPECT_NEAR(field.ScoreAt(points, result.T_world_robot), result.score, 1e-6);
  EXPECT_GT(result.nodes, 0);
}

// On cell centres the interpolated closeness is the search's own score, and halfway between two
// it is their mean; the refined pose scores no less than the search's and stays within its cell
// and turn step, from any start.
TEST(MapSearch, RefineInterpolatesBetweenCellsAndStaysWithinOne) {
  const MapField field = FirstPlacesField();
  ASSERT_FALSE(field.empty());
  const double cell_m = field.cell_m();
  std::vector<Eigen::Vector2d> on_centres;
  for (int k = 0; k < 25; ++k) on_centres.push_back(cell_m * Eigen::Vector2d(k % 5 - 2, k / 5 - 2));
  const Eigen::Vector2d centre =
      field.origin() + cell_m * Eigen::Vector2d(field.width() / 2, field.height() / 2);
  const Pose2 at(centre.x(), centre.y(), 0.0);
  const Pose2 next(centre.x() + cell_m, centre.y(), 0.0);
  const Pose2 halfway(centre.x() + cell_m / 2.0, centre.y(), 0.0);
  EXPECT_NEAR(field.InterpolatedScoreAt(on_centres, at), field.ScoreAt(on_centres, at), 1e-6);
  EXPECT_NEAR(field.InterpolatedScoreAt(on_centres, halfway),
              (field.ScoreAt(on_centres, at) + field.ScoreAt(on_centres, next)) / 2.0, 1e-6);
  EXPECT_GT(field.ScoreAt(on_centres, at) + field.ScoreAt(on_centres, next), 0.0);

  const SimulatedDrive drive = Simulate(TwoRooms(), Drive({{-12, -2}, {-8, -2}}), 8);
  const std::vector<Eigen::Vector2d> points = DenseScanPoints(drive.scans[10]).endpoints_m;
  const MapSearchResult result = field.Search(points, 0.3, 0.0);
  ASSERT_GT(result.score, 0.0);
  const double turn_step_rad = 2.0 * M_PI / kMapSearchRotations;
  for (const Pose2& start :
       {result.T_world_robot, Pose2(result.T_world_robot.x + 0.7, result.T_world_robot.y - 0.4,
                                    result.T_world_robot.theta + 0.3)}) {
    const Pose2 refined = field.Refine(points, start);
    EXPECT_GE(field.InterpolatedScoreAt(points, refined), field.InterpolatedScoreAt(points, start));
    EXPECT_LE(TranslationNorm(Between(start, refined)), cell_m + 1e-9);
    EXPECT_LE(std::abs(std::remainder(refined.theta - start.theta, 2.0 * M_PI)),
              turn_step_rad + 1e-9);
  }
}

TEST(MapSearch, AnEmptyMapOrWindowFindsNothing) {
  const MapField empty(std::vector<Place>{});
  EXPECT_TRUE(empty.empty());
  EXPECT_FALSE(empty.Search({{1.0, 0.0}, {0.0, 1.0}}, 0.5, 0.06).found);
  const MapField field(Recognizer().places());
  EXPECT_FALSE(field.Search({}, 0.5, 0.06).found);
  // Every place excluded: nothing to search.
  const SimulatedDrive drive = Simulate(TwoRooms(), Drive({{6, 8}, {-6, 8}}), 3);
  MapSearch search(5.0, 1.0, 0.06);
  for (std::size_t i = 0; i < drive.scans.size(); ++i) {
    search.AddScan(drive.scans[i], drive.truth[i], static_cast<int>(i));
    EXPECT_FALSE(
        search.Search(Recognizer(), [](const Place&, const std::vector<int>&) { return true; })
            .has_value());
  }
  // A window of 0: never searches.
  for (const std::optional<LocalizationResult>& answer : Answers(drive, 0.0)) {
    EXPECT_FALSE(answer.has_value());
  }
}

// Scans whose keypoints say nothing (none given, as where no stable keypoint is seen again): the
// Relocalizer fixes from the searches alone, and never without them.
// In the background the answers may come scans later; the robot then stands at its last pose
// (its scans repeated) for at most 60 s.
TEST(MapSearch, FixesTheRelocalizerInAnOpenHallWhereKeypointsSayNothing) {
  const SimulatedDrive drive = HallQuery();
  for (const auto& [window_m, background] : {std::pair{5.0, false}, {5.0, true}, {0.0, false}}) {
    SCOPED_TRACE(::testing::Message() << window_m << (background ? " m, background" : " m"));
    LocalizerConfig config;
    config.map_search_window_m = window_m;
    Relocalizer relocalizer(HallMap(), config);
    relocalizer.set_background_search(background);
    int fixed = 0;
    int wrong = 0;
    int searched_answers = 0;
    int beside_keypoint_answers = 0;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    for (std::size_t i = 0; i < drive.scans.size() || (background && fixed == 0 &&
                                                       std::chrono::steady_clock::now() < give_up);
         ++i) {
      // A search running ends before the next scan, whatever the machine's speed: the same
      // windows are searched as inline, their answers taken a scan later.
      while (relocalizer.map_search().searching() && !relocalizer.map_search().search_ended() &&
             std::chrono::steady_clock::now() < give_up) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      const std::size_t at = std::min(i, drive.scans.size() - 1);
      const RelocalizationUpdate update = relocalizer.AddScan(
          drive.scans[at], kTWorldOdom.inverse() * drive.truth[at], {}, static_cast<int>(at));
      // No keypoints given: the queries' answers find nothing; every answer found is a search's.
      EXPECT_FALSE(update.answer && update.answer->found);
      if (update.map_search_answer) {
        EXPECT_TRUE(update.map_search_answer->found);
        ++searched_answers;
        // Inline, an answer is judged with the scan it was searched at, even beside the
        // keypoints' answer of that scan.
        if (!background) {
          EXPECT_EQ(update.map_search_answer->scan_ids.back(), static_cast<int>(at));
        }
        if (update.answer) ++beside_keypoint_answers;
      }
      if (update.status != FixStatus::kFixed) continue;
      ++fixed;
      if (!Near(update.T_world_robot, drive.truth[at], 0.5, 10.0)) ++wrong;
    }
    EXPECT_EQ(wrong, 0);
    if (window_m > 0.0) {
      EXPECT_GE(searched_answers, 2);
      EXPECT_GT(beside_keypoint_answers, 0) << "the drive no longer has that case";
      EXPECT_GT(fixed, 0);  // two searches agree
    } else {
      EXPECT_EQ(fixed, 0);
    }
  }
}

TEST(MapSearch, InvalidSettingsAreRefusedByName) {
  LocalizerConfig config;
  config.map_search_window_m = -1.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = LocalizerConfig{};
  config.map_search_every_m = 0.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = LocalizerConfig{};
  config.map_search_margin = 1.5;
  try {
    Validate(config);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("map_search_margin"), std::string::npos);
  }
}

}  // namespace
}  // namespace keyplace
