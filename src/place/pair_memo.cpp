#include "place/pair_memo.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/fnv1a64.hpp"

namespace keyplace {

void PairMemo::Clear() {
  rows_.clear();
  pairs_ = 0;
  reused_ = 0;
}

std::size_t PairMemo::DescriptorHash::operator()(const BetaGridDescriptor& descriptor) const {
  Fnv1a64 hash;
  hash.Bytes(descriptor.data(), sizeof(descriptor));
  return static_cast<std::size_t>(hash.value());
}

bool PairMemo::SameBytes::operator()(const BetaGridDescriptor& a,
                                     const BetaGridDescriptor& b) const {
  for (std::size_t k = 0; k < a.size(); ++k) {
    std::uint32_t bits_a = 0;
    std::uint32_t bits_b = 0;
    static_assert(sizeof(bits_a) == sizeof(a[k]), "a float has 32 bits");
    std::memcpy(&bits_a, &a[k], sizeof(bits_a));
    std::memcpy(&bits_b, &b[k], sizeof(bits_b));
    if (bits_a != bits_b) return false;
  }
  return true;
}

// The rows of one query: those the memo held, moved out of it, and empty ones for the
// descriptors it did not hold (`fresh`, each once however often the query holds it), with each
// query descriptor's row found once.
struct PairMemoAccess::QueryRows {
  PairMemo::Rows rows;
  std::vector<PairMemo::Row*> row_of;  // per query descriptor; stable: the map's nodes stay put
  std::vector<std::size_t> distinct;   // the query index of each descriptor's first occurrence
  std::vector<BetaGridDescriptor> fresh;
  std::vector<PairMemo::Row*> fresh_rows;
  std::size_t reused = 0;
};

PairMemoAccess::QueryRows PairMemoAccess::TakeRows(PairMemo::Rows& held,
                                                   const std::vector<BetaGridDescriptor>& query) {
  QueryRows taken;
  taken.rows.reserve(query.size());
  taken.row_of.resize(query.size());
  for (std::size_t c = 0; c < query.size(); ++c) {
    const auto [row, inserted] = taken.rows.try_emplace(query[c]);
    taken.row_of[c] = &row->second;
    if (!inserted) continue;  // the query holds this descriptor twice
    taken.distinct.push_back(c);
    auto held_row = held.find(query[c]);
    if (held_row != held.end()) {
      row->second = std::move(held_row->second);
      ++taken.reused;
    } else {
      taken.fresh_rows.push_back(&row->second);
      taken.fresh.push_back(query[c]);
    }
  }
  return taken;
}

void PairMemoAccess::PairFresh(const SqrtDescriptorIndex& index, double chi2_threshold,
                               QueryRows& taken) {
  if (taken.fresh.empty()) return;
  std::vector<std::vector<DescriptorPair>> below;
  index.FindPairs(taken.fresh, chi2_threshold, std::vector<char>(index.places(), 1), below);
  // Slot by slot, each slot's pairs by fresh row, then keypoint: every row's entries end up
  // ordered by slot, then keypoint.
  for (std::size_t slot = 0; slot < below.size(); ++slot) {
    for (const DescriptorPair& pair : below[slot]) {
      taken.fresh_rows[static_cast<std::size_t>(pair.current)]->push_back(
          {static_cast<std::uint32_t>(slot), static_cast<std::uint32_t>(pair.reference),
           pair.distance});
    }
  }
}

void PairMemoAccess::FindPairs(PairMemo& memo, const SqrtDescriptorIndex& index,
                               const std::vector<BetaGridDescriptor>& query, double chi2_threshold,
                               const std::vector<char>& searched,
                               std::vector<std::vector<DescriptorPair>>& below) {
  if (searched.size() != index.places()) {
    throw std::invalid_argument("PairMemo: searched has " + std::to_string(searched.size()) +
                                " entries for " + std::to_string(index.places()) + " places");
  }
  if (memo.index_id_ != index.id() || memo.index_keypoints_ != index.keypoints() ||
      memo.chi2_threshold_ != chi2_threshold) {
    memo.Clear();
    memo.index_id_ = index.id();
    memo.index_keypoints_ = index.keypoints();
    memo.chi2_threshold_ = chi2_threshold;
  }
  // The rows leave the memo until the answer is made: if anything throws on the way, the memo is
  // empty, never holding rows whose pairs were moved out.
  PairMemo::Rows held;
  held.swap(memo.rows_);
  memo.pairs_ = 0;
  memo.reused_ = 0;
  QueryRows taken = TakeRows(held, query);
  PairFresh(index, chi2_threshold, taken);
  below.assign(index.places(), {});
  for (std::size_t c = 0; c < query.size(); ++c) {
    for (const PairMemo::Entry& entry : *taken.row_of[c]) {
      if (!searched[entry.slot]) continue;
      below[entry.slot].push_back(
          {static_cast<int>(c), static_cast<int>(entry.reference), entry.distance});
    }
  }
  // Bounded memory whatever the map: the rows beyond the budget, in query order (a growing query
  // keeps its first keypoints), are paired afresh next time.
  std::size_t pairs = 0;
  for (std::size_t c : taken.distinct) {
    const std::size_t row_pairs = taken.row_of[c]->size();
    if (pairs + row_pairs > memo.max_pairs_) {
      taken.rows.erase(query[c]);
    } else {
      pairs += row_pairs;
    }
  }
  memo.rows_ = std::move(taken.rows);
  memo.pairs_ = pairs;
  memo.reused_ = taken.reused;
}

}  // namespace keyplace
