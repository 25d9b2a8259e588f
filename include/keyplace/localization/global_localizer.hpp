#pragma once
// Global localization of a robot in a map of stable-keypoint submaps, one scan at a time (paper
// Algorithm 4 as a robot lives it): every scan and its odometry pose go into a query submap built
// exactly as the map's submaps were (the map's own mapping configuration); when the query submap
// is complete it is recognised against the map and the localizer answers where the robot is.
// Memory is bounded: only the scans of the query submap being built are kept.
//
//   keyplace::GlobalLocalizer localizer(keyplace::LoadMap("site.kpm"));
//   for (each scan, odometry pose) {
//     if (auto fix = localizer.AddScan(scan, T_odom_robot); fix && fix->found) {
//       use(fix->T_world_robot, fix->confidence);
//     }
//   }

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/localization/query_builder.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/place/pair_memo.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// When the answers of the localizer make a fix, keep it, or lose it (Relocalizer).
struct FixPolicy {
  // Answers that must agree through odometry before the first fix, one of them accepted (the
  // others may be weak: LocalizationResult::weak_T_world_odom); 1: every accepted answer is a
  // fix. Weak answers alone: weak_fix_answers below.
  int confirmations = 2;
  // Weak answers alone make a fix when at least `weak_fix_answers` looks (answers more than
  // agree_m of odometry after the previous look) agree through odometry and lie at least
  // `weak_fix_span_m` of odometry apart, first to last (at most window_m): a pose that keeps
  // explaining what the robot sees along a path longer than a room. Look-alike rooms (Intel's lab,
  // turned by 90 degrees) give weak answers that agree over a few metres; an open hall, whose
  // sparse keypoints make most right answers weak, gives them along the whole drive. 0 = never
  // (weak answers only second an accepted one). Chosen on Intel and FR079 (time split): with 3
  // answers the shortest span without a wrong fix is 5 m (4 m: 26 wrong fixes on Intel); the
  // default is twice that (docs/LOCALIZATION.md).
  int weak_fix_answers = 3;
  double weak_fix_span_m = 10.0;
  // Two answers agree when they put the robot now within agree_m + agree_per_m * (odometry
  // distance between them) and agree_deg of each other: the slack is odometry drift.
  double agree_m = 1.0;
  double agree_per_m = 0.02;
  double agree_deg = 10.0;
  // Answers older than this (odometry distance) are forgotten while searching.
  double window_m = 20.0;
  // A fix that no answer confirmed over this odometry distance is given up (lost).
  double lost_after_m = 20.0;
  // One accepted answer at least this confident that contradicts the fix gives it up at once;
  // less confident ones must agree with each other (confirmations of them) first.
  double contradiction_confidence = 0.9;
  // Every this much odometry while fixed, the latest scans are put into the map by the fix and
  // scored against the occupancy of the places around the robot (TrackCheck, with place
  // recognition's dense thresholds); a check that finds them off the walls where a pose nearby
  // puts them on the walls gives the fix up (lost). 0 = off. The search around the fix covers the
  // shift a missed 45 degree turn makes over about a metre: checks further apart catch less.
  double track_check_every_m = 1.0;
  // The map's own error, which no match removes: added to the covariance derived from the matches
  // (RelocalizationUpdate::covariance) as independent per-axis sigmas. Chosen on FR079 (the
  // first fixes' errors against the corrected poses: median 0.03 m and 0.3 deg, while the
  // inlier fits alone claim 0.01 m; docs/NAVIGATION.md).
  double map_sigma_m = 0.03;
  double map_sigma_deg = 0.3;
};

struct LocalizerConfig {
  PlaceRecognitionConfig place;  // the top-level `place` section
  // A query submap that is not complete after this many scans is recognised as it stands (when
  // the map's own max_scans_per_submap is smaller, that one closes it first). Bounds memory.
  int max_query_scans = 300;
  // Also recognise the query as it stands every time the robot has travelled this far since
  // the last answer (odometry path; 0 = only complete queries): an answer from the scans the
  // robot has now, where submaps take long to complete (scans far apart, open halls). The query
  // keeps growing; completion resets it.
  double query_every_m = 1.0;
  // With retrieval `words` (or `auto` while tracking a fix), a query also pairs the places whose
  // origin lies within this of where a belief of the caller puts the robot
  // (GlobalLocalizer::set_beliefs: the Relocalizer's pending answers and its fix), at most
  // place.retrieval_places per belief, whatever their words rank: an answer that would confirm a
  // belief is not left to the words. 0: the words alone.
  double search_near_m = 3.0;
  // While the Relocalizer has no fix it also searches the whole map for the pose where the beams
  // of the scans over the last map_search_window_m of odometry (at most) fit (MapSearch), every
  // map_search_every_m of odometry; a pose that fits better by map_search_margin (of the mean
  // closeness, 0..1) than every pose distinct from it is an accepted answer. Window 0: never. One
  // search costs up to 0.26 s on a map of a floor and 2.7-4.7 s on one of 92 x 44 m, on one core
  // (docs/LOCALIZATION.md): a robot's node runs it in the background
  // (Relocalizer::set_background_search).
  double map_search_window_m = 5.0;
  double map_search_every_m = 1.0;
  double map_search_margin = 0.08;
  FixPolicy fix;  // the Relocalizer's
};

/// Throw std::invalid_argument naming the first invalid field.
void Validate(const FixPolicy& policy);
void Validate(const LocalizerConfig& config);

/// One answer of the localizer.
struct LocalizationResult {
  bool found = false;      // the match was accepted (verified, not ambiguous, confident enough)
  bool ambiguous = false;  // another distinct place scored nearly as well
  double confidence = 0.0;
  int submap_id = -1;  // matched map submap (place id), -1 when nothing was verified
  // Valid when a candidate was verified (match.verified): the robot's pose in the map at the
  // latest scan, and the map <- odometry correction (T_world_robot = T_world_odom * T_odom_robot).
  Pose2 T_world_robot;
  Pose2 T_world_odom;
  std::size_t scans = 0;      // scans in the query
  std::vector<int> scan_ids;  // their ids as given to AddScan (-1 when none was given)
  Pose2 T_odom_origin;        // odometry pose of the query's first scan (the query frame)
  // Answers with the same id came from one query (LocalizerConfig::query_every_m) and share
  // scans, so they are not independent evidence; -1: independent of every other answer.
  long long query_id = -1;
  // An answer of a search of the whole map (MapSearch): the first and the last scan of the window
  // it searched, numbered in the order the search kept them (a robot standing still adds none).
  // Two such answers whose windows share more than one scan are not independent either. -1: not
  // a search's answer.
  long long window_first_scan = -1;
  long long window_last_scan = -1;
  // When the match was not accepted but names a weak answer (PlaceMatch::weak, its confidence
  // match.weak_confidence): the map <- odometry correction of that pose. Alone it is no fix; the
  // Relocalizer adds such answers up (docs/LOCALIZATION.md, "Weak answers").
  std::optional<Pose2> weak_T_world_odom;
  PlaceMatch match;  // all the details of the recognition
};

/// Which map places a query must not be matched with, given the ids of the query's scans (the
/// `scan_id` passed to AddScan). For evaluations on the map's own log; empty = none.
using QueryExclusion = std::function<bool(const Place&, const std::vector<int>& query_scan_ids)>;

/// A copy shares the place recognizer and the feature extractor (read-only; safe from several
/// threads) and has its own query and exclusion.
class GlobalLocalizer {
 public:
  /// Localizes in `map` with its own mapping configuration. Throws std::invalid_argument for an
  /// invalid config.
  explicit GlobalLocalizer(const GlobalMap& map, const LocalizerConfig& config = {},
                           const FlirtConfig& features = {});
  /// The same from a map file (LoadMap).
  static GlobalLocalizer FromFile(const std::string& map_path, const LocalizerConfig& config = {},
                                  const FlirtConfig& features = {});

  /// Adds the next scan with the robot's pose in its odometry frame. Returns an answer when the
  /// query submap completes with this scan (then the next scan starts a new query) or when
  /// the robot travelled LocalizerConfig::query_every_m since the last answer, else nullopt.
  std::optional<LocalizationResult> AddScan(const LaserScan& scan, const Pose2& T_odom_robot);

  /// The same with the scan's FLIRT keypoints already extracted (laser frame) and the caller's
  /// id of the scan (for `exclusion`).
  std::optional<LocalizationResult> AddScan(const LaserScan& scan, const Pose2& T_odom_robot,
                                            std::vector<Keypoint> keypoints, int scan_id = -1);

  /// Recognises the query as it stands (incomplete), e.g. when the robot must decide now.
  /// nullopt when no scan has been added since the last answer or Reset.
  std::optional<LocalizationResult> LocalizeNow() const;

  /// Forgets the query being built (the robot was kidnapped).
  void Reset();

  void set_exclusion(QueryExclusion exclusion) { exclusion_ = std::move(exclusion); }
  /// Where the caller believes the odometry frame lies in the map (map <- odometry, one per
  /// belief; LocalizerConfig::search_near_m), and whether one of them is a fix the answers only
  /// confirm or contradict (`tracking`): with place.retrieval `auto` a tracking query pairs the
  /// places the words retrieve and those near the beliefs, a searching one every place. Kept
  /// until set again.
  void set_beliefs(std::vector<Pose2> T_world_odom, bool tracking = false) {
    beliefs_ = std::move(T_world_odom);
    tracking_ = tracking;
  }
  const QueryExclusion& exclusion() const { return exclusion_; }

  std::size_t buffered_scans() const { return builder_.size(); }
  const PlaceRecognizer& recognizer() const { return *recognizer_; }
  const MappingConfig& mapping_config() const { return mapping_config_; }
  const LocalizerConfig& config() const { return config_; }

 private:
  GlobalLocalizer(std::vector<Place> places, const MappingConfig& mapping,
                  const LocalizerConfig& config, const FlirtConfig& features);
  // `memo`: the growing query's pairs (AddScan's; LocalizeNow, const, pairs afresh).
  LocalizationResult Localize(PairMemo* memo) const;

  LocalizerConfig config_;
  MappingConfig mapping_config_;
  std::shared_ptr<const PlaceRecognizer> recognizer_;
  std::shared_ptr<const FlirtExtractor> extractor_;
  SubmapQueryBuilder builder_;
  double path_since_answer_m_ = 0.0;
  double query_path_m_ = 0.0;  // odometry path of the query being built
  std::optional<Pose2> last_T_odom_robot_;
  long long query_id_ = 0;  // counts the queries begun
  QueryExclusion exclusion_;
  std::vector<Pose2> beliefs_;  // T_world_odom
  bool tracking_ = false;
  PairMemo pair_memo_;  // the pairs of the query being built, for its next answer
};

/// One scan against single-scan places (the TIP-FLIRT baseline: every scan of a log is a
/// place): the query is the scan's keypoints, the answer its pose. `keypoints` in the laser
/// frame; `T_odom_robot` only sets the returned T_world_odom.
LocalizationResult LocalizeScan(const PlaceRecognizer& recognizer, const LaserScan& scan,
                                const std::vector<Keypoint>& keypoints,
                                const Pose2& T_odom_robot = {},
                                const PlaceExclusion& exclusion = {});

}  // namespace keyplace
