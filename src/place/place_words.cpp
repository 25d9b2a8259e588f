#include "place/place_words.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace keyplace {
namespace {

using RowMatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Descriptors the vocabulary is learned from at most (evenly spaced over the map): k-means then
// costs the same for any larger map.
constexpr std::size_t kMaxVocabularySamples = 20000;
// Lloyd iterations: the vocabulary only needs to spread its words over the descriptors, not
// converge.
constexpr int kKMeansIterations = 8;

// One word per 8 map keypoints: on FR079 and Intel (about 4 300 and 4 900 keypoints) 512 words
// kept more right answers of true revisits than 64, 256 or 1024.
std::size_t WordCount(std::size_t keypoints) {
  return std::clamp<std::size_t>(keypoints / 8, 16, 4096);
}
// A place's words are those of its map neighbours too (ids within this of its own): a query
// submap of all its scans' keypoints covers more ground than one submap's stable keypoints. On
// FR079 and Intel, 2 kept more right answers of true revisits than 0, 1, 3 or 5.
constexpr int kNeighbours = 2;

void FillRoots(const BetaGridDescriptor& descriptor, float* row) {
  for (int i = 0; i < kBetaGridBins; ++i) row[i] = std::sqrt(std::max(descriptor[i], 0.0F));
}

// Row r of `samples` to its nearest row of `centres` (squared Euclidean), by one product.
std::vector<int> Assign(const RowMatrixF& samples, const RowMatrixF& centres) {
  const Eigen::VectorXf centre_norms = centres.rowwise().squaredNorm();
  std::vector<int> word(static_cast<std::size_t>(samples.rows()), 0);
  constexpr Eigen::Index kBlock = 2048;  // rows per product: 2048 x words floats at most
  for (Eigen::Index begin = 0; begin < samples.rows(); begin += kBlock) {
    const Eigen::Index count = std::min(kBlock, samples.rows() - begin);
    const Eigen::MatrixXf dots = samples.middleRows(begin, count) * centres.transpose();
    for (Eigen::Index r = 0; r < count; ++r) {
      Eigen::Index best = 0;
      (centre_norms.transpose() - 2.0F * dots.row(r)).minCoeff(&best);
      word[static_cast<std::size_t>(begin + r)] = static_cast<int>(best);
    }
  }
  return word;
}

// Lloyd's k-means from evenly spaced samples (deterministic): `k` centres (k <= samples); an
// empty cluster keeps its centre.
RowMatrixF KMeans(const RowMatrixF& samples, std::size_t k) {
  RowMatrixF centres(static_cast<Eigen::Index>(k), kBetaGridBins);
  for (std::size_t w = 0; w < k; ++w) {
    centres.row(static_cast<Eigen::Index>(w)) =
        samples.row(static_cast<Eigen::Index>(w * static_cast<std::size_t>(samples.rows()) / k));
  }
  for (int iteration = 0; iteration < kKMeansIterations; ++iteration) {
    const std::vector<int> word = Assign(samples, centres);
    RowMatrixF sums = RowMatrixF::Zero(centres.rows(), kBetaGridBins);
    std::vector<int> counts(k, 0);
    for (Eigen::Index r = 0; r < samples.rows(); ++r) {
      sums.row(word[static_cast<std::size_t>(r)]) += samples.row(r);
      ++counts[static_cast<std::size_t>(word[static_cast<std::size_t>(r)])];
    }
    for (std::size_t w = 0; w < k; ++w) {
      if (counts[w] > 0) {
        centres.row(static_cast<Eigen::Index>(w)) =
            sums.row(static_cast<Eigen::Index>(w)) / static_cast<float>(counts[w]);
      }
    }
  }
  return centres;
}

// The rows of `matrix` listed in `rows`, in that order.
RowMatrixF RowsOf(const RowMatrixF& matrix, const std::vector<Eigen::Index>& rows) {
  RowMatrixF selected(static_cast<Eigen::Index>(rows.size()), kBetaGridBins);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    selected.row(static_cast<Eigen::Index>(k)) = matrix.row(rows[k]);
  }
  return selected;
}

// For each of `words` words, the rows assigned to it (increasing).
std::vector<std::vector<Eigen::Index>> RowsByWord(const std::vector<int>& word_of_row,
                                                  std::size_t words) {
  std::vector<std::vector<Eigen::Index>> rows(words);
  for (std::size_t r = 0; r < word_of_row.size(); ++r) {
    rows[static_cast<std::size_t>(word_of_row[r])].push_back(static_cast<Eigen::Index>(r));
  }
  return rows;
}

}  // namespace

// Two levels: sqrt(n_words) top words, each split into words of its own, so that a descriptor
// finds its word among about 2 sqrt(n_words) centres instead of n_words (a map loads in
// O(keypoints x sqrt(words)), not O(keypoints x words)).
void PlaceWords::LearnVocabulary(const RowMatrixF& samples, std::size_t n_words) {
  const auto branches =
      static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n_words)) - 1e-9));
  top_ = KMeans(samples, branches);
  first_word_.assign(1, 0);
  leaves_.clear();
  for (const std::vector<Eigen::Index>& rows :
       RowsByWord(Assign(samples, top_), static_cast<std::size_t>(top_.rows()))) {
    // Words where the descriptors are: a top word gets its share of n_words by its samples (at
    // least one, at most one per sample); one no sample chose (k-means left it empty) is itself,
    // a word no descriptor of the map has (idf 0).
    const auto share = static_cast<std::size_t>(std::lround(
        static_cast<double>(n_words * rows.size()) / static_cast<double>(samples.rows())));
    leaves_.push_back(rows.empty() ? RowMatrixF(top_.row(static_cast<Eigen::Index>(leaves_.size())))
                                   : KMeans(RowsOf(samples, rows),
                                            std::clamp<std::size_t>(share, 1, rows.size())));
    first_word_.push_back(first_word_.back() + static_cast<int>(leaves_.back().rows()));
  }
}

PlaceWords::PlaceWords(const std::vector<Place>& places) {
  for (const Place& place : places) learned_keypoints_ += place.descriptors.size();
  if (learned_keypoints_ > 0) {
    const std::size_t n_words = std::min(WordCount(learned_keypoints_), learned_keypoints_);
    const std::size_t stride =
        (learned_keypoints_ + kMaxVocabularySamples - 1) / kMaxVocabularySamples;
    RowMatrixF samples(static_cast<Eigen::Index>((learned_keypoints_ + stride - 1) / stride),
                       kBetaGridBins);
    std::size_t k = 0;
    Eigen::Index row = 0;
    for (const Place& place : places) {
      for (const BetaGridDescriptor& descriptor : place.descriptors) {
        if (k++ % stride == 0) FillRoots(descriptor, samples.row(row++).data());
      }
    }
    LearnVocabulary(samples, n_words);
  }
  for (const Place& place : places) {
    place_ids_.push_back(place.id);
    own_words_.push_back(WordsOf(place.descriptors));
  }
  postings_.assign(first_word_.empty() ? 0 : static_cast<std::size_t>(first_word_.back()), {});
  // By place, then by word within a place: each list in increasing place order.
  for (std::size_t p = 0; p < places.size(); ++p) AddPostingsOf(p);
  Weigh();
}

void PlaceWords::Append(const Place& place) {
  const std::size_t n = place_ids_.size();
  place_ids_.push_back(place.id);
  own_words_.push_back(WordsOf(place.descriptors));
  // The earlier places whose neighbourhood holds the new one gain its words ...
  for (std::size_t p = n - std::min<std::size_t>(n, kNeighbours); p < n; ++p) {
    if (!Neighbours(p, n)) continue;
    const int earlier = static_cast<int>(p);
    for (const int word : own_words_[n]) {
      std::vector<std::pair<int, int>>& list = postings_[static_cast<std::size_t>(word)];
      // An entry of place q is appended only while place q, q + 1, ... or q + kNeighbours is
      // (or at construction, in place order): every entry after place p's is of a place
      // p - kNeighbours or later, so the search stops at an earlier one.
      auto it = list.rbegin();
      while (it != list.rend() && it->first != earlier && it->first + kNeighbours >= earlier) ++it;
      if (it != list.rend() && it->first == earlier) {
        ++it->second;
      } else {
        list.emplace_back(earlier, 1);
      }
    }
  }
  // ... and it has its own neighbourhood's.
  AddPostingsOf(n);
  Weigh();
}

void PlaceWords::AddPostingsOf(std::size_t p) {
  for (const auto& [word, count] : CountsOf(p)) {
    postings_[static_cast<std::size_t>(word)].emplace_back(static_cast<int>(p), count);
  }
}

bool PlaceWords::Neighbours(std::size_t p, std::size_t q) const {
  const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(q) - static_cast<std::ptrdiff_t>(p);
  return std::abs(offset) <= kNeighbours && place_ids_[q] == place_ids_[p] + offset;
}

std::vector<std::pair<int, int>> PlaceWords::CountsOf(std::size_t p) const {
  std::vector<int> words;
  const std::size_t first = p - std::min<std::size_t>(p, kNeighbours);
  const std::size_t last = std::min(p + kNeighbours, place_ids_.size() - 1);
  for (std::size_t q = first; q <= last; ++q) {
    if (Neighbours(p, q)) words.insert(words.end(), own_words_[q].begin(), own_words_[q].end());
  }
  std::sort(words.begin(), words.end());
  std::vector<std::pair<int, int>> counts;
  for (std::size_t begin = 0; begin < words.size();) {
    std::size_t end = begin;
    while (end < words.size() && words[end] == words[begin]) ++end;
    counts.emplace_back(words[begin], static_cast<int>(end - begin));
    begin = end;
  }
  return counts;
}

void PlaceWords::Weigh() {
  const std::size_t n_places = place_ids_.size();
  idf_.assign(postings_.size(), 0.0);
  inverse_norms_.assign(n_places, 0.0);
  // Word by word: each place's squares are summed in increasing word order.
  for (std::size_t w = 0; w < postings_.size(); ++w) {
    if (postings_[w].empty()) continue;
    idf_[w] = std::log(static_cast<double>(n_places) / static_cast<double>(postings_[w].size()));
    for (const auto& [place, count] : postings_[w]) {
      const double weight = count * idf_[w];
      inverse_norms_[static_cast<std::size_t>(place)] += weight * weight;
    }
  }
  for (double& norm : inverse_norms_) norm = norm > 0.0 ? 1.0 / std::sqrt(norm) : 0.0;
}

std::vector<int> PlaceWords::WordsOf(const std::vector<BetaGridDescriptor>& descriptors) const {
  if (descriptors.empty() || top_.rows() == 0) return {};  // no vocabulary: a map of no keypoints
  RowMatrixF roots(static_cast<Eigen::Index>(descriptors.size()), kBetaGridBins);
  for (std::size_t k = 0; k < descriptors.size(); ++k) {
    FillRoots(descriptors[k], roots.row(static_cast<Eigen::Index>(k)).data());
  }
  std::vector<int> word(descriptors.size(), 0);
  const std::vector<std::vector<Eigen::Index>> rows_of_top =
      RowsByWord(Assign(roots, top_), leaves_.size());
  for (std::size_t t = 0; t < leaves_.size(); ++t) {
    const std::vector<Eigen::Index>& rows = rows_of_top[t];
    if (rows.empty()) continue;
    const std::vector<int> leaf = Assign(RowsOf(roots, rows), leaves_[t]);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      word[static_cast<std::size_t>(rows[k])] = first_word_[t] + leaf[k];
    }
  }
  return word;
}

std::vector<double> PlaceWords::Similarities(const std::vector<BetaGridDescriptor>& query) const {
  std::vector<double> similarity(place_ids_.size(), 0.0);
  if (idf_.empty() || query.empty()) return similarity;
  std::vector<int> count(idf_.size(), 0);
  for (const int word : WordsOf(query)) ++count[static_cast<std::size_t>(word)];
  double norm2 = 0.0;
  for (std::size_t w = 0; w < count.size(); ++w) {
    const double weight = count[w] * idf_[w];
    norm2 += weight * weight;
  }
  if (norm2 <= 0.0) return similarity;
  const double norm = std::sqrt(norm2);
  for (std::size_t w = 0; w < count.size(); ++w) {
    if (count[w] == 0 || idf_[w] <= 0.0) continue;
    // The query's weight times the word's idf; a place holding the word (idf > 0) has a norm > 0.
    const double factor = count[w] * idf_[w] / norm * idf_[w];
    for (const auto& [place, place_count] : postings_[w]) {
      const auto p = static_cast<std::size_t>(place);
      similarity[p] += factor * place_count * inverse_norms_[p];
    }
  }
  return similarity;
}

}  // namespace keyplace
