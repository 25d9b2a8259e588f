#pragma once
// Parameters of place recognition (paper Section 4, defaults from Table V and Section 5.2).
// Every reading of an ambiguity in the paper is a field here; docs/PLACE.md explains each one.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "keyplace/place/ransac.hpp"

namespace keyplace {

struct PlaceRecognitionConfig {
  // --- submap matching (Algorithm 3)
  int min_pairs = 10;        // mu: unique descriptor pairs for a candidate
  int max_candidates = 500;  // n_c: candidates verified, by increasing mean pair distance
  // Which n_c candidates are verified when there are more. kMeanDistance: the n_c with the
  // smallest mean pair distance (the paper). kRigidPairs: the n_c whose descriptor pairs agree
  // best with one rigid transform (LargestRigidStar in src/place/candidate_ranking.hpp, ties by
  // mean distance). Either way the chosen ones are verified by increasing mean pair distance, so
  // with n_c or fewer candidates both give the same answer (docs/PLACE.md, "Candidate ranking").
  enum class CandidateRanking { kMeanDistance, kRigidPairs };
  CandidateRanking candidate_ranking = CandidateRanking::kRigidPairs;
  double descriptor_match_chi2 = 0.4;  // a descriptor pair: symmetric chi2 below this
  // How "FindUniqueMatch" pairs keypoints, each used at most once. kQueryOrder: every query
  // keypoint in turn takes its nearest still-unused reference keypoint (Algorithm 3 read
  // literally). kGlobalGreedy: all pairs below the threshold by increasing distance.
  enum class PairMatching { kQueryOrder, kGlobalGreedy };
  PairMatching pair_matching = PairMatching::kGlobalGreedy;
  // How the pairs below descriptor_match_chi2 are found; every choice finds exactly the same pairs
  // (docs/PLACE.md, "Descriptor index"). kNone: every query keypoint against every place keypoint
  // (the oracle). kKdTree, kDense: ||sqrt(x) - sqrt(y)||^2 <= 2 chi2_sym(x, y), so only the place
  // keypoints within a radius^2 of 2 * descriptor_match_chi2 of the query keypoint in square-root
  // space get the exact chi2 test; kKdTree finds them by a nanoflann kd-tree, kDense by one
  // matrix product of the query keypoints with all place keypoints.
  enum class DescriptorIndex { kNone, kKdTree, kDense };
  DescriptorIndex descriptor_index = DescriptorIndex::kDense;
  // Which places a query is paired with. kExact: every place (the oracle). kWords: the
  // retrieval_places places whose word histograms (a vocabulary of descriptors learned from the
  // map, tf-idf weighted) are most similar to the query's (docs/PLACE.md, "Retrieval"). kAuto:
  // kWords for SLAM's loop queries (a loop one submap's query misses, the next submaps' find) and
  // for the Relocalizer's queries while it holds a fix (they confirm or contradict it; the places
  // near the fix are paired too), kExact wherever else (PlaceRecognizer takes kAuto as kExact but
  // for a query that asks for the words, PlaceQuery::by_words): a searching query's miss is a
  // lost answer, and the Relocalizer fixed fewer starts with kWords (docs/notes/retrieval.md).
  enum class Retrieval { kAuto, kExact, kWords };
  Retrieval retrieval = Retrieval::kAuto;
  int retrieval_places = 50;
  // Which query keypoints go through pairing and RANSAC. kStable: the query submap's stable
  // keypoints (the paper). kAllScans: every keypoint of every scan of the query submap, in the
  // submap frame (PlaceQuery::all_positions), merged within query_merge_m; falls back to the
  // stable keypoints when the query has none. The gamma check always uses the stable keypoints.
  enum class QueryKeypoints { kStable, kAllScans };
  QueryKeypoints query_keypoints = QueryKeypoints::kAllScans;
  double query_merge_m = 0.05;  // kAllScans: a keypoint within this of a kept one is dropped

  // --- RANSAC (Section 4.1.1; FLIRTLib's RansacFeatureSetMatcher): inlier threshold, 18 sampled
  // hypotheses (FLIRTLib: p = 0.95, w = 0.4), every pair enumerated up to 40 descriptor pairs,
  // rigidity pre-check, refit on the inliers; the seed is combined with the place id.
  RansacConfig ransac;

  // --- geometric verification (Section 4.2)
  // Beyond the paper: verify (consensus and gamma) against the candidate submap together with
  // this many map neighbours on each side (places id - k .. id + k, mapped into the candidate's
  // frame; neighbour keypoints within inlier_distance_m of one already present are dropped).
  // Excluded places never contribute. Candidate ranking still uses the candidate alone. 0 = the
  // paper.
  int verification_neighbours = 1;
  int min_consensus = 9;  // first check: RANSAC inliers
  // Third check (beyond the paper; 0 = off; 0.5 in the "strict" preset), for queries verified
  // with their all-scan keypoints
  // only: the fraction of the reference keypoints inside the overlap box that a verified query
  // keypoint hits within inlier_distance_m. Stable keypoints are the ones that reappear, so a
  // true revisit re-observes most of them, while a chance alignment of ~100 query keypoints hits
  // a few. A stable-keypoint query (SLAM, paper preset) sees too little of the reference for
  // this to mean anything and is not checked (docs/PLACE.md, "Reference coverage").
  double min_reference_coverage = 0.0;
  // How the consensus is counted. kQueryKeypoints: query keypoints with a reference keypoint
  // within inlier_distance_m (the paper). kDistinctReference: distinct reference keypoints hit by
  // those inliers (several query keypoints on one reference keypoint count once).
  enum class ConsensusCounting { kQueryKeypoints, kDistinctReference };
  ConsensusCounting consensus_counting = ConsensusCounting::kDistinctReference;
  // Dense check (beyond the paper; place/dense_check.hpp, docs/PLACE.md "Dense check"), for a
  // query that carries its scans' beams (PlaceQuery::scans) with enough of them ending in the
  // candidate's area. Veto: fewer than dense_min_hit_fraction of those endpoints on the
  // candidate's occupied cells, or more than dense_max_see_through of the beams crossing its
  // area passing through one, refuse the candidate whatever its keypoints say. Sure: at least
  // dense_sure_hit_fraction on them and at most dense_sure_see_through through them pass the
  // second check in place of gamma. dense_min_hit_fraction 0 = off. All four chosen on FR079 and
  // Intel (docs/PLACE.md).
  double dense_min_hit_fraction = 0.5;
  double dense_max_see_through = 0.3;
  double dense_sure_hit_fraction = 0.8;
  double dense_sure_see_through = 0.1;
  double min_gamma = 0.4;  // gamma_min: second check, Eq. (10), for stable query keypoints
  // gamma_min when the query was paired and verified with its all-scan keypoints (kAllScans and
  // PlaceQuery::all_positions given): lower, because that consensus already rejects wrong
  // candidates (docs/PLACE.md). Queries with stable keypoints only (e.g. SLAM) keep min_gamma.
  double min_gamma_all_scans = 0.15;
  double double_match_m = 0.05;  // lambda: max distance of a doubly matched pair
  // How n_dm counts doubly matched keypoints. kUniquePairs: pairs in a one-to-one matching (by
  // increasing distance), gamma = 2 n_pairs / (n_r + n_c). kPerKeypoint: every keypoint of either
  // side with some double match counts half, gamma = (n_dm_r + n_dm_c) / (n_r + n_c).
  enum class GammaCounting { kUniquePairs, kPerKeypoint };
  GammaCounting gamma_counting = GammaCounting::kUniquePairs;

  // --- which verified candidate answers
  // kFirstVerified: the first candidate (in mean-distance order) that passes both checks (the
  // paper). kBestScore: verify all n_c candidates and answer the one with the highest score.
  enum class Selection { kFirstVerified, kBestScore };
  Selection selection = Selection::kBestScore;
  // The score of a verified candidate: kGamma, kConsensus, or kConsensusGamma = consensus * gamma.
  enum class Score { kGamma, kConsensus, kConsensusGamma };
  Score score = Score::kConsensusGamma;

  // --- confidence and ambiguity (beyond the paper)
  // Two verified candidates are distinct when their estimated poses differ by more than these.
  double distinct_distance_m = 1.0;
  double distinct_angle_deg = 20.0;
  // The answer is ambiguous when a distinct verified candidate scores at least this fraction of
  // the best score (1 or more = never ambiguous).
  double ambiguity_ratio = 0.8;
  // Answers below this confidence are not accepted (confidence in [0, 1], see PlaceMatch).
  double min_confidence = 0.0;
  // Consensus at which the consensus factor of the confidence saturates.
  int confidence_consensus = 20;
};

/// The paper's method as closely as we can: Algorithm 3 pairing in query order, 18 sampled
/// hypotheses (FLIRTLib), first verified candidate wins, no ambiguity rejection.
PlaceRecognitionConfig PaperPlaceConfig();

/// The default with the reference-coverage check at 0.5: for localizing in a map recorded on
/// another day (no query shares scans with the map), where it lifts precision to >= 0.99 at some
/// recall (docs/PLACE.md).
PlaceRecognitionConfig StrictPlaceConfig();

/// "default" | "paper" | "strict"; throws std::invalid_argument naming the accepted values.
PlaceRecognitionConfig PlacePreset(const std::string& name);

/// Throws std::invalid_argument naming the first invalid field.
void Validate(const PlaceRecognitionConfig& config);

/// Every field as (name, text value), in declaration order; enums as lower-case names.
std::vector<std::pair<std::string, std::string>> ToKeyValues(const PlaceRecognitionConfig& config);

/// Sets the named fields from text. Throws std::invalid_argument naming the key for an unknown
/// key or a value that does not parse. The result is validated.
void ApplyKeyValues(const std::map<std::string, std::string>& values,
                    PlaceRecognitionConfig& config);

}  // namespace keyplace
