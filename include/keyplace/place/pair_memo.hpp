#pragma once
// What a growing query's earlier answers found about its descriptors, kept for its next answer.
// A query that answers every metre while it grows (localization.query_every_m) keeps most of its
// keypoints from one answer to the next, and pairing each of them with every keypoint of the map
// again is a large part of a searching answer's time in open halls (docs/PLACE.md, "Descriptor
// index"). The memo holds, per query descriptor, its pairs below the χ² threshold with every
// keypoint of the map, so that the next answer pairs only the descriptors it does not hold.
// Exact: an answer is the same with and without it.

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "keyplace/features/descriptor.hpp"

namespace keyplace {

/// Used by PlaceRecognizer::Recognize through PlaceQuery::pair_memo, on the exact path with a
/// descriptor index (retrieval `exact`, or `auto` for a query not by_words); other queries leave
/// it as it is. A memo serves one map: answers against another recognizer, or after places were
/// added, start it afresh. It holds at most max_pairs pairs (16 bytes each, besides the rows'
/// keys and spare capacity): on a map whose rows need more, those of a query's later descriptors
/// are paired afresh each time. Not thread-safe: one per growing query (GlobalLocalizer holds
/// one).
class PairMemo {
 public:
  static constexpr std::size_t kDefaultMaxPairs = std::size_t{1} << 21;  // 32 MiB
  explicit PairMemo(std::size_t max_pairs = kDefaultMaxPairs) : max_pairs_(max_pairs) {}

  /// Forgets every descriptor.
  void Clear();
  /// Descriptors whose pairs are held: those of the last query that used the memo (the rows of
  /// descriptors a query no longer has are dropped when it is answered).
  std::size_t descriptors() const { return rows_.size(); }
  /// The pairs those rows hold.
  std::size_t pairs() const { return pairs_; }
  /// Of the last query's distinct descriptors, how many were held from the query before.
  std::size_t reused() const { return reused_; }

 private:
  friend class PairMemoAccess;  // src/place/pair_memo.hpp
  // One pair below the threshold: the place's slot in the descriptor index, its keypoint, the
  // symmetric χ².
  struct Entry {
    std::uint32_t slot = 0;
    std::uint32_t reference = 0;
    double distance = 0.0;
  };
  using Row = std::vector<Entry>;  // ordered by slot, then keypoint
  // Descriptors are keyed by their bytes, not their values: a NaN bin would never equal itself,
  // and -0.0 would equal 0.0 but hash apart.
  struct DescriptorHash {
    std::size_t operator()(const BetaGridDescriptor& descriptor) const;
  };
  struct SameBytes {
    bool operator()(const BetaGridDescriptor& a, const BetaGridDescriptor& b) const;
  };
  using Rows = std::unordered_map<BetaGridDescriptor, Row, DescriptorHash, SameBytes>;
  Rows rows_;
  // What the rows were computed against: the index (its id and how many keypoints it held) and
  // the threshold.
  std::uint64_t index_id_ = 0;
  std::size_t index_keypoints_ = 0;
  double chi2_threshold_ = -1.0;
  std::size_t max_pairs_;
  std::size_t pairs_ = 0;
  std::size_t reused_ = 0;
};

}  // namespace keyplace
