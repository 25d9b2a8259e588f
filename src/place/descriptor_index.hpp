#pragma once
// The exact descriptor index of place recognition: every place keypoint whose descriptor has a
// symmetric chi2 below a threshold to a query descriptor, found through a bound in the space of
// square-root descriptors (descriptor_index.cpp proves it) and checked by the exact chi2. It
// finds the pairs exhaustive matching finds, with the same distances, in the same order.

#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

class SqrtDescriptorIndex {
 public:
  /// Indexes the descriptors of `places` (copied; the places may change afterwards). `kind` is
  /// kKdTree or kDense (kNone throws std::invalid_argument: no index).
  SqrtDescriptorIndex(const std::vector<Place>& places,
                      PlaceRecognitionConfig::DescriptorIndex kind);
  ~SqrtDescriptorIndex();
  SqrtDescriptorIndex(const SqrtDescriptorIndex&) = delete;
  SqrtDescriptorIndex& operator=(const SqrtDescriptorIndex&) = delete;

  /// For every place p with searched[p] != 0: below[p] = the pairs (query index, keypoint index
  /// of place p, SymmetricChi2) with SymmetricChi2Below(query, keypoint, chi2_threshold), ordered
  /// by query index, then keypoint index. Other places' lists are left empty. `below` is resized
  /// to the number of places; `searched` must have that size.
  void FindPairs(const std::vector<BetaGridDescriptor>& query, double chi2_threshold,
                 const std::vector<char>& searched,
                 std::vector<std::vector<DescriptorPair>>& below) const;

 private:
  struct KdTree;
  // The squared search radius in square-root space for a query row of squared norm
  // `query_squared_norm`: 2 * chi2_threshold and a margin for rounding (descriptor_index.cpp).
  double SearchRadius2(double chi2_threshold, double query_squared_norm) const;
  // The exact test of query descriptor `query_index` against keypoint `keypoint`.
  void AddIfBelow(const BetaGridDescriptor& query, int query_index, std::size_t keypoint,
                  double chi2_threshold, std::vector<std::vector<DescriptorPair>>& below) const;

  PlaceRecognitionConfig::DescriptorIndex kind_;
  std::vector<BetaGridDescriptor> descriptors_;  // every place keypoint, place-major
  std::vector<int> place_of_;                    // place index of each keypoint
  std::vector<int> first_of_place_;              // index of each place's first keypoint
  // Row k: the element-wise square roots of descriptors_[k] (zero bins as FLIRTLib's pseudo-zero).
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> roots_;
  Eigen::VectorXd squared_norms_;  // of the rows of roots_
  double max_squared_norm_ = 0.0;
  std::unique_ptr<KdTree> tree_;  // kKdTree only
};

}  // namespace keyplace
