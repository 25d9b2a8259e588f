#include "keyplace/localization/global_localizer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/fixed_text.hpp"
#include "keyplace/store/map_file.hpp"

namespace keyplace {
namespace {

// The answer of a recognition whose query pose (the latest scan) is T_odom_latest in odometry.
LocalizationResult ResultOf(PlaceMatch match, const Pose2& T_odom_latest) {
  LocalizationResult result;
  result.match = std::move(match);
  result.found = result.match.found;
  result.ambiguous = result.match.ambiguous;
  result.confidence = result.match.confidence;
  if (result.match.verified) {
    result.submap_id = result.match.place_id;
    result.T_world_robot = result.match.estimated_pose;
    result.T_world_odom = result.T_world_robot * T_odom_latest.inverse();
  }
  if (!result.found && result.match.weak) {
    result.weak_T_world_odom = result.match.weak->estimated_pose * T_odom_latest.inverse();
  }
  return result;
}

}  // namespace

void Validate(const LocalizerConfig& config) {
  Validate(config.place);
  if (config.max_query_scans < 1) {
    throw std::invalid_argument("LocalizerConfig.max_query_scans must be >= 1");
  }
  if (!(config.query_every_m >= 0.0) || !std::isfinite(config.query_every_m)) {
    throw std::invalid_argument("LocalizerConfig.query_every_m must be finite and >= 0");
  }
  if (!(config.search_near_m >= 0.0) || !std::isfinite(config.search_near_m)) {
    throw std::invalid_argument("LocalizerConfig.search_near_m must be finite and >= 0");
  }
  if (!(config.map_search_window_m >= 0.0) || !std::isfinite(config.map_search_window_m)) {
    throw std::invalid_argument("LocalizerConfig.map_search_window_m must be finite and >= 0");
  }
  if (!(config.map_search_every_m > 0.0) || !std::isfinite(config.map_search_every_m)) {
    throw std::invalid_argument("LocalizerConfig.map_search_every_m must be finite and > 0");
  }
  if (!(config.map_search_margin >= 0.0 && config.map_search_margin <= 1.0)) {
    throw std::invalid_argument("LocalizerConfig.map_search_margin must be in [0, 1]");
  }
  Validate(config.fix);
}

void Validate(const FixPolicy& policy) {
  if (policy.confirmations < 1) {
    throw std::invalid_argument("FixPolicy.confirmations must be >= 1");
  }
  if (policy.weak_fix_answers < 0) {
    throw std::invalid_argument("FixPolicy.weak_fix_answers must be >= 0");
  }
  if (!(policy.weak_fix_span_m >= 0.0) || !std::isfinite(policy.weak_fix_span_m)) {
    throw std::invalid_argument("FixPolicy.weak_fix_span_m must be finite and >= 0");
  }
  // Answers older than window_m are forgotten: a longer span could never be reached.
  if (policy.weak_fix_answers > 0 && policy.weak_fix_span_m > policy.window_m) {
    throw std::invalid_argument(
        "FixPolicy.weak_fix_span_m (" + FixedText(policy.weak_fix_span_m) +
        " m) must not exceed window_m (" + FixedText(policy.window_m) +
        " m): older answers are forgotten; lower it, or set weak_fix_answers to 0");
  }
  const auto require_positive = [](double value, const char* name) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      throw std::invalid_argument(std::string("FixPolicy.") + name +
                                  " must be positive and finite");
    }
  };
  require_positive(policy.agree_m, "agree_m");
  require_positive(policy.agree_deg, "agree_deg");
  require_positive(policy.window_m, "window_m");
  require_positive(policy.lost_after_m, "lost_after_m");
  if (!(policy.track_check_every_m >= 0.0) || !std::isfinite(policy.track_check_every_m)) {
    throw std::invalid_argument("FixPolicy.track_check_every_m must be finite and >= 0");
  }
  for (const auto& [value, name] :
       {std::pair<double, const char*>{policy.map_sigma_m, "map_sigma_m"},
        {policy.map_sigma_deg, "map_sigma_deg"}}) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      throw std::invalid_argument(std::string("FixPolicy.") + name + " must be >= 0 and finite");
    }
  }
  if (!(policy.agree_per_m >= 0.0) || !std::isfinite(policy.agree_per_m)) {
    throw std::invalid_argument("FixPolicy.agree_per_m must be >= 0 and finite");
  }
  if (!(policy.contradiction_confidence >= 0.0 && policy.contradiction_confidence <= 1.0)) {
    throw std::invalid_argument("FixPolicy.contradiction_confidence must be in [0, 1]");
  }
}

GlobalLocalizer::GlobalLocalizer(const GlobalMap& map, const LocalizerConfig& config,
                                 const FlirtConfig& features)
    : GlobalLocalizer(PlacesFromMap(map), map.config, config, features) {}

GlobalLocalizer::GlobalLocalizer(std::vector<Place> places, const MappingConfig& mapping,
                                 const LocalizerConfig& config, const FlirtConfig& features)
    : config_(config),
      mapping_config_(mapping),
      recognizer_(std::make_shared<const PlaceRecognizer>(
          std::move(places), config.place,
          config.place.retrieval == PlaceRecognitionConfig::Retrieval::kAuto
              ? PlaceRecognizer::LearnWords::kAlways
              : PlaceRecognizer::LearnWords::kForRetrievalWords)),
      extractor_(std::make_shared<const FlirtExtractor>(features)),
      builder_(mapping) {
  Validate(config_);
}

GlobalLocalizer GlobalLocalizer::FromFile(const std::string& map_path,
                                          const LocalizerConfig& config,
                                          const FlirtConfig& features) {
  return GlobalLocalizer(LoadMap(map_path), config, features);
}

std::optional<LocalizationResult> GlobalLocalizer::AddScan(const LaserScan& scan,
                                                           const Pose2& T_odom_robot) {
  // FLIRT's duplicate box is oriented by the laser pose (as FLIRTLib does with the log's pose).
  return AddScan(scan, T_odom_robot, extractor_->Extract(scan, T_odom_robot * scan.T_robot_laser));
}

std::optional<LocalizationResult> GlobalLocalizer::AddScan(const LaserScan& scan,
                                                           const Pose2& T_odom_robot,
                                                           std::vector<Keypoint> keypoints,
                                                           int scan_id) {
  const bool complete = builder_.AddScan(scan, T_odom_robot, std::move(keypoints), scan_id);
  if (last_T_odom_robot_) {
    const double step_m = TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
    path_since_answer_m_ += step_m;
    query_path_m_ += step_m;
  }
  last_T_odom_robot_ = T_odom_robot;
  if (complete || static_cast<int>(builder_.size()) >= config_.max_query_scans) {
    LocalizationResult result = Localize(&pair_memo_);
    Reset();
    return result;
  }
  // An answer of a long query says something new only when a good part of it is new: the next
  // one waits for half the path the query had at the last (at least query_every_m), so a query
  // of length L answers O(log L) times, not L / query_every_m.
  const double next_answer_m =
      std::max(config_.query_every_m, 0.5 * (query_path_m_ - path_since_answer_m_));
  if (config_.query_every_m > 0.0 && path_since_answer_m_ >= next_answer_m) {
    path_since_answer_m_ = 0.0;
    return Localize(&pair_memo_);
  }
  return std::nullopt;
}

std::optional<LocalizationResult> GlobalLocalizer::LocalizeNow() const {
  if (builder_.empty()) return std::nullopt;
  return Localize(nullptr);
}

void GlobalLocalizer::Reset() {
  builder_.Reset();
  path_since_answer_m_ = 0.0;
  query_path_m_ = 0.0;
  last_T_odom_robot_.reset();
  pair_memo_.Clear();  // the next query's scans are new
  ++query_id_;
}

LocalizationResult GlobalLocalizer::Localize(PairMemo* memo) const {
  const std::size_t latest = builder_.size() - 1;
  PlaceQuery query = builder_.Query(latest, config_.place.query_keypoints);
  // Holding a fix, an answer confirms it or contradicts it: the places near the fix and those
  // most like the query suffice (issue 30: on fr079-gmapping 0.91 of the updates were tracking,
  // at 12 ms each pairing all 529 places). Searching, a missed place is a lost answer.
  query.by_words = tracking_ && config_.place.retrieval == PlaceRecognitionConfig::Retrieval::kAuto;
  // The words may leave out the place that would confirm a belief. Searched around the latest
  // scan, where the robot is, as a query may span 300 scans.
  const std::vector<Place>& places = recognizer_->places();
  for (const Pose2& T_world_odom : beliefs_) {
    const std::vector<int> near = PlaceIdsToAlsoSearch(
        config_.place, query.by_words, places, places.size(),
        (T_world_odom * builder_.pose(latest)).translation(), config_.search_near_m);
    query.also_search_ids.insert(query.also_search_ids.end(), near.begin(), near.end());
  }
  query.pair_memo = memo;
  std::vector<int> scan_ids = builder_.scan_ids();
  PlaceExclusion exclude;
  if (exclusion_) {
    exclude = [&](const Place& place) { return exclusion_(place, scan_ids); };
  }
  LocalizationResult result =
      ResultOf(recognizer_->Recognize(query, exclude), builder_.pose(latest));
  result.scans = builder_.size();
  result.scan_ids = std::move(scan_ids);
  result.T_odom_origin = builder_.pose(0);
  result.query_id = query_id_;
  return result;
}

LocalizationResult LocalizeScan(const PlaceRecognizer& recognizer, const LaserScan& scan,
                                const std::vector<Keypoint>& keypoints, const Pose2& T_odom_robot,
                                const PlaceExclusion& exclusion) {
  PlaceQuery query;
  for (const Keypoint& keypoint : keypoints) {
    query.positions.push_back(scan.T_robot_laser * keypoint.position_m);
    query.descriptors.push_back(keypoint.descriptor);
  }
  LocalizationResult result = ResultOf(recognizer.Recognize(query, exclusion), T_odom_robot);
  result.scans = 1;
  result.T_odom_origin = T_odom_robot;
  return result;
}

}  // namespace keyplace
