#include "keyplace/place/place_recognizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "place/descriptor_index.hpp"
#include "place/place_words.hpp"
#include "place/unique_pairs.hpp"

namespace keyplace {
namespace {

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
  const PointMapper ref_from_cur(T_ref_cur);
  for (const auto& p : current_positions) {
    result.current_in_ref.push_back(ref_from_cur(p));
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

}  // namespace

std::vector<int> PlaceIdsNear(const std::vector<Place>& places, std::size_t candidates,
                              const Eigen::Vector2d& position_m, double radius_m,
                              std::size_t count) {
  std::vector<std::pair<double, std::size_t>> near;  // (distance, index)
  candidates = std::min(candidates, places.size());
  for (std::size_t p = 0; p < candidates; ++p) {
    const double distance_m = (places[p].T_world_place.translation() - position_m).norm();
    if (distance_m <= radius_m) near.emplace_back(distance_m, p);
  }
  const std::size_t kept = std::min(count, near.size());
  std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(kept), near.end());
  std::vector<int> ids;
  ids.reserve(kept);
  for (std::size_t k = 0; k < kept; ++k) ids.push_back(places[near[k].second].id);
  return ids;
}

std::vector<int> PlaceIdsToAlsoSearch(const PlaceRecognitionConfig& config, bool by_words,
                                      const std::vector<Place>& places, std::size_t candidates,
                                      const Eigen::Vector2d& position_m, double radius_m) {
  const bool retrieves = by_words || config.retrieval == PlaceRecognitionConfig::Retrieval::kWords;
  if (!retrieves || !(radius_m > 0.0)) return {};
  return PlaceIdsNear(places, candidates, position_m, radius_m,
                      static_cast<std::size_t>(config.retrieval_places));
}

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
    place.occupancy_cells = submap.occupancy.cells;
    place.occupancy_cell_m = submap.occupancy.cell_size_m;
    places.push_back(std::move(place));
  }
  return places;
}

namespace {

// Algorithm 3's global greedy: the pairs by distance (equal ones in their given order, by
// current then reference keypoint), each taken when neither keypoint is used yet. Instead of
// sorting every pair (a tenth of a FR079 query's time), the nearest `chunk` pairs are split off
// (nth_element), sorted and taken; the pairs left that hold a used keypoint can never be taken
// and are dropped before the next chunk. The pairs taken, and their order, are the same.
std::vector<DescriptorPair> GreedyUniquePairs(std::vector<DescriptorPair> below,
                                              std::size_t n_current, std::size_t n_reference) {
  const auto nearer = [](const DescriptorPair& a, const DescriptorPair& b) {
    if (a.distance != b.distance) return a.distance < b.distance;
    return a.current != b.current ? a.current < b.current : a.reference < b.reference;
  };
  std::vector<char> current_used(n_current, 0);
  std::vector<char> reference_used(n_reference, 0);
  std::vector<DescriptorPair> pairs;
  using Iterator = std::vector<DescriptorPair>::iterator;
  const auto take_sorted = [&](Iterator first, Iterator last) {
    std::size_t taken = 0;
    for (auto it = first; it != last; ++it) {
      if (current_used[it->current] || reference_used[it->reference]) continue;
      current_used[it->current] = 1;
      reference_used[it->reference] = 1;
      pairs.push_back(*it);
      ++taken;
    }
    return taken;
  };
  // At most min(n_current, n_reference) pairs are taken; twice that is a chunk that usually
  // leaves few pairs open.
  const std::size_t chunk = std::max<std::size_t>(64, 2 * std::min(n_current, n_reference));
  auto begin = below.begin();
  auto end = below.end();
  while (static_cast<std::size_t>(end - begin) > chunk) {
    const auto split = begin + static_cast<std::ptrdiff_t>(chunk);
    std::nth_element(begin, split, end, nearer);
    std::sort(begin, split, nearer);
    const std::size_t taken = take_sorted(begin, split);
    end = std::remove_if(split, end, [&](const DescriptorPair& pair) {
      return current_used[pair.current] || reference_used[pair.reference];
    });
    begin = split;
    // A chunk that takes few pairs (the nearest pairs crowding on a few keypoints) would make
    // as many passes over the rest as pairs taken: the rest is then sorted once instead.
    if (taken * 8 < chunk) break;
  }
  std::sort(begin, end, nearer);
  take_sorted(begin, end);
  return pairs;
}

}  // namespace

std::vector<DescriptorPair> UniquePairs(std::vector<DescriptorPair> below, std::size_t n_current,
                                        std::size_t n_reference,
                                        PlaceRecognitionConfig::PairMatching mode) {
  if (mode == PlaceRecognitionConfig::PairMatching::kGlobalGreedy) {
    return GreedyUniquePairs(std::move(below), n_current, n_reference);
  }
  // kQueryOrder: `below` is ordered by current keypoint; each takes its nearest unused reference.
  std::vector<char> reference_used(n_reference, 0);
  std::vector<DescriptorPair> pairs;
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

std::vector<DescriptorPair> MatchDescriptorPairs(const std::vector<BetaGridDescriptor>& current,
                                                 const std::vector<BetaGridDescriptor>& reference,
                                                 double chi2_threshold,
                                                 PlaceRecognitionConfig::PairMatching mode) {
  // Every pair below the threshold, with its distance.
  std::vector<DescriptorPair> below;
  for (std::size_t c = 0; c < current.size(); ++c) {
    for (std::size_t r = 0; r < reference.size(); ++r) {
      const double distance = SymmetricChi2IfBelow(current[c], reference[r], chi2_threshold);
      if (distance < chi2_threshold) {
        below.push_back({static_cast<int>(c), static_cast<int>(r), distance});
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

PlaceRecognizer::PlaceRecognizer(std::vector<Place> places, const PlaceRecognitionConfig& config,
                                 LearnWords learn_words)
    : places_(std::move(places)),
      config_(config),
      learns_words_(learn_words == LearnWords::kAlways ||
                    config.retrieval == PlaceRecognitionConfig::Retrieval::kWords) {
  Validate(config_);
  for (const Place& place : places_) {
    if (place.positions.size() != place.descriptors.size()) {
      throw std::invalid_argument("Place " + std::to_string(place.id) +
                                  ": positions and descriptors differ in size");
    }
  }
  RebuildIndex();
  RebuildWords();
}

PlaceRecognizer::~PlaceRecognizer() = default;

void PlaceRecognizer::RebuildWords() {
  if (learns_words_) {
    words_ = std::make_shared<PlaceWords>(places_);  // built first: a throw keeps the old
  }
}

void PlaceRecognizer::AddWordsOfLastPlace() {
  if (!words_) return;  // no words learned
  std::size_t keypoints = 0;
  for (const Place& place : places_) keypoints += place.descriptors.size();
  // Learning anew once the map holds twice the keypoints the vocabulary was learned from costs
  // at most twice the last learning over all the places added (a growing SLAM map learns about
  // log2(places) times), and keeps about one word per 8 to 16 map keypoints.
  if (keypoints >= 2 * words_->learned_keypoints()) {
    RebuildWords();
    return;
  }
  if (words_.use_count() > 1) words_ = std::make_shared<PlaceWords>(*words_);  // a copy shares it
  words_->Append(places_.back());
}

void PlaceRecognizer::RebuildIndex() {
  index_.reset();
  slots_.clear();
  removed_keypoints_ = 0;
  if (config_.descriptor_index == PlaceRecognitionConfig::DescriptorIndex::kNone) return;
  // Retrieval indexes the places it retrieves for each query instead (recognition.cpp).
  if (config_.retrieval == PlaceRecognitionConfig::Retrieval::kWords) return;
  index_ = std::make_shared<SqrtDescriptorIndex>(places_, config_.descriptor_index);
  for (std::size_t p = 0; p < places_.size(); ++p) slots_.push_back(p);
}

void PlaceRecognizer::AddPlace(Place place) {
  if (place.positions.size() != place.descriptors.size()) {
    throw std::invalid_argument("Place " + std::to_string(place.id) +
                                ": positions and descriptors differ in size");
  }
  places_.push_back(std::move(place));
  try {
    AddWordsOfLastPlace();
  } catch (...) {  // out of memory: the place is not added, the words describe places_ again
    places_.pop_back();
    RebuildWords();
    throw;
  }
  if (!index_) return;  // descriptor_index none, or retrieval words
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
  RebuildWords();
  if (!index_) return true;  // descriptor_index none, or retrieval words
  slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(p));
  // The removed keypoints stay indexed (never searched: Recognize searches the slots of places_)
  // until they are the majority, so rebuilding costs O(1) amortised per removed keypoint.
  if (index_.use_count() > 1 || 2 * removed_keypoints_ > index_->keypoints()) RebuildIndex();
  return true;
}

void PlaceRecognizer::SetPlacePose(std::size_t place_index, const Pose2& T_world_place) {
  places_.at(place_index).T_world_place = T_world_place;
}

}  // namespace keyplace
