#pragma once
// The exact descriptor index of place recognition: every place keypoint whose descriptor has a
// symmetric chi2 below a threshold to a query descriptor, found through a bound in the space of
// square-root descriptors (descriptor_index.cpp proves it) and checked by the exact chi2. It
// finds the pairs exhaustive matching finds, with the same distances, in the same order.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

class SqrtDescriptorIndex {
 public:
  /// Indexes the descriptors of `places` (copied; the places may change afterwards) as places
  /// 0..n-1, in one tree for kKdTree. `kind` is kKdTree or kDense (kNone throws
  /// std::invalid_argument: no index).
  SqrtDescriptorIndex(const std::vector<Place>& places,
                      PlaceRecognitionConfig::DescriptorIndex kind);
  ~SqrtDescriptorIndex();
  SqrtDescriptorIndex(const SqrtDescriptorIndex&) = delete;
  SqrtDescriptorIndex& operator=(const SqrtDescriptorIndex&) = delete;

  /// Appends one place's descriptors (copied) as place number places() and returns that number;
  /// the places already indexed keep theirs. No rebuild of the whole index: kDense appends rows;
  /// kKdTree gives the new keypoints a tree of their own and merges it with the trees before it
  /// while the earlier one is at most twice its size (the logarithmic method: at most
  /// log2(keypoints) + 1 trees, each keypoint rebuilt O(log keypoints) times in all).
  std::size_t AddPlace(const std::vector<BetaGridDescriptor>& descriptors);

  std::size_t places() const { return first_of_place_.size() - 1; }
  std::size_t keypoints() const { return descriptors_.size(); }
  std::size_t trees() const;  // kKdTree: the trees searched per query (kDense: 0)
  /// Distinct for every index made in this process (what a PairMemo's rows were computed
  /// against).
  std::uint64_t id() const { return id_; }

  /// For every place p with searched[p] != 0: below[p] = the pairs (query index, keypoint index
  /// of place p, SymmetricChi2) with SymmetricChi2Below(query, keypoint, chi2_threshold), ordered
  /// by query index, then keypoint index. Other places' lists are left empty. `below` is resized
  /// to the number of places; `searched` must have that size. Searches blocks of places (kDense)
  /// or of query rows (kKdTree) in parallel (TBB), with the same result at any number of threads.
  void FindPairs(const std::vector<BetaGridDescriptor>& query, double chi2_threshold,
                 const std::vector<char>& searched,
                 std::vector<std::vector<DescriptorPair>>& below) const;

 private:
  struct KdTree;  // a tree over the contiguous keypoints [begin, begin + count)
  // Appends the descriptors, their roots and norms (no tree).
  void Append(const std::vector<BetaGridDescriptor>& descriptors);
  // The squared search radius in square-root space for a query row of squared norm
  // `query_squared_norm`: 2 * chi2_threshold and a margin for rounding (descriptor_index.cpp).
  double SearchRadius2(double chi2_threshold, double query_squared_norm) const;
  // The exact test of query descriptor `query_index` against keypoint `keypoint`: true, and
  // `pair` (query index, keypoint index in its place, SymmetricChi2), when below the threshold.
  bool PairIfBelow(const BetaGridDescriptor& query, int query_index, std::size_t keypoint,
                   double chi2_threshold, DescriptorPair& pair) const;

  PlaceRecognitionConfig::DescriptorIndex kind_;
  std::uint64_t id_;
  std::vector<BetaGridDescriptor> descriptors_;  // every place keypoint, place-major
  std::vector<int> place_of_;                    // place index of each keypoint
  std::vector<int> first_of_place_{0};           // each place's first keypoint, then the end
  // Row k (kBetaGridBins doubles from k * kBetaGridBins): the element-wise square roots of
  // descriptors_[k] (zero bins as FLIRTLib's pseudo-zero). A growable vector, so adding a place
  // appends its rows instead of copying the matrix.
  std::vector<double> roots_;
  std::vector<double> squared_norms_;  // of the rows of roots_
  double max_squared_norm_ = 0.0;
  // kKdTree only: trees over consecutive keypoint ranges covering all keypoints, oldest first,
  // each more than twice the size of the next.
  std::vector<std::unique_ptr<KdTree>> trees_;
};

}  // namespace keyplace
