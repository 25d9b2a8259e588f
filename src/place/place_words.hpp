#pragma once
// The retrieval stage of place recognition (PlaceRecognitionConfig::Retrieval::kWords): a
// vocabulary of FLIRT descriptors learned from the map itself (k-means on the square roots of the
// descriptors, where the Euclidean distance bounds the symmetric chi2 of a pair, see
// descriptor_index.cpp) and a tf-idf weighted word histogram per place. A query's histogram
// against every place's (an inverted file: only the places sharing a word are touched) gives the
// places worth pairing; Algorithm 3, RANSAC and the checks then run on those alone.

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

class PlaceWords {
 public:
  /// Learns the vocabulary from the places' descriptors (deterministic) and indexes each place:
  /// O(keypoints x words), which a recognizer that relearns it on every AddPlace pays per place.
  explicit PlaceWords(const std::vector<Place>& places);

  /// The cosine similarity of the query's tf-idf word histogram with each place's, in the order
  /// of the places given at construction (0 for a place sharing no word).
  std::vector<double> Similarities(const std::vector<BetaGridDescriptor>& query) const;

  std::size_t words() const { return idf_.size(); }

 private:
  // The word of each descriptor: its nearest centre in square-root space.
  std::vector<int> WordsOf(const std::vector<BetaGridDescriptor>& descriptors) const;

  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> centres_;  // a word a row
  std::vector<double> idf_;  // log(places / places holding the word)
  std::vector<std::vector<std::pair<int, double>>> postings_;  // per word: (place, weight)
  std::size_t num_places_ = 0;
};

}  // namespace keyplace
