// PlaceRecognizer::Recognize and RecognizeAtThresholds: Algorithm 3 against every place, the
// ranking of the candidates, their geometric verification and the choice of the answer. The
// stages run in parallel (TBB), each result into its own slot, gathered in place or candidate
// order: the same answer at any number of threads.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "common/seconds_since.hpp"
#include "keyplace/place/dense_check.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "keyplace/place/ransac.hpp"
#include "place/candidate_ranking.hpp"
#include "place/descriptor_index.hpp"
#include "place/pair_memo.hpp"
#include "place/place_words.hpp"
#include "place/unique_pairs.hpp"

namespace keyplace {
namespace {

using Clock = std::chrono::steady_clock;

double SelectionScore(PlaceRecognitionConfig::Score score, int consensus, double gamma) {
  switch (score) {
    case PlaceRecognitionConfig::Score::kGamma:
      return gamma;
    case PlaceRecognitionConfig::Score::kConsensus:
      return consensus;
    case PlaceRecognitionConfig::Score::kConsensusGamma:
      break;
  }
  return consensus * gamma;
}

// Mixes the RANSAC seed with the place id so that each place's hypotheses do not depend on the
// order in which candidates are verified.
std::uint64_t PlaceSeed(std::uint64_t seed, int place_id) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(place_id) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// A place with enough unique pairs (Algorithm 3).
struct Candidate {
  int place_index = -1;  // -1: not a candidate
  double mean_distance = 0.0;
  std::vector<DescriptorPair> pairs;
};

// Grain sizes of the parallel loops (TBB): places of the unique pairs per task (microseconds each
// with an index), candidates of LargestRigidStar per task (O(pairs^2) each). Candidates are
// verified in parallel (a RANSAC each, grain 1).
constexpr std::size_t kPlacesPerTask = 16;
constexpr std::size_t kRankedCandidatesPerTask = 4;
// Fewest query endpoints in the reference's area for a dense score to count.
constexpr int kDenseMinEndpoints = 50;

// The query keypoints paired and verified by RANSAC: the stable ones, or those of every scan
// merged (kAllScans; the gamma check uses the stable ones either way).
struct MatchKeypoints {
  std::vector<Eigen::Vector2d> positions;
  std::vector<BetaGridDescriptor> descriptors;
  bool all_scans = false;
};

MatchKeypoints QueryMatchKeypoints(const PlaceQuery& query, const PlaceRecognitionConfig& config) {
  MatchKeypoints keypoints;
  if (config.query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans &&
      !query.all_positions.empty()) {
    keypoints.all_scans = true;
    for (int k : MergeNearbyKeypoints(query.all_positions, config.query_merge_m)) {
      keypoints.positions.push_back(query.all_positions[k]);
      keypoints.descriptors.push_back(query.all_descriptors[k]);
    }
    return keypoints;
  }
  keypoints.positions = query.positions;
  keypoints.descriptors = query.descriptors;
  return keypoints;
}

// Algorithm 3 against every place of at least `min_pairs` keypoints that `exclude` lets through.
struct Pairing {
  std::vector<Candidate> by_place;  // place p's unique pairs (place_index -1: < min_pairs)
  std::vector<char> excluded;       // places of >= min_pairs keypoints that `exclude` rejected
  int descriptors_remembered = -1;  // PlaceMatch's
};

// Of the places marked in `searched`, keeps the `count` most similar to the query by their words
// (ties: the earlier place).
void KeepRetrieved(const PlaceWords& words, const std::vector<BetaGridDescriptor>& query,
                   std::size_t count, std::vector<char>& searched) {
  const std::vector<double> similarity = words.Similarities(query);
  std::vector<int> order;
  for (std::size_t p = 0; p < searched.size(); ++p) {
    if (searched[p]) order.push_back(static_cast<int>(p));
  }
  if (order.size() <= count) return;
  // Only the first `count` need an order: O(places log count), not a sort of the whole map.
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count), order.end(),
                    [&similarity](int a, int b) {
                      const double similarity_a = similarity[static_cast<std::size_t>(a)];
                      const double similarity_b = similarity[static_cast<std::size_t>(b)];
                      return similarity_a > similarity_b || (similarity_a == similarity_b && a < b);
                    });
  for (std::size_t k = count; k < order.size(); ++k)
    searched[static_cast<std::size_t>(order[k])] = 0;
}

// Retrieval pairs a few places: they get a dense index of their own for the query (the same pairs
// as any index), so that the recognizer keeps none over the whole map. `slot_of[p]`: the index
// slot of each searched place p.
std::unique_ptr<SqrtDescriptorIndex> IndexOfRetrieved(const std::vector<Place>& places,
                                                      const std::vector<char>& searched,
                                                      std::vector<std::size_t>& slot_of) {
  auto index = std::make_unique<SqrtDescriptorIndex>(
      std::vector<Place>{}, PlaceRecognitionConfig::DescriptorIndex::kDense);
  slot_of.assign(places.size(), 0);
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (searched[p]) slot_of[p] = index->AddPlace(places[p].descriptors);
  }
  return index;
}

Pairing PairWithPlaces(const std::vector<Place>& places, const SqrtDescriptorIndex* index,
                       const std::vector<std::size_t>& slots, const PlaceRecognitionConfig& config,
                       const std::vector<BetaGridDescriptor>& query,
                       const std::vector<int>& also_search_ids, std::size_t min_pairs,
                       const PlaceExclusion& exclude, const PlaceWords* words, PairMemo* memo) {
  Pairing pairing;
  pairing.by_place.resize(places.size());
  pairing.excluded.assign(places.size(), 0);
  std::vector<char> searched(places.size(), 0);
  // Retrieval ranks every place `exclude` lets through, whatever mu: RecognizeAtThresholds pairs
  // once for all its thresholds, so the places retrieved must not depend on mu.
  const auto too_small = [&](std::size_t p) { return places[p].positions.size() < min_pairs; };
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (!words && too_small(p)) continue;  // can never reach mu pairs
    if (exclude && exclude(places[p])) {
      pairing.excluded[p] = 1;
      continue;
    }
    searched[p] = 1;
  }
  if (words) {
    const std::vector<char> eligible = searched;
    KeepRetrieved(*words, query, static_cast<std::size_t>(config.retrieval_places), searched);
    std::vector<int> also = also_search_ids;
    std::sort(also.begin(), also.end());
    for (std::size_t p = 0; p < places.size(); ++p) {
      if (eligible[p] && std::binary_search(also.begin(), also.end(), places[p].id))
        searched[p] = 1;
      searched[p] = searched[p] && !too_small(p);
    }
  }
  // The index finds, per place, the pairs below the threshold that the exhaustive loop of
  // MatchDescriptorPairs finds, in its order and with its distances.
  std::vector<std::vector<DescriptorPair>> below;  // by index slot
  std::vector<std::size_t> retrieved_slots;
  std::unique_ptr<SqrtDescriptorIndex> retrieved;
  if (words && config.descriptor_index != PlaceRecognitionConfig::DescriptorIndex::kNone) {
    retrieved = IndexOfRetrieved(places, searched, retrieved_slots);
    index = retrieved.get();
  }
  const std::vector<std::size_t>& slot_of = retrieved ? retrieved_slots : slots;
  if (index) {
    std::vector<char> searched_slots(index->places(), 0);
    for (std::size_t p = 0; p < places.size(); ++p) {
      if (searched[p]) searched_slots[slot_of[p]] = 1;
    }
    if (memo && !retrieved) {
      PairMemoAccess::FindPairs(*memo, *index, query, config.descriptor_match_chi2, searched_slots,
                                below);
      pairing.descriptors_remembered = static_cast<int>(memo->reused());
    } else {
      index->FindPairs(query, config.descriptor_match_chi2, searched_slots, below);
    }
  }
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, places.size(), kPlacesPerTask),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t p = range.begin(); p != range.end(); ++p) {
          if (!searched[p]) continue;
          const Place& place = places[p];
          std::vector<DescriptorPair> pairs =
              index ? UniquePairs(std::move(below[slot_of[p]]), query.size(),
                                  place.descriptors.size(), config.pair_matching)
                    : MatchDescriptorPairs(query, place.descriptors, config.descriptor_match_chi2,
                                           config.pair_matching);
          if (pairs.size() < min_pairs) continue;
          double sum = 0.0;
          for (const DescriptorPair& pair : pairs) sum += pair.distance;
          pairing.by_place[p] = {static_cast<int>(p), sum / static_cast<double>(pairs.size()),
                                 std::move(pairs)};
        }
      });
  return pairing;
}

// LargestRigidStar of each place, computed once when a ranking first needs it (-1: not yet).
void ComputeRigidStars(const Pairing& pairing, const std::vector<int>& place_indices,
                       const std::vector<Place>& places,
                       const std::vector<Eigen::Vector2d>& match_positions, double rigidity_m2,
                       std::vector<int>& rigid_star) {
  std::vector<int> missing;
  for (int p : place_indices) {
    if (rigid_star[static_cast<std::size_t>(p)] < 0) missing.push_back(p);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, missing.size(), kRankedCandidatesPerTask),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        const auto p = static_cast<std::size_t>(missing[k]);
                        rigid_star[p] = LargestRigidStar(pairing.by_place[p].pairs, match_positions,
                                                         places[p].positions, rigidity_m2);
                      }
                    });
}

// The candidates of one mu in verification order (place indices): the places with >= mu unique
// pairs by increasing mean pair distance (place order on ties); with more than n_c of them and
// kRigidPairs, the n_c most rigid in that order. Sets match.candidates and places_excluded.
std::vector<int> CandidatesInOrder(const Pairing& pairing, const std::vector<Place>& places,
                                   const PlaceRecognitionConfig& config, std::size_t min_pairs,
                                   const std::vector<Eigen::Vector2d>& match_positions,
                                   std::vector<int>& rigid_star, PlaceMatch& match) {
  std::vector<int> order;
  if (match_positions.size() < min_pairs) return order;  // nothing searched, nothing excluded
  for (std::size_t p = 0; p < places.size(); ++p) {
    if (pairing.excluded[p] && places[p].positions.size() >= min_pairs) ++match.places_excluded;
    const Candidate& candidate = pairing.by_place[p];
    if (candidate.place_index >= 0 && candidate.pairs.size() >= min_pairs) {
      order.push_back(static_cast<int>(p));
    }
  }
  std::stable_sort(order.begin(), order.end(), [&pairing](int a, int b) {
    return pairing.by_place[static_cast<std::size_t>(a)].mean_distance <
           pairing.by_place[static_cast<std::size_t>(b)].mean_distance;
  });
  match.candidates = static_cast<int>(order.size());
  const auto max_candidates = static_cast<std::size_t>(config.max_candidates);
  if (order.size() > max_candidates &&
      config.candidate_ranking == PlaceRecognitionConfig::CandidateRanking::kRigidPairs) {
    ComputeRigidStars(pairing, order, places, match_positions, config.ransac.rigidity_m2,
                      rigid_star);
    std::vector<int> stars;
    stars.reserve(order.size());
    for (int p : order) stars.push_back(rigid_star[static_cast<std::size_t>(p)]);
    std::vector<int> kept;
    kept.reserve(max_candidates);
    for (std::size_t k : KeepMostRigid(stars, max_candidates)) kept.push_back(order[k]);
    order = std::move(kept);
  }
  order.resize(std::min(order.size(), max_candidates));
  return order;
}

// What the verification of the candidates of one query reads.
struct Verification {
  const std::vector<Place>& places;
  const PlaceRecognitionConfig& config;
  const PlaceQuery& query;
  const Pairing& pairing;
  const std::vector<Eigen::Vector2d>& match_positions;  // the query keypoints paired
  double min_gamma;  // the lowest of the thresholds: a candidate below it passes none
  double min_coverage;
};

// The map neighbours of places[place_index] (ids adjacent to its own, within
// verification_neighbours, in offset order) that `exclude` lets through.
std::vector<int> VerificationNeighbours(const std::vector<Place>& places, int place_index,
                                        int verification_neighbours,
                                        const PlaceExclusion& exclude) {
  std::vector<int> neighbours;
  const Place& place = places[static_cast<std::size_t>(place_index)];
  const int count = static_cast<int>(places.size());
  for (int offset = -verification_neighbours; offset <= verification_neighbours; ++offset) {
    const int n = place_index + offset;
    if (offset == 0 || n < 0 || n >= count) continue;
    const Place& neighbour = places[static_cast<std::size_t>(n)];
    if (neighbour.id != place.id + offset) continue;  // not adjacent in the map
    if (exclude && exclude(neighbour)) continue;
    neighbours.push_back(n);
  }
  return neighbours;
}

// The occupied cells of a place and its verification neighbours, in the place's frame. (The
// places around the candidate within a lidar's range instead, excluded ones left out, gave fewer
// correct and more wrong answers on FR079: overlapping submaps thicken every wall.)
DenseReference ReferenceOccupancy(const std::vector<Place>& places, int place_index,
                                  const std::vector<int>& neighbours) {
  const Place& place = places[static_cast<std::size_t>(place_index)];
  std::vector<Eigen::Vector2i> cells = place.occupancy_cells;
  const double cell_m = place.occupancy_cell_m;
  for (int n : neighbours) {
    const Place& neighbour = places[static_cast<std::size_t>(n)];
    AppendCellsInFrame(neighbour.occupancy_cells, neighbour.occupancy_cell_m,
                       Between(place.T_world_place, neighbour.T_world_place), cell_m, cells);
  }
  return DenseReference(cells, cell_m);
}

// The dense score of a candidate when the check is on, the query carries its beams and the place
// its occupancy (the raster is built per candidate: not worth it when nothing reads the score).
void ScoreDense(const Verification& v, int place_index, const std::vector<int>& neighbours,
                const Pose2& T_ref_query, CandidateResult& result) {
  const Place& place = v.places[static_cast<std::size_t>(place_index)];
  if (v.config.dense_min_hit_fraction <= 0.0 || v.query.scans.empty() ||
      place.occupancy_cells.empty()) {
    return;
  }
  const DenseReference reference = ReferenceOccupancy(v.places, place_index, neighbours);
  if (reference.empty()) return;
  DenseVeto veto;
  veto.min_endpoints = kDenseMinEndpoints;
  veto.min_hit_fraction = v.config.dense_min_hit_fraction;
  veto.max_see_through = v.config.dense_max_see_through;
  result.dense = reference.Score(T_ref_query, v.query.scans, veto);
  result.dense_checked = true;
}

// RANSAC and the three checks of one candidate (the place's own seed: the answer does not depend
// on which other candidates are verified, nor in which order), with the lowest gamma_min of the
// thresholds. nullopt: neither verified nor supported by the beams (CandidateResult::verified,
// dense_supported).
std::optional<CandidateResult> VerifyCandidate(const Verification& v, const Candidate& candidate,
                                               const std::vector<int>& neighbours) {
  const PlaceRecognitionConfig& config = v.config;
  const Place& place = v.places[static_cast<std::size_t>(candidate.place_index)];
  std::vector<std::pair<int, int>> index_pairs;
  index_pairs.reserve(candidate.pairs.size());
  for (const DescriptorPair& pair : candidate.pairs) {
    index_pairs.emplace_back(pair.current, pair.reference);
  }
  RansacConfig ransac = config.ransac;
  ransac.seed = PlaceSeed(config.ransac.seed, place.id);
  // The reference: the candidate, then its map neighbours in its frame (pairs index the
  // candidate's keypoints, which come first).
  std::vector<Eigen::Vector2d> extended_positions;
  std::vector<BetaGridDescriptor> extended_descriptors;
  const std::vector<Eigen::Vector2d>* reference_positions = &place.positions;
  const std::vector<BetaGridDescriptor>* reference_descriptors = &place.descriptors;
  if (config.verification_neighbours > 0) {
    extended_positions = place.positions;
    extended_descriptors = place.descriptors;
    const double merge2 = config.ransac.inlier_distance_m * config.ransac.inlier_distance_m;
    for (int n : neighbours) {
      const Place& neighbour = v.places[static_cast<std::size_t>(n)];
      const Pose2 T_place_neighbour = Between(place.T_world_place, neighbour.T_world_place);
      const std::size_t own = extended_positions.size();
      for (std::size_t q = 0; q < neighbour.positions.size(); ++q) {
        const Eigen::Vector2d p = T_place_neighbour * neighbour.positions[q];
        bool duplicate = false;
        for (std::size_t j = 0; j < own && !duplicate; ++j) {
          duplicate = (extended_positions[j] - p).squaredNorm() < merge2;
        }
        if (duplicate) continue;
        extended_positions.push_back(p);
        extended_descriptors.push_back(neighbour.descriptors[q]);
      }
    }
    reference_positions = &extended_positions;
    reference_descriptors = &extended_descriptors;
  }
  const RansacResult estimate =
      EstimateRigidTransformRansac(*reference_positions, v.match_positions, index_pairs, ransac);
  if (!estimate.valid) return std::nullopt;
  const int consensus = CountConsensus(estimate.inliers, config.consensus_counting);
  if (consensus < config.min_consensus) return std::nullopt;  // first check
  CandidateResult result;
  // Second check. Where enough of the query's beams fall in the candidate's area they veto a
  // pose that puts them off its walls or through them, and a pose they confirm beyond doubt
  // needs no gamma (sparse stable keypoints make gamma small in open halls); elsewhere gamma.
  ScoreDense(v, candidate.place_index, neighbours, estimate.T_ref_cur, result);
  if (result.dense.vetoed) return std::nullopt;
  const bool dense_applies = result.dense_checked && result.dense.endpoints >= kDenseMinEndpoints;
  const GammaResult gamma =
      ComputeGamma(*reference_positions, *reference_descriptors, v.query.positions,
                   v.query.descriptors, estimate.T_ref_cur, config.double_match_m,
                   config.descriptor_match_chi2, config.gamma_counting);
  result.dense_sure = dense_applies &&
                      result.dense.hit_fraction >= config.dense_sure_hit_fraction &&
                      result.dense.see_through_fraction <= config.dense_sure_see_through;
  // Second check, then the third (ours). A candidate failing them is kept when the beams support
  // it: a weak answer (PlaceMatch::weak).
  result.dense_supported = dense_applies;
  const bool second_check = result.dense_sure || gamma.gamma >= v.min_gamma;
  if (!second_check && !result.dense_supported) return std::nullopt;
  const double coverage = ReferenceCoverage(*reference_positions, v.match_positions,
                                            estimate.T_ref_cur, config.ransac.inlier_distance_m);
  result.verified = second_check && coverage >= v.min_coverage;
  if (!result.verified && !result.dense_supported) return std::nullopt;
  result.place_index = candidate.place_index;
  result.pairs = static_cast<int>(candidate.pairs.size());
  result.mean_pair_distance = candidate.mean_distance;
  result.consensus = consensus;
  result.gamma = gamma.gamma;
  result.reference_coverage = coverage;
  result.T_ref_cur = estimate.T_ref_cur;
  result.estimated_pose = place.T_world_place * estimate.T_ref_cur * v.query.T_first_evaluated;
  result.estimated_pose_covariance = ComposedCovariance(
      place.T_world_place, estimate.T_ref_cur, v.query.T_first_evaluated,
      RigidFitCovariance(*reference_positions, v.match_positions, estimate.inliers,
                         estimate.T_ref_cur, config.ransac.min_fit_sigma_m));
  result.score = SelectionScore(config.score, consensus, gamma.gamma);
  return result;
}

// A verified candidate passes a threshold's second check when its beams confirm it beyond doubt,
// else by its gamma (thresholds of a sweep differ in gamma_min; the dense veto is the same).
bool PassesSecondCheck(const CandidateResult& result, double min_gamma) {
  return result.verified && (result.dense_sure || result.gamma >= min_gamma);
}

// The threads a parallel loop started here may use (the arena's, within the global control).
std::size_t AvailableThreads() {
  const auto arena = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  const std::size_t allowed =
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return std::max<std::size_t>(1, std::min(arena, allowed));
}

// Each place's verification, done at most once per query: the thresholds share it. Results are
// kept for the places verified only (a map may have 10^5 places).
struct VerifiedPlaces {
  explicit VerifiedPlaces(std::size_t places) : slot(places, -1) {}
  std::vector<int> slot;  // into results; -1: not verified
  std::vector<std::optional<CandidateResult>> results;
  bool Done(int p) const { return slot[static_cast<std::size_t>(p)] >= 0; }
  const std::optional<CandidateResult>& Result(int p) const {
    return results[static_cast<std::size_t>(slot[static_cast<std::size_t>(p)])];
  }
  bool Passes(int p, double min_gamma) const {
    return Done(p) && Result(p) && PassesSecondCheck(*Result(p), min_gamma);
  }
};

// Verifies the places of `order` (no place twice) not verified yet, in parallel, each into its
// own slot. With `first_passing` set, a place after one passing `first_passing_gamma` may be
// skipped (it stays unverified). Neighbours (`exclude`) are found on this thread.
void VerifyPlaces(const Verification& v, const std::vector<int>& order, bool first_passing,
                  double first_passing_gamma, const PlaceExclusion& exclude,
                  VerifiedPlaces& verified) {
  std::vector<int> todo;
  for (int p : order) {
    if (!verified.Done(p)) todo.push_back(p);
  }
  const std::size_t first_slot = verified.results.size();
  verified.results.resize(first_slot + todo.size());
  std::vector<std::vector<int>> neighbours(todo.size());
  if (v.config.verification_neighbours > 0) {
    for (std::size_t k = 0; k < todo.size(); ++k) {
      neighbours[k] =
          VerificationNeighbours(v.places, todo[k], v.config.verification_neighbours, exclude);
    }
  }
  std::vector<char> computed(todo.size(), 0);
  std::atomic<std::size_t> first_passed{todo.size()};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, todo.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          if (first_passing && k > first_passed.load()) return;
          auto& result = verified.results[first_slot + k];
          result = VerifyCandidate(v, v.pairing.by_place[static_cast<std::size_t>(todo[k])],
                                   neighbours[k]);
          computed[k] = 1;
          if (!first_passing || !result || !PassesSecondCheck(*result, first_passing_gamma)) {
            continue;
          }
          std::size_t seen = first_passed.load();
          while (k < seen && !first_passed.compare_exchange_weak(seen, k)) {
          }
        }
      });
  for (std::size_t k = 0; k < todo.size(); ++k) {
    if (computed[k])
      verified.slot[static_cast<std::size_t>(todo[k])] = static_cast<int>(first_slot + k);
  }
}

// The verified candidates of one threshold, in candidate order, into match.verified_candidates
// and match.candidates_verified. kFirstVerified verifies in waves of as many candidates as there
// are threads (one at a time on one thread) and stops after the wave holding the first verified
// one: the answer, and candidates_verified (those up to the first verified), are the sequential
// loop's.
void GatherVerified(const Verification& v, const std::vector<int>& order, double min_gamma,
                    const PlaceExclusion& exclude, VerifiedPlaces& verified, PlaceMatch& match) {
  const bool first_verified =
      v.config.selection == PlaceRecognitionConfig::Selection::kFirstVerified;
  const std::size_t wave =
      first_verified ? AvailableThreads() : std::max<std::size_t>(order.size(), 1);
  bool done = false;
  for (std::size_t begin = 0; begin < order.size() && !done; begin += wave) {
    const std::size_t end = std::min(order.size(), begin + wave);
    const std::vector<int> slice(order.begin() + static_cast<std::ptrdiff_t>(begin),
                                 order.begin() + static_cast<std::ptrdiff_t>(end));
    VerifyPlaces(v, slice, first_verified, min_gamma, exclude, verified);
    for (std::size_t k = begin; k < end && !done; ++k) {
      ++match.candidates_verified;
      if (!verified.Passes(order[k], min_gamma)) continue;
      match.verified_candidates.push_back(*verified.Result(order[k]));
      done = first_verified;
    }
  }
}

// Two candidates name different robot poses (PlaceRecognitionConfig::distinct_*).
bool Distinct(const CandidateResult& a, const CandidateResult& b,
              const PlaceRecognitionConfig& config) {
  const Pose2 delta = Between(a.estimated_pose, b.estimated_pose);
  return TranslationNorm(delta) > config.distinct_distance_m ||
         std::abs(delta.theta) > config.distinct_angle_deg * M_PI / 180.0;
}

// The answer among match.verified_candidates: the best score, unless a distinct one comes close.
void ChooseAnswer(const std::vector<Place>& places, const PlaceRecognitionConfig& config,
                  PlaceMatch& match) {
  match.candidates_accepted = static_cast<int>(match.verified_candidates.size());
  if (match.verified_candidates.empty()) return;
  // The best score; ties keep the earlier candidate (smaller mean pair distance).
  const CandidateResult* best = &match.verified_candidates.front();
  for (const CandidateResult& candidate : match.verified_candidates) {
    if (candidate.score > best->score) best = &candidate;
  }
  double second = 0.0;
  for (const CandidateResult& candidate : match.verified_candidates) {
    if (Distinct(*best, candidate, config)) second = std::max(second, candidate.score);
  }
  match.verified = true;
  match.place_index = best->place_index;
  match.place_id = places[static_cast<std::size_t>(best->place_index)].id;
  match.T_ref_cur = best->T_ref_cur;
  match.estimated_pose = best->estimated_pose;
  match.estimated_pose_covariance = best->estimated_pose_covariance;
  match.pairs = best->pairs;
  match.consensus = best->consensus;
  match.gamma = best->gamma;
  match.reference_coverage = best->reference_coverage;
  match.dense_checked = best->dense_checked;
  match.dense = best->dense;
  match.score = best->score;
  match.second_score = second;
  const double consensus_factor =
      std::min(1.0, static_cast<double>(best->consensus) / config.confidence_consensus);
  const double gap = best->score > 0.0 ? std::max(0.0, 1.0 - second / best->score) : 0.0;
  match.confidence = consensus_factor * best->gamma * gap;
  match.ambiguous = second > 0.0 && second >= config.ambiguity_ratio * best->score;
  match.found = !match.ambiguous && match.confidence >= config.min_confidence;
}

// PlaceMatch::weak among the candidates of `order` that the sequential loop verifies
// (match.candidates_verified: with kFirstVerified, a wave may verify more, depending on the
// threads). Consensus, not the score, ranks them: their gamma is what may be missing.
void ChooseWeak(const std::vector<int>& order, const VerifiedPlaces& verified, double min_gamma,
                const PlaceRecognitionConfig& config, PlaceMatch& match) {
  std::vector<const CandidateResult*> supported;
  const auto counted = static_cast<std::size_t>(match.candidates_verified);
  for (std::size_t k = 0; k < std::min(order.size(), counted); ++k) {
    if (!verified.Done(order[k])) continue;
    const std::optional<CandidateResult>& result = verified.Result(order[k]);
    if (result && result->dense_supported) supported.push_back(&*result);
  }
  if (supported.empty()) return;
  const CandidateResult* best = supported.front();
  for (const CandidateResult* candidate : supported) {
    if (candidate->consensus > best->consensus) best = candidate;
  }
  int second = 0;
  for (const CandidateResult* candidate : supported) {
    if (Distinct(*best, *candidate, config)) second = std::max(second, candidate->consensus);
  }
  const double ratio = static_cast<double>(second) / static_cast<double>(best->consensus);
  if (second > 0 && ratio >= config.ambiguity_ratio) {
    match.weak_ambiguous = true;
    return;
  }
  match.weak = *best;
  match.weak->verified = PassesSecondCheck(*best, min_gamma);  // at this threshold's gamma_min
  const double consensus_factor =
      std::min(1.0, static_cast<double>(best->consensus) / config.confidence_consensus);
  match.weak_confidence = consensus_factor * best->gamma * (1.0 - ratio);
}

void CheckThresholds(const std::vector<RecognitionThresholds>& thresholds) {
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    const RecognitionThresholds& t = thresholds[k];
    const std::string where = "recognition thresholds " + std::to_string(k) + ": ";
    if (t.min_pairs < 2) throw std::invalid_argument(where + "min_pairs must be >= 2");
    for (double gamma : {t.min_gamma, t.min_gamma_all_scans}) {
      if (!(gamma >= 0.0 && gamma <= 1.0)) {
        throw std::invalid_argument(where + "min_gamma and min_gamma_all_scans must lie in [0, 1]");
      }
    }
  }
}

}  // namespace

PlaceMatch PlaceRecognizer::Recognize(const PlaceQuery& query,
                                      const PlaceExclusion& exclude) const {
  const RecognitionThresholds own{config_.min_pairs, config_.min_gamma,
                                  config_.min_gamma_all_scans};
  return RecognizeAtThresholds(query, {own}, exclude).front();
}

std::vector<PlaceMatch> PlaceRecognizer::RecognizeAtThresholds(
    const PlaceQuery& query, const std::vector<RecognitionThresholds>& thresholds,
    const PlaceExclusion& exclude) const {
  const auto start = Clock::now();
  if (query.positions.size() != query.descriptors.size()) {
    throw std::invalid_argument("PlaceQuery: positions and descriptors differ in size");
  }
  if (query.all_positions.size() != query.all_descriptors.size()) {
    throw std::invalid_argument("PlaceQuery: all_positions and all_descriptors differ in size");
  }
  CheckThresholds(thresholds);
  if (query.by_words && !words_) {
    throw std::invalid_argument(
        "PlaceQuery.by_words: this recognizer learned no words "
        "(PlaceRecognizer::LearnWords::kAlways)");
  }
  // Retrieval by the words for every query (kWords) or for those that ask (kAuto, kExact).
  const bool by_words =
      config_.retrieval == PlaceRecognitionConfig::Retrieval::kWords || query.by_words;
  std::vector<PlaceMatch> matches(thresholds.size());
  if (thresholds.empty()) return matches;
  const MatchKeypoints keypoints = QueryMatchKeypoints(query, config_);
  const auto gamma_of = [&keypoints](const RecognitionThresholds& t) {
    return keypoints.all_scans ? t.min_gamma_all_scans : t.min_gamma;
  };
  const auto lowest = [&](auto value) {
    auto low = value(thresholds.front());
    for (const RecognitionThresholds& t : thresholds) low = std::min(low, value(t));
    return low;
  };
  const auto lowest_pairs =
      static_cast<std::size_t>(lowest([](const RecognitionThresholds& t) { return t.min_pairs; }));

  // Algorithm 3 once, for the smallest mu; each threshold's candidates are among its places.
  Pairing pairing;
  if (keypoints.positions.size() >= lowest_pairs) {
    pairing = PairWithPlaces(places_, index_.get(), slots_, config_, keypoints.descriptors,
                             query.also_search_ids, lowest_pairs, exclude,
                             by_words ? words_.get() : nullptr, query.pair_memo);
  }
  std::vector<int> rigid_star(places_.size(), -1);
  std::vector<std::vector<int>> orders(thresholds.size());
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    if (pairing.by_place.empty()) continue;
    orders[k] = CandidatesInOrder(pairing, places_, config_,
                                  static_cast<std::size_t>(thresholds[k].min_pairs),
                                  keypoints.positions, rigid_star, matches[k]);
  }
  const double seconds_pairing = SecondsSince(start);

  // Geometric verification, each candidate at most once for all thresholds.
  const auto verify_start = Clock::now();
  const double min_coverage = keypoints.all_scans ? config_.min_reference_coverage : 0.0;
  const Verification verification{
      places_, config_, query, pairing, keypoints.positions, lowest(gamma_of), min_coverage};
  VerifiedPlaces verified(places_.size());
  if (config_.selection != PlaceRecognitionConfig::Selection::kFirstVerified) {
    // Every threshold's candidates (each place once), verified in one parallel pass.
    std::vector<char> listed(orders.size() > 1 ? places_.size() : 0, 0);
    std::vector<int> all = orders.front();
    for (std::size_t k = 1; k < orders.size(); ++k) {
      if (k == 1) {
        for (int p : all) listed[static_cast<std::size_t>(p)] = 1;
      }
      for (int p : orders[k]) {
        if (listed[static_cast<std::size_t>(p)]) continue;
        listed[static_cast<std::size_t>(p)] = 1;
        all.push_back(p);
      }
    }
    VerifyPlaces(verification, all, false, 0.0, exclude, verified);
  }
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    GatherVerified(verification, orders[k], gamma_of(thresholds[k]), exclude, verified, matches[k]);
    ChooseAnswer(places_, config_, matches[k]);
    ChooseWeak(orders[k], verified, gamma_of(thresholds[k]), config_, matches[k]);
  }
  const double seconds_verification = SecondsSince(verify_start);
  const double seconds = SecondsSince(start);
  for (PlaceMatch& match : matches) {
    match.descriptors_remembered = pairing.descriptors_remembered;
    match.seconds_pairing = seconds_pairing;
    match.seconds_verification = seconds_verification;
    match.seconds = seconds;
  }
  return matches;
}

}  // namespace keyplace
