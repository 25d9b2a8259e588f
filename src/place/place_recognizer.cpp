#include "keyplace/place/place_recognizer.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "keyplace/place/ransac.hpp"
#include "place/candidate_ranking.hpp"
#include "place/descriptor_index.hpp"

namespace keyplace {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Box {
  Eigen::Vector2d min{std::numeric_limits<double>::infinity(),
                      std::numeric_limits<double>::infinity()};
  Eigen::Vector2d max{-std::numeric_limits<double>::infinity(),
                      -std::numeric_limits<double>::infinity()};
  void Add(const Eigen::Vector2d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  bool Contains(const Eigen::Vector2d& p) const {
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
};

// The current keypoints mapped into the reference frame, and the overlap area of Eq. (10): the
// intersection of both keypoint bounding boxes (empty: nullopt).
struct MappedOverlap {
  std::vector<Eigen::Vector2d> current_in_ref;
  std::optional<Box> overlap;
};
MappedOverlap MapAndOverlap(const std::vector<Eigen::Vector2d>& reference_positions,
                            const std::vector<Eigen::Vector2d>& current_positions,
                            const Pose2& T_ref_cur) {
  MappedOverlap result;
  result.current_in_ref.reserve(current_positions.size());
  Box reference_box;
  Box current_box;
  for (const auto& p : reference_positions) reference_box.Add(p);
  for (const auto& p : current_positions) {
    result.current_in_ref.push_back(T_ref_cur * p);
    current_box.Add(result.current_in_ref.back());
  }
  Box overlap;
  overlap.min = reference_box.min.cwiseMax(current_box.min);
  overlap.max = reference_box.max.cwiseMin(current_box.max);
  if (overlap.min.x() <= overlap.max.x() && overlap.min.y() <= overlap.max.y()) {
    result.overlap = overlap;
  }
  return result;
}

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

}  // namespace

std::vector<Place> PlacesFromMap(const GlobalMap& map) {
  std::vector<Place> places;
  places.reserve(map.submaps.size());
  for (const Submap& submap : map.submaps) {
    Place place;
    place.id = submap.id;
    place.T_world_place = submap.poses.empty() ? Pose2{} : submap.origin();
    for (const StableKeypoint& keypoint : submap.keypoints) {
      place.positions.push_back(keypoint.position_m);
      place.descriptors.push_back(keypoint.descriptor);
    }
    place.scan_indices = submap.scan_indices;
    places.push_back(std::move(place));
  }
  return places;
}

namespace {

// The unique pairs (Algorithm 3's FindUniqueMatch) among `below`: every pair below the threshold
// with its distance, ordered by current index, then reference index.
std::vector<DescriptorPair> UniquePairs(std::vector<DescriptorPair> below, std::size_t n_current,
                                        std::size_t n_reference,
                                        PlaceRecognitionConfig::PairMatching mode) {
  if (mode == PlaceRecognitionConfig::PairMatching::kGlobalGreedy) {
    std::stable_sort(
        below.begin(), below.end(),
        [](const DescriptorPair& a, const DescriptorPair& b) { return a.distance < b.distance; });
  }
  // kQueryOrder: `below` is ordered by current keypoint; each takes its nearest unused reference.
  std::vector<char> current_used(n_current, 0);
  std::vector<char> reference_used(n_reference, 0);
  std::vector<DescriptorPair> pairs;
  if (mode == PlaceRecognitionConfig::PairMatching::kGlobalGreedy) {
    for (const DescriptorPair& pair : below) {
      if (current_used[pair.current] || reference_used[pair.reference]) continue;
      current_used[pair.current] = 1;
      reference_used[pair.reference] = 1;
      pairs.push_back(pair);
    }
    return pairs;
  }
  std::size_t begin = 0;
  while (begin < below.size()) {
    std::size_t end = begin;
    const DescriptorPair* best = nullptr;
    while (end < below.size() && below[end].current == below[begin].current) {
      const DescriptorPair& pair = below[end];
      if (!reference_used[pair.reference] && (!best || pair.distance < best->distance)) {
        best = &pair;
      }
      ++end;
    }
    if (best) {
      reference_used[best->reference] = 1;
      pairs.push_back(*best);
    }
    begin = end;
  }
  return pairs;
}

}  // namespace

std::vector<DescriptorPair> MatchDescriptorPairs(const std::vector<BetaGridDescriptor>& current,
                                                 const std::vector<BetaGridDescriptor>& reference,
                                                 double chi2_threshold,
                                                 PlaceRecognitionConfig::PairMatching mode) {
  // Every pair below the threshold, with its distance.
  std::vector<DescriptorPair> below;
  for (std::size_t c = 0; c < current.size(); ++c) {
    for (std::size_t r = 0; r < reference.size(); ++r) {
      if (SymmetricChi2Below(current[c], reference[r], chi2_threshold)) {
        below.push_back(
            {static_cast<int>(c), static_cast<int>(r), SymmetricChi2(current[c], reference[r])});
      }
    }
  }
  return UniquePairs(std::move(below), current.size(), reference.size(), mode);
}

GammaResult ComputeGamma(const std::vector<Eigen::Vector2d>& reference_positions,
                         const std::vector<BetaGridDescriptor>& reference_descriptors,
                         const std::vector<Eigen::Vector2d>& current_positions,
                         const std::vector<BetaGridDescriptor>& current_descriptors,
                         const Pose2& T_ref_cur, double lambda_m, double chi2_threshold,
                         PlaceRecognitionConfig::GammaCounting counting) {
  GammaResult result;
  const auto [current_in_ref, maybe_overlap] =
      MapAndOverlap(reference_positions, current_positions, T_ref_cur);
  if (!maybe_overlap) return result;
  const Box& overlap = *maybe_overlap;

  std::vector<int> reference_inside;
  std::vector<int> current_inside;
  for (std::size_t r = 0; r < reference_positions.size(); ++r) {
    if (overlap.Contains(reference_positions[r])) reference_inside.push_back(static_cast<int>(r));
  }
  for (std::size_t c = 0; c < current_in_ref.size(); ++c) {
    if (overlap.Contains(current_in_ref[c])) current_inside.push_back(static_cast<int>(c));
  }
  result.reference_in_overlap = static_cast<int>(reference_inside.size());
  result.current_in_overlap = static_cast<int>(current_inside.size());
  const int total = result.reference_in_overlap + result.current_in_overlap;
  if (total == 0) return result;

  // Doubly matched: within lambda and descriptors within the chi2 threshold.
  const double lambda2 = lambda_m * lambda_m;
  std::vector<std::tuple<double, int, int>> doubles;  // (distance^2, current, reference)
  for (int c : current_inside) {
    for (int r : reference_inside) {
      const double d2 = (current_in_ref[c] - reference_positions[r]).squaredNorm();
      if (d2 <= lambda2 &&
          SymmetricChi2Below(current_descriptors[c], reference_descriptors[r], chi2_threshold)) {
        doubles.emplace_back(d2, c, r);
      }
    }
  }
  if (counting == PlaceRecognitionConfig::GammaCounting::kUniquePairs) {
    std::sort(doubles.begin(), doubles.end());
    std::vector<char> current_used(current_positions.size(), 0);
    std::vector<char> reference_used(reference_positions.size(), 0);
    int matched = 0;
    for (const auto& [d2, c, r] : doubles) {
      if (current_used[c] || reference_used[r]) continue;
      current_used[c] = 1;
      reference_used[r] = 1;
      ++matched;
    }
    result.double_matched = matched;
  } else {
    std::vector<char> current_hit(current_positions.size(), 0);
    std::vector<char> reference_hit(reference_positions.size(), 0);
    for (const auto& [d2, c, r] : doubles) {
      current_hit[c] = 1;
      reference_hit[r] = 1;
    }
    int hits = 0;
    for (char h : current_hit) hits += h;
    for (char h : reference_hit) hits += h;
    result.double_matched = 0.5 * hits;
  }
  result.gamma = 2.0 * result.double_matched / static_cast<double>(total);
  return result;
}

double ReferenceCoverage(const std::vector<Eigen::Vector2d>& reference_positions,
                         const std::vector<Eigen::Vector2d>& current_positions,
                         const Pose2& T_ref_cur, double radius_m) {
  const auto [current_in_ref, maybe_overlap] =
      MapAndOverlap(reference_positions, current_positions, T_ref_cur);
  if (!maybe_overlap) return 0.0;
  const Box& overlap = *maybe_overlap;
  const double radius2 = radius_m * radius_m;
  int inside = 0;
  int hit = 0;
  for (const auto& r : reference_positions) {
    if (!overlap.Contains(r)) continue;
    ++inside;
    for (const auto& c : current_in_ref) {
      if ((c - r).squaredNorm() <= radius2) {
        ++hit;
        break;
      }
    }
  }
  return inside > 0 ? static_cast<double>(hit) / inside : 0.0;
}

std::vector<int> MergeNearbyKeypoints(const std::vector<Eigen::Vector2d>& positions,
                                      double radius_m) {
  std::vector<int> kept;
  const double radius2 = radius_m * radius_m;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    bool near = false;
    if (radius_m > 0.0) {
      for (int k : kept) {
        if ((positions[k] - positions[i]).squaredNorm() < radius2) {
          near = true;
          break;
        }
      }
    }
    if (!near) kept.push_back(static_cast<int>(i));
  }
  return kept;
}

int CountConsensus(const std::vector<std::pair<int, int>>& inliers,
                   PlaceRecognitionConfig::ConsensusCounting counting) {
  if (counting == PlaceRecognitionConfig::ConsensusCounting::kQueryKeypoints) {
    return static_cast<int>(inliers.size());
  }
  std::vector<int> references;
  references.reserve(inliers.size());
  for (const auto& inlier : inliers) references.push_back(inlier.second);
  std::sort(references.begin(), references.end());
  return static_cast<int>(std::unique(references.begin(), references.end()) - references.begin());
}

PlaceRecognizer::PlaceRecognizer(std::vector<Place> places, const PlaceRecognitionConfig& config)
    : places_(std::move(places)), config_(config) {
  Validate(config_);
  for (const Place& place : places_) {
    if (place.positions.size() != place.descriptors.size()) {
      throw std::invalid_argument("Place " + std::to_string(place.id) +
                                  ": positions and descriptors differ in size");
    }
  }
  RebuildIndex();
}

PlaceRecognizer::~PlaceRecognizer() = default;

void PlaceRecognizer::RebuildIndex() {
  index_.reset();
  slots_.clear();
  removed_keypoints_ = 0;
  if (config_.descriptor_index == PlaceRecognitionConfig::DescriptorIndex::kNone) return;
  index_ = std::make_shared<SqrtDescriptorIndex>(places_, config_.descriptor_index);
  for (std::size_t p = 0; p < places_.size(); ++p) slots_.push_back(p);
}

void PlaceRecognizer::AddPlace(Place place) {
  if (place.positions.size() != place.descriptors.size()) {
    throw std::invalid_argument("Place " + std::to_string(place.id) +
                                ": positions and descriptors differ in size");
  }
  places_.push_back(std::move(place));
  if (!index_) return;  // kNone
  if (index_.use_count() > 1) {
    RebuildIndex();  // a copy shares the index: never change it under the copy
    return;
  }
  slots_.push_back(index_->AddPlace(places_.back().descriptors));
}

bool PlaceRecognizer::RemovePlace(int place_id) {
  const auto it = std::find_if(places_.begin(), places_.end(),
                               [place_id](const Place& place) { return place.id == place_id; });
  if (it == places_.end()) return false;
  const auto p = static_cast<std::size_t>(it - places_.begin());
  removed_keypoints_ += it->descriptors.size();
  places_.erase(it);
  if (!index_) return true;  // kNone
  slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(p));
  // The removed keypoints stay indexed (never searched: Recognize searches the slots of places_)
  // until they are the majority, so rebuilding costs O(1) amortised per removed keypoint.
  if (index_.use_count() > 1 || 2 * removed_keypoints_ > index_->keypoints()) RebuildIndex();
  return true;
}

void PlaceRecognizer::SetPlacePose(std::size_t place_index, const Pose2& T_world_place) {
  places_.at(place_index).T_world_place = T_world_place;
}

namespace {

// A place with >= mu unique pairs (Algorithm 3), verified in the order of the candidate list.
struct Candidate {
  int place_index = -1;  // -1: not a candidate
  double mean_distance = 0.0;
  std::vector<DescriptorPair> pairs;
};

// Grain sizes of the parallel loops of Recognize (TBB): places of the unique pairs per task
// (microseconds each with an index), candidates of LargestRigidStar per task (O(pairs^2) each).
// Candidates are verified in parallel (a RANSAC each, grain 1).
constexpr std::size_t kPlacesPerTask = 16;
constexpr std::size_t kRankedCandidatesPerTask = 4;

// What the verification of every candidate of one query reads.
struct Verification {
  const std::vector<Place>& places;
  const PlaceRecognitionConfig& config;
  const PlaceQuery& query;
  const std::vector<Eigen::Vector2d>& match_positions;  // the query keypoints paired
  double min_gamma;
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

// RANSAC and the three checks of one candidate (the place's own seed: the answer does not depend
// on which other candidates are verified, nor in which order). nullopt: not verified.
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
  const GammaResult gamma =
      ComputeGamma(*reference_positions, *reference_descriptors, v.query.positions,
                   v.query.descriptors, estimate.T_ref_cur, config.double_match_m,
                   config.descriptor_match_chi2, config.gamma_counting);
  if (gamma.gamma < v.min_gamma) return std::nullopt;  // second check
  const double coverage = ReferenceCoverage(*reference_positions, v.match_positions,
                                            estimate.T_ref_cur, config.ransac.inlier_distance_m);
  if (coverage < v.min_coverage) return std::nullopt;  // third check (ours)
  CandidateResult result;
  result.place_index = candidate.place_index;
  result.pairs = static_cast<int>(candidate.pairs.size());
  result.mean_pair_distance = candidate.mean_distance;
  result.consensus = consensus;
  result.gamma = gamma.gamma;
  result.reference_coverage = coverage;
  result.verified = true;
  result.T_ref_cur = estimate.T_ref_cur;
  result.estimated_pose = place.T_world_place * estimate.T_ref_cur * v.query.T_first_evaluated;
  result.estimated_pose_covariance = ComposedCovariance(
      place.T_world_place, estimate.T_ref_cur, v.query.T_first_evaluated,
      RigidFitCovariance(*reference_positions, v.match_positions, estimate.inliers,
                         estimate.T_ref_cur, config.ransac.min_fit_sigma_m));
  result.score = SelectionScore(config.score, consensus, gamma.gamma);
  return result;
}

// The threads a parallel loop started here may use (the arena's, within the global control).
std::size_t AvailableThreads() {
  const auto arena = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  const std::size_t allowed =
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return std::max<std::size_t>(1, std::min(arena, allowed));
}

// Geometric verification of the first `to_verify` candidates, in parallel, each into its own
// slot, gathered in candidate order into match.verified_candidates and
// match.candidates_verified. kFirstVerified verifies them in waves of as many as there are
// threads (one at a time on one thread) and stops after the wave holding the first verified
// one; within a wave, candidates after a verified one are skipped. The answer, and
// candidates_verified (those up to the first verified), are the sequential loop's. `exclude` is
// called on this thread only.
void VerifyCandidates(const Verification& v, const std::vector<Candidate>& candidates,
                      std::size_t to_verify, const PlaceExclusion& exclude, PlaceMatch& match) {
  const bool first_verified =
      v.config.selection == PlaceRecognitionConfig::Selection::kFirstVerified;
  const std::size_t wave =
      first_verified ? AvailableThreads() : std::max<std::size_t>(to_verify, 1);
  bool done = false;
  for (std::size_t begin = 0; begin < to_verify && !done; begin += wave) {
    const std::size_t end = std::min(to_verify, begin + wave);
    std::vector<std::vector<int>> neighbours(end - begin);
    if (v.config.verification_neighbours > 0) {
      for (std::size_t k = begin; k < end; ++k) {
        neighbours[k - begin] = VerificationNeighbours(v.places, candidates[k].place_index,
                                                       v.config.verification_neighbours, exclude);
      }
    }
    std::vector<std::optional<CandidateResult>> results(end - begin);
    std::atomic<std::size_t> first_verified_in_wave{end};
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(begin, end, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t k = range.begin(); k != range.end(); ++k) {
            if (first_verified && k > first_verified_in_wave.load()) return;
            results[k - begin] = VerifyCandidate(v, candidates[k], neighbours[k - begin]);
            if (!first_verified || !results[k - begin]) continue;
            std::size_t seen = first_verified_in_wave.load();
            while (k < seen && !first_verified_in_wave.compare_exchange_weak(seen, k)) {
            }
          }
        });
    for (std::size_t k = begin; k < end && !done; ++k) {
      ++match.candidates_verified;
      if (!results[k - begin]) continue;
      match.verified_candidates.push_back(std::move(*results[k - begin]));
      done = first_verified;
    }
  }
}

}  // namespace

PlaceMatch PlaceRecognizer::Recognize(const PlaceQuery& query,
                                      const PlaceExclusion& exclude) const {
  const auto start = Clock::now();
  PlaceMatch match;
  if (query.positions.size() != query.descriptors.size()) {
    throw std::invalid_argument("PlaceQuery: positions and descriptors differ in size");
  }
  const std::size_t min_pairs = static_cast<std::size_t>(config_.min_pairs);
  if (query.all_positions.size() != query.all_descriptors.size()) {
    throw std::invalid_argument("PlaceQuery: all_positions and all_descriptors differ in size");
  }
  // The query keypoints paired and verified by RANSAC (the gamma check uses the stable ones).
  std::vector<Eigen::Vector2d> merged_positions;
  std::vector<BetaGridDescriptor> merged_descriptors;
  const std::vector<Eigen::Vector2d>* match_positions = &query.positions;
  const std::vector<BetaGridDescriptor>* match_descriptors = &query.descriptors;
  if (config_.query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans &&
      !query.all_positions.empty()) {
    for (int k : MergeNearbyKeypoints(query.all_positions, config_.query_merge_m)) {
      merged_positions.push_back(query.all_positions[k]);
      merged_descriptors.push_back(query.all_descriptors[k]);
    }
    match_positions = &merged_positions;
    match_descriptors = &merged_descriptors;
  }

  const bool all_scan_query = match_positions != &query.positions;
  const double min_gamma = all_scan_query ? config_.min_gamma_all_scans : config_.min_gamma;
  const double min_coverage = all_scan_query ? config_.min_reference_coverage : 0.0;

  // Algorithm 3 against every place: candidates with >= mu unique pairs. The places, their
  // blocks in the index and the candidates are worked on in parallel (TBB), each into its own
  // slot, and gathered in place order: the same answer at any number of threads. `exclude` is
  // called on this thread only.
  std::vector<Candidate> candidates;
  if (match_positions->size() >= min_pairs) {
    std::vector<char> searched(places_.size(), 0);
    for (std::size_t p = 0; p < places_.size(); ++p) {
      const Place& place = places_[p];
      if (place.positions.size() < min_pairs) continue;  // can never reach mu pairs
      if (exclude && exclude(place)) {
        ++match.places_excluded;
        continue;
      }
      searched[p] = 1;
    }
    // The index finds, per place, the pairs below the threshold that the exhaustive loop of
    // MatchDescriptorPairs finds, in its order and with its distances.
    std::vector<std::vector<DescriptorPair>> below;  // by index slot
    if (index_) {
      std::vector<char> searched_slots(index_->places(), 0);
      for (std::size_t p = 0; p < places_.size(); ++p) searched_slots[slots_[p]] = searched[p];
      index_->FindPairs(*match_descriptors, config_.descriptor_match_chi2, searched_slots, below);
    }
    std::vector<Candidate> by_place(places_.size());
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, places_.size(), kPlacesPerTask),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t p = range.begin(); p != range.end(); ++p) {
            if (!searched[p]) continue;
            const Place& place = places_[p];
            std::vector<DescriptorPair> pairs =
                index_ ? UniquePairs(std::move(below[slots_[p]]), match_descriptors->size(),
                                     place.descriptors.size(), config_.pair_matching)
                       : MatchDescriptorPairs(*match_descriptors, place.descriptors,
                                              config_.descriptor_match_chi2, config_.pair_matching);
            if (pairs.size() < min_pairs) continue;
            double sum = 0.0;
            for (const DescriptorPair& pair : pairs) sum += pair.distance;
            by_place[p] = {static_cast<int>(p), sum / static_cast<double>(pairs.size()),
                           std::move(pairs)};
          }
        });
    for (Candidate& candidate : by_place) {
      if (candidate.place_index >= 0) candidates.push_back(std::move(candidate));
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const Candidate& a, const Candidate& b) { return a.mean_distance < b.mean_distance; });
  match.candidates = static_cast<int>(candidates.size());
  const auto max_candidates = static_cast<std::size_t>(config_.max_candidates);
  if (candidates.size() > max_candidates &&
      config_.candidate_ranking == PlaceRecognitionConfig::CandidateRanking::kRigidPairs) {
    std::vector<int> rigid_star(candidates.size(), 0);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, candidates.size(), kRankedCandidatesPerTask),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const Candidate& candidate = candidates[k];
            rigid_star[k] =
                LargestRigidStar(candidate.pairs, *match_positions,
                                 places_[static_cast<std::size_t>(candidate.place_index)].positions,
                                 config_.ransac.rigidity_m2);
          }
        });
    std::vector<Candidate> kept;
    kept.reserve(max_candidates);
    for (std::size_t k : KeepMostRigid(rigid_star, max_candidates)) {
      kept.push_back(std::move(candidates[k]));
    }
    candidates = std::move(kept);
  }
  match.seconds_pairing = SecondsSince(start);

  // Geometric verification of the first n_c candidates (VerifyCandidates: in parallel, the
  // sequential loop's answer).
  const auto verify_start = Clock::now();
  const std::size_t to_verify = std::min(candidates.size(), max_candidates);
  const Verification verification{places_,          config_,   query,
                                  *match_positions, min_gamma, min_coverage};
  VerifyCandidates(verification, candidates, to_verify, exclude, match);
  match.candidates_accepted = static_cast<int>(match.verified_candidates.size());
  match.seconds_verification = SecondsSince(verify_start);

  if (!match.verified_candidates.empty()) {
    // The best score; ties keep the earlier candidate (smaller mean pair distance).
    const CandidateResult* best = &match.verified_candidates.front();
    for (const CandidateResult& candidate : match.verified_candidates) {
      if (candidate.score > best->score) best = &candidate;
    }
    const double distinct_angle = config_.distinct_angle_deg * M_PI / 180.0;
    double second = 0.0;
    for (const CandidateResult& candidate : match.verified_candidates) {
      const Pose2 delta = Between(best->estimated_pose, candidate.estimated_pose);
      const bool distinct = TranslationNorm(delta) > config_.distinct_distance_m ||
                            std::abs(delta.theta) > distinct_angle;
      if (distinct) second = std::max(second, candidate.score);
    }
    match.verified = true;
    match.place_index = best->place_index;
    match.place_id = places_[best->place_index].id;
    match.T_ref_cur = best->T_ref_cur;
    match.estimated_pose = best->estimated_pose;
    match.estimated_pose_covariance = best->estimated_pose_covariance;
    match.pairs = best->pairs;
    match.consensus = best->consensus;
    match.gamma = best->gamma;
    match.reference_coverage = best->reference_coverage;
    match.score = best->score;
    match.second_score = second;
    const double consensus_factor =
        std::min(1.0, static_cast<double>(best->consensus) / config_.confidence_consensus);
    const double gap = best->score > 0.0 ? std::max(0.0, 1.0 - second / best->score) : 0.0;
    match.confidence = consensus_factor * best->gamma * gap;
    match.ambiguous = second > 0.0 && second >= config_.ambiguity_ratio * best->score;
    match.found = !match.ambiguous && match.confidence >= config_.min_confidence;
  }
  match.seconds = SecondsSince(start);
  return match;
}

}  // namespace keyplace
