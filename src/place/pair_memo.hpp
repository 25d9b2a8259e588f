#pragma once
// Internal to src/place: a descriptor index's FindPairs through a PairMemo.

#include <vector>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/place/pair_memo.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "place/descriptor_index.hpp"

namespace keyplace {

class PairMemoAccess {
 public:
  /// index.FindPairs(query, chi2_threshold, searched, below), the same lists in the same order,
  /// pairing only the query descriptors `memo` does not hold (with every place of the index, so
  /// that a later query with other places searched can use them too). Afterwards `memo` holds
  /// the rows of `query`'s descriptors only, those of its first descriptors that fit its
  /// max_pairs.
  static void FindPairs(PairMemo& memo, const SqrtDescriptorIndex& index,
                        const std::vector<BetaGridDescriptor>& query, double chi2_threshold,
                        const std::vector<char>& searched,
                        std::vector<std::vector<DescriptorPair>>& below);

 private:
  struct QueryRows;
  // Moves the rows of `query`'s descriptors out of `held`.
  static QueryRows TakeRows(PairMemo::Rows& held, const std::vector<BetaGridDescriptor>& query);
  static void PairFresh(const SqrtDescriptorIndex& index, double chi2_threshold, QueryRows& taken);
};

}  // namespace keyplace
