#pragma once
// The retrieval stage of place recognition (PlaceRecognitionConfig::Retrieval::kWords): a
// vocabulary of FLIRT descriptors learned from the map itself (two levels of k-means on the square
// roots of the descriptors, where the Euclidean distance bounds the symmetric chi2 of a pair, see
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
  /// O(keypoints x sqrt(words)).
  explicit PlaceWords(const std::vector<Place>& places);

  /// Appends a place described with the vocabulary held (not learned anew): its words join its
  /// own histogram and those of its map neighbours, and every place is weighed again by the new
  /// idf, O(its keypoints x sqrt(words) + the map's histogram entries).
  void Append(const Place& place);

  /// The cosine similarity of the query's tf-idf word histogram with each place's, in the order
  /// of the places given at construction and appended (0 for a place sharing no word).
  std::vector<double> Similarities(const std::vector<BetaGridDescriptor>& query) const;

  std::size_t words() const { return idf_.size(); }
  /// The map keypoints the vocabulary was learned from (those of the places at construction).
  std::size_t learned_keypoints() const { return learned_keypoints_; }

 private:
  using RowMatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  // Learns top_, leaves_ and first_word_ from square-root descriptors (a row each): about n_words
  // words (n_words <= samples).
  void LearnVocabulary(const RowMatrixF& samples, std::size_t n_words);
  // The word of each descriptor: its nearest leaf under its nearest top centre.
  std::vector<int> WordsOf(const std::vector<BetaGridDescriptor>& descriptors) const;
  // Whether place q is in the neighbourhood of place p (ids as far apart as their indices).
  bool Neighbours(std::size_t p, std::size_t q) const;
  // The word counts of place p's neighbourhood (its own words and its neighbours'), by word.
  std::vector<std::pair<int, int>> CountsOf(std::size_t p) const;
  // Appends place p's neighbourhood counts (CountsOf) to the postings.
  void AddPostingsOf(std::size_t p);
  // idf_ and inverse_norms_ from postings_.
  void Weigh();

  // A two-level vocabulary: top_ (a centre a row) splits square-root space, leaves_[t] the part of
  // top word t; the words are the leaves, those of top word t numbered from first_word_[t].
  RowMatrixF top_;
  std::vector<RowMatrixF> leaves_;
  std::vector<int> first_word_;
  std::size_t learned_keypoints_ = 0;
  std::vector<int> place_ids_;
  std::vector<std::vector<int>> own_words_;  // per place: the word of each of its keypoints
  std::vector<std::vector<std::pair<int, int>>> postings_;  // per word: (place, count)
  std::vector<double> idf_;            // per word: log(places / places holding the word)
  std::vector<double> inverse_norms_;  // per place: 1 / the norm of its tf-idf histogram (or 0)
};

}  // namespace keyplace
