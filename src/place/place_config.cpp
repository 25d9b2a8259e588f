#include "keyplace/place/place_config.hpp"

#include <stdexcept>
#include <string>

#include "common/config_fields.hpp"
#include "place/place_fields.hpp"

namespace keyplace {
namespace {

void Require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw std::invalid_argument("PlaceRecognitionConfig." + field + " " + rule);
}

// A share or a probability: NaN fails too.
void RequireFraction(double value, const std::string& field) {
  Require(value >= 0.0 && value <= 1.0, field, "must lie in [0, 1]");
}

}  // namespace

const ConfigFields<RansacConfig>& RansacConfigFields() {
  using C = RansacConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("RansacConfig");
    table
        .Double("inlier_distance_m", &C::inlier_distance_m, "m",
                "a mapped query keypoint this close to its nearest reference keypoint is an inlier")
        .Int("iterations", &C::iterations, "", "sampled 2-pair hypotheses (FLIRTLib: 18)")
        .Int("exhaustive_max_pairs", &C::exhaustive_max_pairs, "",
             "enumerate every pair of descriptor pairs up to this many pairs (0 = always sample)")
        .Double("rigidity_m2", &C::rigidity_m2, "m^2", "FLIRTLib's rigidity pre-check of a sample")
        .Bool("refine", &C::refine,
              "least-squares refit on the inliers, kept when it scores better")
        .Int("seed", &C::seed, "", "random seed, combined with the place id")
        .Double("min_fit_sigma_m", &C::min_fit_sigma_m, "m",
                "floor of the residual sigma in a match's covariance (l_g / sqrt(12))");
    return table;
  }();
  return fields;
}

const ConfigFields<PlaceRecognitionConfig>& PlaceConfigFields() {
  using C = PlaceRecognitionConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("PlaceRecognitionConfig");
    table.Int("min_pairs", &C::min_pairs, "", "mu: unique descriptor pairs for a candidate submap")
        .Int("max_candidates", &C::max_candidates, "",
             "n_c: candidates verified, by increasing mean pair distance")
        .Enum("candidate_ranking", &C::candidate_ranking,
              {{C::CandidateRanking::kMeanDistance, "mean_distance"},
               {C::CandidateRanking::kRigidPairs, "rigid_pairs"}},
              "which n_c of more candidates are verified: smallest mean pair distance (paper) or "
              "most pairs agreeing with one rigid transform")
        .Double("descriptor_match_chi2", &C::descriptor_match_chi2, "",
                "a descriptor pair: symmetric chi2 below this")
        .Enum("pair_matching", &C::pair_matching,
              {{C::PairMatching::kQueryOrder, "query_order"},
               {C::PairMatching::kGlobalGreedy, "global_greedy"}},
              "how unique pairs are chosen: query order (Algorithm 3) or globally by distance")
        .Enum("descriptor_index", &C::descriptor_index,
              {{C::DescriptorIndex::kNone, "none"},
               {C::DescriptorIndex::kKdTree, "kdtree"},
               {C::DescriptorIndex::kDense, "dense"}},
              "how descriptor pairs are found (same pairs): exhaustive chi2 (none), or a "
              "square-root bound searched by a kd-tree (kdtree) or a matrix product (dense); "
              "with retrieval words, kdtree and dense both index the retrieved places densely")
        .Enum("retrieval", &C::retrieval,
              {{C::Retrieval::kAuto, "auto"},
               {C::Retrieval::kExact, "exact"},
               {C::Retrieval::kWords, "words"}},
              "places paired with a query: every one (exact), the retrieval_places most similar "
              "by a vocabulary of descriptors learned from the map (words), or words for SLAM's "
              "loop queries and the relocalizer's once it holds a fix, exact elsewhere (auto)")
        .Int("retrieval_places", &C::retrieval_places, "",
             "words (and auto where it retrieves): places paired with a query")
        .Enum("query_keypoints", &C::query_keypoints,
              {{C::QueryKeypoints::kStable, "stable"}, {C::QueryKeypoints::kAllScans, "all_scans"}},
              "query keypoints paired and verified: the submap's stable ones or all its scans'")
        .Double("query_merge_m", &C::query_merge_m, "m",
                "all_scans: a query keypoint this close to a kept one is dropped")
        .Nested("ransac", &C::ransac, RansacConfigFields())
        .Int("verification_neighbours", &C::verification_neighbours, "",
             "verify against the candidate and this many map neighbours on each side (0 = paper)")
        .Int("min_consensus", &C::min_consensus, "", "first check: RANSAC inliers")
        .Enum("consensus_counting", &C::consensus_counting,
              {{C::ConsensusCounting::kQueryKeypoints, "query_keypoints"},
               {C::ConsensusCounting::kDistinctReference, "distinct_reference"}},
              "what the consensus counts")
        .Double("min_gamma", &C::min_gamma, "",
                "gamma_min: second check, Eq. (10), for stable query keypoints")
        .Double("min_gamma_all_scans", &C::min_gamma_all_scans, "",
                "gamma_min for queries verified with their all-scan keypoints")
        .Double("min_reference_coverage", &C::min_reference_coverage, "",
                "third check: share of reference keypoints in the overlap hit (0 = off)")
        .Double("dense_min_hit_fraction", &C::dense_min_hit_fraction, "",
                "dense veto: least share of query endpoints on the candidate's walls (0 = off)")
        .Double("dense_max_see_through", &C::dense_max_see_through, "",
                "dense veto: largest share of query beams passing through its walls")
        .Double("dense_sure_hit_fraction", &C::dense_sure_hit_fraction, "",
                "dense check passes in place of gamma: share of endpoints on the walls ...")
        .Double("dense_sure_see_through", &C::dense_sure_see_through, "",
                "... and largest share of beams through them")
        .Double("double_match_m", &C::double_match_m, "m",
                "lambda: max distance of a doubly matched pair")
        .Enum("gamma_counting", &C::gamma_counting,
              {{C::GammaCounting::kUniquePairs, "unique_pairs"},
               {C::GammaCounting::kPerKeypoint, "per_keypoint"}},
              "how n_dm of gamma counts doubly matched keypoints")
        .Enum("selection", &C::selection,
              {{C::Selection::kFirstVerified, "first_verified"},
               {C::Selection::kBestScore, "best_score"}},
              "which verified candidate answers: the first (paper) or the best-scoring")
        .Enum("score", &C::score,
              {{C::Score::kGamma, "gamma"},
               {C::Score::kConsensus, "consensus"},
               {C::Score::kConsensusGamma, "consensus_gamma"}},
              "score of a verified candidate")
        .Double("distinct_distance_m", &C::distinct_distance_m, "m",
                "two verified candidates are distinct beyond this distance ...")
        .Double("distinct_angle_deg", &C::distinct_angle_deg, "deg", "... or this angle")
        .Double(
            "ambiguity_ratio", &C::ambiguity_ratio, "",
            "ambiguous when a distinct candidate scores this fraction of the best (>= 1: never)")
        .Double("min_confidence", &C::min_confidence, "",
                "answers below this confidence are refused")
        .Int("confidence_consensus", &C::confidence_consensus, "",
             "consensus at which the confidence's consensus factor saturates");
    return table;
  }();
  return fields;
}

PlaceRecognitionConfig PaperPlaceConfig() {
  PlaceRecognitionConfig config;
  config.pair_matching = PlaceRecognitionConfig::PairMatching::kQueryOrder;
  config.ransac.exhaustive_max_pairs = 0;
  config.selection = PlaceRecognitionConfig::Selection::kFirstVerified;
  config.score = PlaceRecognitionConfig::Score::kGamma;
  config.ambiguity_ratio = 1.0;
  config.verification_neighbours = 0;
  config.query_keypoints = PlaceRecognitionConfig::QueryKeypoints::kStable;
  config.consensus_counting = PlaceRecognitionConfig::ConsensusCounting::kQueryKeypoints;
  config.min_gamma_all_scans = 0.4;     // unused: stable query keypoints
  config.min_reference_coverage = 0.0;  // unused: stable query keypoints
  config.dense_min_hit_fraction = 0.0;  // gamma decides, as in the paper
  config.candidate_ranking = PlaceRecognitionConfig::CandidateRanking::kMeanDistance;
  config.retrieval = PlaceRecognitionConfig::Retrieval::kExact;  // every place, SLAM's too
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
  Require(config.retrieval_places >= 1, "retrieval_places", "must be >= 1");
  Require(config.ransac.inlier_distance_m > 0.0, "ransac.inlier_distance_m", "must be positive");
  Require(config.ransac.iterations >= 1, "ransac.iterations", "must be >= 1");
  Require(config.ransac.exhaustive_max_pairs >= 0, "ransac.exhaustive_max_pairs", "must be >= 0");
  Require(config.ransac.rigidity_m2 > 0.0, "ransac.rigidity_m2", "must be positive");
  Require(config.ransac.min_fit_sigma_m >= 0.0, "ransac.min_fit_sigma_m", "must be >= 0");
  Require(config.verification_neighbours >= 0, "verification_neighbours", "must be >= 0");
  Require(config.min_consensus >= 2, "min_consensus", "must be >= 2");
  RequireFraction(config.min_gamma, "min_gamma");
  RequireFraction(config.min_gamma_all_scans, "min_gamma_all_scans");
  RequireFraction(config.min_reference_coverage, "min_reference_coverage");
  RequireFraction(config.dense_min_hit_fraction, "dense_min_hit_fraction");
  RequireFraction(config.dense_max_see_through, "dense_max_see_through");
  RequireFraction(config.dense_sure_hit_fraction, "dense_sure_hit_fraction");
  RequireFraction(config.dense_sure_see_through, "dense_sure_see_through");
  Require(config.double_match_m > 0.0, "double_match_m", "must be positive");
  Require(config.distinct_distance_m > 0.0, "distinct_distance_m", "must be positive");
  Require(config.distinct_angle_deg > 0.0, "distinct_angle_deg", "must be positive");
  Require(config.ambiguity_ratio > 0.0, "ambiguity_ratio", "must be positive");
  RequireFraction(config.min_confidence, "min_confidence");
  Require(config.confidence_consensus >= 1, "confidence_consensus", "must be >= 1");
}

std::vector<std::pair<std::string, std::string>> ToKeyValues(const PlaceRecognitionConfig& config) {
  return PlaceConfigFields().ToKeyValues(config);
}

void ApplyKeyValues(const std::map<std::string, std::string>& values,
                    PlaceRecognitionConfig& config) {
  PlaceConfigFields().Apply(values, config);
  Validate(config);
}

}  // namespace keyplace
