#pragma once
// Place recognition (paper Section 4): submap matching by unique descriptor pairs (Algorithm 3),
// RANSAC pose estimation (Eq. 9), first (consensus) and second (gamma, Eq. 10) geometric
// verification. A "place" is a set of keypoints in its own frame with the world pose of that
// frame: a submap of a GlobalMap, or a single scan (the TIP-FLIRT baseline), on the same code.
// Descriptor pairs come from an exact index over all place keypoints (descriptor_index), or from
// exhaustive matching (descriptor_index none): the oracle, with the same pairs.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/descriptor.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/place/dense_check.hpp"
#include "keyplace/place/pair_memo.hpp"
#include "keyplace/place/place_config.hpp"

namespace keyplace {

struct Place {
  int id = 0;                                   // submap id (or scan index for single-scan places)
  Pose2 T_world_place;                          // P_r[0]: the world pose of the place's frame
  std::vector<Eigen::Vector2d> positions;       // keypoints, place frame
  std::vector<BetaGridDescriptor> descriptors;  // same order
  std::vector<int> scan_indices;                // scans the place was built from
  // Optional, for the dense check: the cells its scans' beams ended in (Submap::occupancy), in
  // the place frame, of occupancy_cell_m. Empty: the place is judged by its keypoints alone.
  std::vector<Eigen::Vector2i> occupancy_cells;
  double occupancy_cell_m = 0.0;
};

/// One place per submap, in map order (keypoints in the submap frame, T_world_place = P[0]).
std::vector<Place> PlacesFromMap(const GlobalMap& map);

/// Ids of the first `candidates` places whose origin lies within `radius_m` of `position_m`, at
/// most `count` of them, nearest first (ties: map order): PlaceQuery::also_search_ids for a
/// query the caller already places near position_m.
std::vector<int> PlaceIdsNear(const std::vector<Place>& places, std::size_t candidates,
                              const Eigen::Vector2d& position_m, double radius_m,
                              std::size_t count);

/// What a query under `config` names near position_m (PlaceQuery::also_search_ids): PlaceIdsNear
/// within radius_m, at most config.retrieval_places; none unless the query retrieves (retrieval
/// `words`, or a query `by_words`: the exact path pairs every place anyway) and radius_m > 0.
std::vector<int> PlaceIdsToAlsoSearch(const PlaceRecognitionConfig& config, bool by_words,
                                      const std::vector<Place>& places, std::size_t candidates,
                                      const Eigen::Vector2d& position_m, double radius_m);

/// The keypoints of the current submap S_c in its own frame (P_c[0]) and p_c: the pose to
/// estimate, relative to P_c[0] (its last scan in the paper).
struct PlaceQuery {
  std::vector<Eigen::Vector2d> positions;
  std::vector<BetaGridDescriptor> descriptors;
  Pose2 T_first_evaluated;
  // Optional: every keypoint of every scan of S_c in the same frame (used with
  // PlaceRecognitionConfig::QueryKeypoints::kAllScans; may hold near-duplicates, merged there).
  std::vector<Eigen::Vector2d> all_positions;
  std::vector<BetaGridDescriptor> all_descriptors;
  // Optional: the latest scans' beams in the same frame, for the dense check
  // (PlaceRecognitionConfig::dense_min_hit_fraction). Empty: keypoints alone decide.
  std::vector<QueryScanPoints> scans;
  // Optional, with retrieval `words` or by_words: ids of places paired whatever their words rank
  // (those near where the caller already believes the query lies: SLAM's estimate, the
  // Relocalizer's answers and fix). `exact` pairs every place anyway; an id the map does not hold,
  // or an excluded place, is not searched.
  std::vector<int> also_search_ids;
  // Pair only the places the words retrieve (and also_search_ids), whatever the recognizer's
  // retrieval: the Relocalizer's queries once it holds a fix (PlaceRecognitionConfig::kAuto).
  // Needs a recognizer that learned the words (retrieval words, or LearnWords::kAlways).
  bool by_words = false;
  // Optional: the growing query's memo of descriptor pairs (PairMemo), used and updated when the
  // query pairs every place through the descriptor index. The answer does not depend on it.
  PairMemo* pair_memo = nullptr;
};

/// Greedy merge: keeps each keypoint unless one already kept lies within `radius_m` (input order
/// decides; radius 0 keeps all). Returns the kept indices.
std::vector<int> MergeNearbyKeypoints(const std::vector<Eigen::Vector2d>& positions,
                                      double radius_m);

/// The consensus of an inlier set (query index, reference index) under `counting`.
int CountConsensus(const std::vector<std::pair<int, int>>& inliers,
                   PlaceRecognitionConfig::ConsensusCounting counting);

/// A descriptor pair of Algorithm 3: (query keypoint, place keypoint, symmetric chi2).
struct DescriptorPair {
  int current = 0;
  int reference = 0;
  double distance = 0.0;
};

/// Unique descriptor pairs below `chi2_threshold` (each keypoint used at most once), by comparing
/// every current with every reference descriptor.
std::vector<DescriptorPair> MatchDescriptorPairs(const std::vector<BetaGridDescriptor>& current,
                                                 const std::vector<BetaGridDescriptor>& reference,
                                                 double chi2_threshold,
                                                 PlaceRecognitionConfig::PairMatching mode);

/// The second geometric verification, Eq. (10), with the current keypoints mapped by T_ref_cur
/// into the reference frame. The overlap area is the intersection of the two axis-aligned
/// bounding boxes (reference frame) of the keypoints; n_r, n_c count the keypoints inside it.
struct GammaResult {
  double gamma = 0.0;  // 0 when the overlap holds no keypoint
  int reference_in_overlap = 0;
  int current_in_overlap = 0;
  double double_matched = 0.0;  // n_dm (pairs, or half-counts of keypoints; see GammaCounting)
};
GammaResult ComputeGamma(const std::vector<Eigen::Vector2d>& reference_positions,
                         const std::vector<BetaGridDescriptor>& reference_descriptors,
                         const std::vector<Eigen::Vector2d>& current_positions,
                         const std::vector<BetaGridDescriptor>& current_descriptors,
                         const Pose2& T_ref_cur, double lambda_m, double chi2_threshold,
                         PlaceRecognitionConfig::GammaCounting counting);

/// The fraction of the reference keypoints inside the overlap box (as for gamma: the intersection
/// of both keypoint bounding boxes, the current keypoints mapped by T_ref_cur) that have a mapped
/// current keypoint within `radius_m`. 0 when the overlap holds no reference keypoint.
double ReferenceCoverage(const std::vector<Eigen::Vector2d>& reference_positions,
                         const std::vector<Eigen::Vector2d>& current_positions,
                         const Pose2& T_ref_cur, double radius_m);

/// One candidate place that went through RANSAC.
struct CandidateResult {
  int place_index = -1;
  int pairs = 0;
  double mean_pair_distance = 0.0;
  int consensus = 0;
  double gamma = 0.0;
  double reference_coverage = 0.0;  // see ReferenceCoverage, with the RANSAC query keypoints
  // The dense score, when the check is on, the query has its scans and the place its occupancy,
  // and whether it confirmed the pose beyond doubt, which passes the second check whatever gamma
  // (PlaceRecognitionConfig::dense_sure_hit_fraction).
  bool dense_checked = false;
  bool dense_sure = false;
  DenseScore dense;
  // The dense check applied (enough of the query's endpoints in the candidate's area) and did not
  // veto the pose: the beams support it, whatever gamma says (PlaceMatch::weak).
  bool dense_supported = false;
  bool verified = false;  // passed all checks (within a sweep: at its lowest gamma_min)
  Pose2 T_ref_cur;
  Pose2 estimated_pose;  // Eq. (9)
  // Covariance of estimated_pose over its (x, y, theta) (world frame): RigidFitCovariance of the
  // RANSAC inliers, carried through T_world_place and the query's pose (ComposedCovariance).
  Eigen::Matrix3d estimated_pose_covariance = Eigen::Matrix3d::Zero();
  double score = 0.0;  // selection score (PlaceRecognitionConfig::score), verified only
};

struct PlaceMatch {
  // A candidate passed both checks (the best one is described below), before the ambiguity and
  // confidence filters.
  bool verified = false;
  // The answer is accepted: verified, not ambiguous, confidence >= min_confidence.
  bool found = false;
  // A distinct verified candidate (pose farther than distinct_*) scored >= ambiguity_ratio * best.
  bool ambiguous = false;
  int place_index = -1;  // into the recognizer's places
  int place_id = -1;
  Pose2 T_ref_cur;       // P_c[0] in the frame of P_r[0]
  Pose2 estimated_pose;  // p^ = P_r[0] * T_ref_cur * p_c (Eq. 9), world frame
  // Its covariance over (x, y, theta), derived from the match (CandidateResult).
  Eigen::Matrix3d estimated_pose_covariance = Eigen::Matrix3d::Zero();
  int pairs = 0;
  int consensus = 0;
  double gamma = 0.0;
  double reference_coverage = 0.0;
  bool dense_checked = false;  // of the answer (CandidateResult)
  DenseScore dense;
  double score = 0.0;
  double second_score = 0.0;  // best distinct verified candidate (0 if none)
  // In [0, 1]: min(1, consensus / confidence_consensus) * gamma * (1 - second_score / score).
  double confidence = 0.0;
  int candidates = 0;  // places with >= mu pairs
  // Candidates that went through RANSAC in the sequential order, up to and including the first
  // verified one for `first_verified` (RANSACs verified ahead in a wave are not counted).
  int candidates_verified = 0;
  int candidates_accepted = 0;  // candidates that passed both checks
  int places_excluded = 0;      // skipped by the exclusion predicate
  // Query descriptors whose pairs came from PlaceQuery::pair_memo (-1: the memo was not used).
  int descriptors_remembered = -1;
  double seconds_pairing = 0.0;
  double seconds_verification = 0.0;
  double seconds = 0.0;
  std::vector<CandidateResult> verified_candidates;  // those that passed both checks
  // The weak answer: of the candidates whose RANSAC passed the first check and whose pose the
  // dense check supports (CandidateResult::dense_supported), verified or not, the one with the
  // largest consensus; nullopt when there is none, or when a distinct one (distinct_*) has at
  // least ambiguity_ratio of its consensus. Where gamma or the coverage check rejects the right
  // pose (open halls keep few stable keypoints) it is still named here, as evidence that answers
  // of later queries can confirm (Relocalizer; docs/LOCALIZATION.md, "Weak answers").
  std::optional<CandidateResult> weak;
  // As confidence, for the weak answer (its gamma, consensus and the distinct runner-up's
  // consensus in place of the score).
  double weak_confidence = 0.0;
  // No weak answer because two distinct candidates the dense check supports tie on consensus: the
  // query sees a place that looks like another (as `ambiguous`, for the weak answers).
  bool weak_ambiguous = false;
};

/// Returns true for places the query must not be matched with (self-matches).
using PlaceExclusion = std::function<bool(const Place&)>;

/// The thresholds a parameter sweep varies (paper Figure 9): mu and gamma_min, the latter for
/// stable and for all-scan query keypoints alike (PlaceRecognitionConfig's fields of these names).
struct RecognitionThresholds {
  int min_pairs = 10;
  double min_gamma = 0.4;
  double min_gamma_all_scans = 0.15;
};

class SqrtDescriptorIndex;  // place/descriptor_index.hpp (internal)
class PlaceWords;           // place/place_words.hpp (internal)

class PlaceRecognizer {
 public:
  /// When the recognizer learns the words of its places: only when its retrieval is `words`, or
  /// always, for the queries that ask for them whatever the retrieval (PlaceQuery::by_words).
  enum class LearnWords { kForRetrievalWords, kAlways };

  /// Throws std::invalid_argument (Validate) for an invalid config.
  PlaceRecognizer(std::vector<Place> places, const PlaceRecognitionConfig& config,
                  LearnWords learn_words = LearnWords::kForRetrievalWords);
  // Copies share the index until one of them adds or removes a place (it then indexes its own).
  PlaceRecognizer(const PlaceRecognizer&) = default;
  PlaceRecognizer& operator=(const PlaceRecognizer&) = default;
  PlaceRecognizer(PlaceRecognizer&&) = default;
  PlaceRecognizer& operator=(PlaceRecognizer&&) = default;
  ~PlaceRecognizer();

  /// Appends a place (last in places()) and indexes its descriptors without rebuilding the index:
  /// with retrieval exact every answer is then the one of a recognizer constructed from places()
  /// at once. With words learned (retrieval kWords, LearnWords::kAlways) the place is described
  /// with the vocabulary held, which is learned anew from places() (answers as at once) when they
  /// hold twice the keypoints it was learned from; in between, retrieval's answers may differ
  /// from those of a recognizer built at once.
  /// Throws std::invalid_argument when its positions and descriptors differ in size.
  void AddPlace(Place place);
  /// Removes the first place with this id (later places move up one index); every answer is then
  /// the one of a recognizer constructed from the remaining places() at once. The index forgets
  /// the place's keypoints lazily (a rebuild from places() once the removed keypoints outnumber
  /// the live ones). Returns false, and changes nothing, when no place has the id.
  bool RemovePlace(int place_id);
  /// Sets the world pose of places()[place_index] (no index change: descriptors do not move).
  /// Throws std::out_of_range for an index outside places().
  void SetPlacePose(std::size_t place_index, const Pose2& T_world_place);

  /// Not thread-safe with AddPlace, RemovePlace or SetPlacePose on the same recognizer. Uses the
  /// threads TBB allows (tbb::global_control, the calling task arena) for the pairs of blocks of
  /// places, the candidates' ranking and their verification; every field of the answer but the
  /// seconds_* timings is the same at any number of threads. `exclude` is called on the calling
  /// thread only, but how often depends on the threads (neighbours of candidates verified ahead
  /// in a wave), so it must be a pure predicate. With `first_verified` a wave verifies as many
  /// candidates as there are threads, also when queries already run in parallel, so up to
  /// threads - 1 RANSACs past the first verified one run and are not counted. Throws
  /// std::invalid_argument for a query by_words to a recognizer without words.
  PlaceMatch Recognize(const PlaceQuery& query, const PlaceExclusion& exclude = {}) const;

  /// Recognize under each of `thresholds` (this recognizer's config with min_pairs, min_gamma and
  /// min_gamma_all_scans replaced), sharing what they have in common: the descriptor pairs are
  /// found once, for the smallest mu, and each candidate is verified at most once (its gamma is
  /// then compared with each threshold; a candidate's RANSAC does not depend on the others).
  /// answers[k] equals the Recognize answer of a recognizer built with thresholds[k] in every
  /// field but the seconds_* timings, which are those of the shared work. Recognize is this with
  /// the config's own thresholds. Throws std::invalid_argument for a threshold that Validate
  /// would refuse, naming it.
  std::vector<PlaceMatch> RecognizeAtThresholds(
      const PlaceQuery& query, const std::vector<RecognitionThresholds>& thresholds,
      const PlaceExclusion& exclude = {}) const;

  const std::vector<Place>& places() const { return places_; }
  const PlaceRecognitionConfig& config() const { return config_; }

 private:
  // A new index over places_ (slots 0..n-1), forgetting removed keypoints; none for
  // descriptor_index none or retrieval words (the retrieved places get one per query).
  void RebuildIndex();
  // The vocabulary and word histograms of places_ (learns_words_), learned anew.
  void RebuildWords();
  // Adds places_.back() to the word histograms, learning the vocabulary anew when due.
  void AddWordsOfLastPlace();

  std::vector<Place> places_;
  PlaceRecognitionConfig config_;
  std::shared_ptr<SqrtDescriptorIndex> index_;  // null for descriptor_index none or words
  std::vector<std::size_t> slots_;              // index place number of each of places_
  std::size_t removed_keypoints_ = 0;           // still in index_, of removed places
  bool learns_words_ = false;                   // retrieval words, or LearnWords::kAlways
  std::shared_ptr<PlaceWords> words_;           // null unless learns_words_
};

}  // namespace keyplace
