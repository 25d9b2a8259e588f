#include "keyplace/place/place_config.hpp"

#include <stdexcept>
#include <string>

#include "keyplace/common/config_fields.hpp"

namespace keyplace {
namespace {

void Require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw std::invalid_argument("PlaceRecognitionConfig." + field + " " + rule);
}

const ConfigFields<PlaceRecognitionConfig>& Fields() {
  using C = PlaceRecognitionConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("PlaceRecognitionConfig");
    table.Int("min_pairs", &C::min_pairs)
        .Int("max_candidates", &C::max_candidates)
        .Double("descriptor_match_chi2", &C::descriptor_match_chi2)
        .Enum("pair_matching", &C::pair_matching,
              {{C::PairMatching::kQueryOrder, "query_order"},
               {C::PairMatching::kGlobalGreedy, "global_greedy"}})
        .Enum("query_keypoints", &C::query_keypoints,
              {{C::QueryKeypoints::kStable, "stable"}, {C::QueryKeypoints::kAllScans, "all_scans"}})
        .Double("query_merge_m", &C::query_merge_m)
        .Double("inlier_distance_m", &C::inlier_distance_m)
        .Int("ransac_iterations", &C::ransac_iterations)
        .Int("exhaustive_hypotheses_max_pairs", &C::exhaustive_hypotheses_max_pairs)
        .Double("rigidity_m2", &C::rigidity_m2)
        .Bool("refine", &C::refine)
        .Int("seed", &C::seed)
        .Int("verification_neighbours", &C::verification_neighbours)
        .Int("min_consensus", &C::min_consensus)
        .Enum("consensus_counting", &C::consensus_counting,
              {{C::ConsensusCounting::kQueryKeypoints, "query_keypoints"},
               {C::ConsensusCounting::kDistinctReference, "distinct_reference"}})
        .Double("min_gamma", &C::min_gamma)
        .Double("min_gamma_all_scans", &C::min_gamma_all_scans)
        .Double("min_reference_coverage", &C::min_reference_coverage)
        .Double("double_match_m", &C::double_match_m)
        .Enum("gamma_counting", &C::gamma_counting,
              {{C::GammaCounting::kUniquePairs, "unique_pairs"},
               {C::GammaCounting::kPerKeypoint, "per_keypoint"}})
        .Enum("selection", &C::selection,
              {{C::Selection::kFirstVerified, "first_verified"},
               {C::Selection::kBestScore, "best_score"}})
        .Enum("score", &C::score,
              {{C::Score::kGamma, "gamma"},
               {C::Score::kConsensus, "consensus"},
               {C::Score::kConsensusGamma, "consensus_gamma"}})
        .Double("distinct_distance_m", &C::distinct_distance_m)
        .Double("distinct_angle_deg", &C::distinct_angle_deg)
        .Double("ambiguity_ratio", &C::ambiguity_ratio)
        .Double("min_confidence", &C::min_confidence)
        .Int("confidence_consensus", &C::confidence_consensus);
    return table;
  }();
  return fields;
}

}  // namespace

PlaceRecognitionConfig PaperPlaceConfig() {
  PlaceRecognitionConfig config;
  config.pair_matching = PlaceRecognitionConfig::PairMatching::kQueryOrder;
  config.exhaustive_hypotheses_max_pairs = 0;
  config.selection = PlaceRecognitionConfig::Selection::kFirstVerified;
  config.score = PlaceRecognitionConfig::Score::kGamma;
  config.ambiguity_ratio = 1.0;
  config.verification_neighbours = 0;
  config.query_keypoints = PlaceRecognitionConfig::QueryKeypoints::kStable;
  config.consensus_counting = PlaceRecognitionConfig::ConsensusCounting::kQueryKeypoints;
  config.min_gamma_all_scans = 0.4;     // unused: stable query keypoints
  config.min_reference_coverage = 0.0;  // unused: stable query keypoints
  return config;
}

PlaceRecognitionConfig StrictPlaceConfig() {
  PlaceRecognitionConfig config;
  config.min_reference_coverage = 0.5;
  return config;
}

PlaceRecognitionConfig PlacePreset(const std::string& name) {
  if (name == "default") return PlaceRecognitionConfig{};
  if (name == "paper") return PaperPlaceConfig();
  if (name == "strict") return StrictPlaceConfig();
  throw std::invalid_argument("unknown place recognition preset '" + name +
                              "' (expected default, paper or strict)");
}

void Validate(const PlaceRecognitionConfig& config) {
  Require(config.min_pairs >= 2, "min_pairs", "must be >= 2");
  Require(config.max_candidates >= 1, "max_candidates", "must be >= 1");
  Require(config.descriptor_match_chi2 > 0.0, "descriptor_match_chi2", "must be positive");
  Require(config.query_merge_m >= 0.0, "query_merge_m", "must be >= 0");
  Require(config.inlier_distance_m > 0.0, "inlier_distance_m", "must be positive");
  Require(config.ransac_iterations >= 1, "ransac_iterations", "must be >= 1");
  Require(config.exhaustive_hypotheses_max_pairs >= 0, "exhaustive_hypotheses_max_pairs",
          "must be >= 0");
  Require(config.rigidity_m2 > 0.0, "rigidity_m2", "must be positive");
  Require(config.verification_neighbours >= 0, "verification_neighbours", "must be >= 0");
  Require(config.min_consensus >= 2, "min_consensus", "must be >= 2");
  Require(config.min_gamma >= 0.0 && config.min_gamma <= 1.0, "min_gamma", "must lie in [0, 1]");
  Require(config.min_gamma_all_scans >= 0.0 && config.min_gamma_all_scans <= 1.0,
          "min_gamma_all_scans", "must lie in [0, 1]");
  Require(config.min_reference_coverage >= 0.0 && config.min_reference_coverage <= 1.0,
          "min_reference_coverage", "must lie in [0, 1]");
  Require(config.double_match_m > 0.0, "double_match_m", "must be positive");
  Require(config.distinct_distance_m > 0.0, "distinct_distance_m", "must be positive");
  Require(config.distinct_angle_deg > 0.0, "distinct_angle_deg", "must be positive");
  Require(config.ambiguity_ratio > 0.0, "ambiguity_ratio", "must be positive");
  Require(config.min_confidence >= 0.0 && config.min_confidence <= 1.0, "min_confidence",
          "must lie in [0, 1]");
  Require(config.confidence_consensus >= 1, "confidence_consensus", "must be >= 1");
}

std::vector<std::pair<std::string, std::string>> ToKeyValues(const PlaceRecognitionConfig& config) {
  return Fields().ToKeyValues(config);
}

void ApplyKeyValues(const std::map<std::string, std::string>& values,
                    PlaceRecognitionConfig& config) {
  Fields().Apply(values, config);
  Validate(config);
}

}  // namespace keyplace
