#include "place/descriptor_index.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <tbb/parallel_for.h>
#include <nanoflann.hpp>

namespace keyplace {

// Why a radius search in square-root space finds every pair (the bound).
//
// SymmetricChi2 (features/descriptor.cpp) is FLIRTLib's
//   chi2(x, y) = 1/2 * sum_i (x'_i - y'_i)^2 / (x'_i + y'_i),
// where x'_i = x_i, or z = DBL_MIN (FLIRTLib's PSEUDOZERO) when x_i = 0; likewise y'. Index the
// vectors u = sqrt(x'), v = sqrt(y') (element-wise) and let H(x, y) = ||u - v||^2. For a, b > 0:
//   (sqrt(a) - sqrt(b))^2 = (a - b)^2 / (sqrt(a) + sqrt(b))^2,
//   (sqrt(a) + sqrt(b))^2 = a + b + 2 sqrt(a b) >= a + b,
// hence (sqrt(a) - sqrt(b))^2 <= (a - b)^2 / (a + b). Summed over the 48 bins:
//   H(x, y) <= sum_i (x'_i - y'_i)^2 / (x'_i + y'_i) = 2 chi2(x, y),
// so chi2 < t implies H < c t with c = 2 (the 1/2 of FLIRTLib's chi2 is why c is 2 and not 1).
// c = 2 cannot be lowered: disjoint supports give chi2 -> 1 and H -> 2 (real FR079 descriptors
// reach H / chi2 = 2.0000, tests/place/descriptor_index_test.cpp). The other direction,
// (sqrt(a) + sqrt(b))^2 <= 2 (a + b), gives H >= chi2: the radius lets through only pairs with
// chi2 < 2 t, and the exact test decides those.
//
// Rounding. SymmetricChi2 sums 48 non-negative terms of 4 rounded operations each, so the
// computed value is >= chi2 (1 - 53 eps), eps = 2^-53. The roots are rounded (relative 2^-53),
// and the computed H (three dot products of 48 terms, or nanoflann's sum of 48 squares, and
// its cell bounds) is within 4 * 48 eps (||u|| + ||v||)^2 <= 400 eps (||u||^2 + ||v||^2) of the
// exact H of the unrounded roots. The search radius^2 2 t (1 + 1e-9) + 1e-9 (||u||^2 +
// max ||v||^2) covers all of it with a wide margin (eps = 1.1e-16) and costs nothing measurable:
// it lets through a few more pairs for the exact test, never fewer.
namespace {

constexpr double kPseudoZero = std::numeric_limits<double>::min();  // as SymmetricChi2
constexpr double kRadiusSlack = 1e-9;

// At most this many doubles for the query-by-keypoint product of kDense (4 MiB), per thread.
constexpr std::size_t kProductBudget = std::size_t{1} << 19;
// kDense splits larger maps into at least this many blocks of places (searched in parallel), of
// at least kMinBlockKeypoints keypoints each (smaller products lose their speed per keypoint).
// Only the data sizes decide the blocks, never the threads.
constexpr std::size_t kMinBlocks = 8;
constexpr std::size_t kMinBlockKeypoints = 256;
// kKdTree searches this many query rows per task.
constexpr std::size_t kRowsPerTask = 8;

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void FillRoots(const BetaGridDescriptor& descriptor, double* row) {
  for (int i = 0; i < kBetaGridBins; ++i) {
    row[i] = std::sqrt(std::max(static_cast<double>(descriptor[i]), kPseudoZero));
  }
}

std::uint64_t NextIndexId() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

// Named, not anonymous: SqrtDescriptorIndex::KdTree, a class with external linkage, holds these.
namespace descriptor_kdtree {

// nanoflann reads the rows [begin, begin + count) of the roots through this adaptor (no copy;
// through the vector, which may reallocate as places are added).
struct RootsAdaptor {
  const std::vector<double>* roots;
  std::size_t begin;
  std::size_t count;

  std::size_t kdtree_get_point_count() const { return count; }
  double kdtree_get_pt(std::size_t index, std::size_t dim) const {
    return (*roots)[(begin + index) * kBetaGridBins + dim];
  }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bbox*/) const {
    return false;
  }
};

using RootsTree = nanoflann::KDTreeSingleIndexAdaptor<
    nanoflann::L2_Simple_Adaptor<double, RootsAdaptor, double, std::size_t>, RootsAdaptor,
    kBetaGridBins, std::size_t>;

// Leaf size of the kd-tree: 10 and 20 measured alike on FR079 (docs/BENCHMARKS.md).
constexpr std::size_t kLeafSize = 16;

}  // namespace descriptor_kdtree

struct SqrtDescriptorIndex::KdTree {
  descriptor_kdtree::RootsAdaptor adaptor;
  descriptor_kdtree::RootsTree tree;  // built by its constructor
  KdTree(const std::vector<double>& roots, std::size_t begin, std::size_t count)
      : adaptor{&roots, begin, count},
        tree(kBetaGridBins, adaptor,
             nanoflann::KDTreeSingleIndexAdaptorParams(descriptor_kdtree::kLeafSize)) {}
};

SqrtDescriptorIndex::SqrtDescriptorIndex(const std::vector<Place>& places,
                                         PlaceRecognitionConfig::DescriptorIndex kind)
    : kind_(kind), id_(NextIndexId()) {
  if (kind == PlaceRecognitionConfig::DescriptorIndex::kNone) {
    throw std::invalid_argument("SqrtDescriptorIndex: descriptor_index none has no index");
  }
  for (const Place& place : places) Append(place.descriptors);
  // One tree over everything: a map loaded at once is searched as fast as before places could
  // be added.
  if (kind == PlaceRecognitionConfig::DescriptorIndex::kKdTree && !descriptors_.empty()) {
    trees_.push_back(std::make_unique<KdTree>(roots_, 0, descriptors_.size()));
  }
}

SqrtDescriptorIndex::~SqrtDescriptorIndex() = default;

void SqrtDescriptorIndex::Append(const std::vector<BetaGridDescriptor>& descriptors) {
  const auto place = static_cast<int>(places());
  for (const BetaGridDescriptor& descriptor : descriptors) {
    const std::size_t row = roots_.size();
    roots_.resize(row + kBetaGridBins);
    FillRoots(descriptor, roots_.data() + row);
    double squared_norm = 0.0;
    for (int i = 0; i < kBetaGridBins; ++i) squared_norm += roots_[row + i] * roots_[row + i];
    squared_norms_.push_back(squared_norm);
    max_squared_norm_ = std::max(max_squared_norm_, squared_norm);
    descriptors_.push_back(descriptor);
    place_of_.push_back(place);
  }
  first_of_place_.push_back(static_cast<int>(descriptors_.size()));
}

std::size_t SqrtDescriptorIndex::AddPlace(const std::vector<BetaGridDescriptor>& descriptors) {
  const std::size_t place = places();
  const std::size_t begin = descriptors_.size();
  Append(descriptors);
  if (kind_ != PlaceRecognitionConfig::DescriptorIndex::kKdTree || descriptors.empty()) {
    return place;
  }
  std::size_t count = descriptors.size();
  // Merging trees at most twice the size of the new one keeps the sizes more than doubling from
  // newest to oldest, hence few trees to search, and rebuilds each keypoint rarely.
  std::size_t first = begin;
  while (!trees_.empty() && trees_.back()->adaptor.count <= 2 * count) {
    first = trees_.back()->adaptor.begin;
    count += trees_.back()->adaptor.count;
    trees_.pop_back();
  }
  trees_.push_back(std::make_unique<KdTree>(roots_, first, count));
  return place;
}

std::size_t SqrtDescriptorIndex::trees() const { return trees_.size(); }

double SqrtDescriptorIndex::SearchRadius2(double chi2_threshold, double query_squared_norm) const {
  return 2.0 * chi2_threshold * (1.0 + kRadiusSlack) +
         kRadiusSlack * (query_squared_norm + max_squared_norm_);
}

bool SqrtDescriptorIndex::PairIfBelow(const BetaGridDescriptor& query, int query_index,
                                      std::size_t keypoint, double chi2_threshold,
                                      DescriptorPair& pair) const {
  const double distance = SymmetricChi2IfBelow(query, descriptors_[keypoint], chi2_threshold);
  if (!(distance < chi2_threshold)) return false;  // +inf: not below
  const int place = place_of_[keypoint];
  pair = {query_index,
          static_cast<int>(keypoint) - first_of_place_[static_cast<std::size_t>(place)], distance};
  return true;
}

void SqrtDescriptorIndex::FindPairs(const std::vector<BetaGridDescriptor>& query,
                                    double chi2_threshold, const std::vector<char>& searched,
                                    std::vector<std::vector<DescriptorPair>>& below) const {
  const std::size_t n_places = first_of_place_.size() - 1;
  if (searched.size() != n_places) {
    throw std::invalid_argument("SqrtDescriptorIndex::FindPairs: searched has " +
                                std::to_string(searched.size()) + " entries for " +
                                std::to_string(n_places) + " places");
  }
  below.assign(n_places, {});
  if (descriptors_.empty() || query.empty()) return;
  RowMatrix query_roots(static_cast<Eigen::Index>(query.size()), kBetaGridBins);
  for (std::size_t c = 0; c < query.size(); ++c) {
    FillRoots(query[c], query_roots.row(static_cast<Eigen::Index>(c)).data());
  }
  const Eigen::VectorXd query_norms = query_roots.rowwise().squaredNorm();

  if (kind_ == PlaceRecognitionConfig::DescriptorIndex::kKdTree) {
    // Blocks of query rows in parallel (TBB), each listing its pairs, then appended to the places'
    // lists in row order.
    const std::size_t n_tasks = (query.size() + kRowsPerTask - 1) / kRowsPerTask;
    std::vector<std::vector<std::pair<int, DescriptorPair>>> found_by_task(
        n_tasks);  // (place, pair)
    tbb::parallel_for(std::size_t{0}, n_tasks, [&](std::size_t task) {
      std::vector<std::pair<std::size_t, double>> found;
      std::vector<std::pair<std::size_t, double>> in_tree;
      const std::size_t end_row = std::min(query.size(), (task + 1) * kRowsPerTask);
      for (std::size_t c = task * kRowsPerTask; c < end_row; ++c) {
        const auto row = static_cast<Eigen::Index>(c);
        const double radius2 = SearchRadius2(chi2_threshold, query_norms[row]);
        found.clear();
        for (const auto& tree : trees_) {
          tree->tree.radiusSearch(query_roots.row(row).data(), radius2, in_tree,
                                  nanoflann::SearchParams(32, 0.0f, false));
          for (const auto& [local, distance2] : in_tree) {
            found.emplace_back(tree->adaptor.begin + local, distance2);
          }
        }
        std::sort(found.begin(), found.end());  // by keypoint: the exhaustive order
        for (const auto& [keypoint, distance2] : found) {
          const int place = place_of_[keypoint];
          DescriptorPair pair;
          if (searched[static_cast<std::size_t>(place)] &&
              PairIfBelow(query[c], static_cast<int>(c), keypoint, chi2_threshold, pair)) {
            found_by_task[task].emplace_back(place, pair);
          }
        }
      }
    });
    for (const auto& task_pairs : found_by_task) {
      for (const auto& [place, pair] : task_pairs) {
        below[static_cast<std::size_t>(place)].push_back(pair);
      }
    }
    return;
  }

  // kDense: ||u - v||^2 = ||u||^2 + ||v||^2 - 2 u.v for a block of whole places against every
  // query row at once (one matrix product), then the exact test where it is within the radius.
  // Blocks of places, not of query rows: each keypoint's roots are read from memory once per
  // query however large the map (blocks of query rows reread the whole map per block). The
  // blocks are searched in parallel (TBB); each writes only its own places' lists.
  const Eigen::Map<const RowMatrix> roots(
      roots_.data(), static_cast<Eigen::Index>(descriptors_.size()), kBetaGridBins);
  const std::size_t block_keypoints =
      std::min(std::max<std::size_t>(kProductBudget / query.size(), 1),
               std::max(descriptors_.size() / kMinBlocks, kMinBlockKeypoints));
  std::vector<std::pair<std::size_t, std::size_t>> blocks;  // [first place, end place)
  for (std::size_t first_place = 0; first_place < n_places;) {
    std::size_t end_place = first_place + 1;
    const auto begin = static_cast<std::size_t>(first_of_place_[first_place]);
    while (end_place < n_places &&
           static_cast<std::size_t>(first_of_place_[end_place + 1]) - begin <= block_keypoints) {
      ++end_place;
    }
    blocks.emplace_back(first_place, end_place);
    first_place = end_place;
  }
  // The pairs of the places [first_place, end_place), contiguous in the index, by one product.
  const auto find_in_run = [&](std::size_t first_place, std::size_t end_place) {
    const auto begin = static_cast<std::size_t>(first_of_place_[first_place]);
    const auto count = static_cast<std::size_t>(first_of_place_[end_place]) - begin;
    if (count == 0) return;
    Eigen::MatrixXd dots(static_cast<Eigen::Index>(count),
                         static_cast<Eigen::Index>(query.size()));  // keypoint x query row
    dots.noalias() =
        roots.middleRows(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(count)) *
        query_roots.transpose();
    // Per place, pairs in the exhaustive order: query keypoint, then place keypoint.
    for (std::size_t c = 0; c < query.size(); ++c) {
      const double query_norm = query_norms[static_cast<Eigen::Index>(c)];
      const double radius2 = SearchRadius2(chi2_threshold, query_norm);
      const double* column = dots.col(static_cast<Eigen::Index>(c)).data();
      for (std::size_t p = first_place; p < end_place; ++p) {
        const auto end = static_cast<std::size_t>(first_of_place_[p + 1]);
        for (auto k = static_cast<std::size_t>(first_of_place_[p]); k < end; ++k) {
          DescriptorPair pair;
          if (squared_norms_[k] + query_norm - 2.0 * column[k - begin] < radius2 &&
              PairIfBelow(query[c], static_cast<int>(c), k, chi2_threshold, pair)) {
            below[p].push_back(pair);
          }
        }
      }
    }
  };
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t block) {
    const auto [first_place, end_place] = blocks[block];
    // One product per run of consecutive searched places: the whole block when every place is
    // searched, a few rows when retrieval kept a few places (it costs no product elsewhere).
    for (std::size_t run_first = first_place; run_first < end_place;) {
      if (!searched[run_first]) {
        ++run_first;
        continue;
      }
      std::size_t run_end = run_first + 1;
      while (run_end < end_place && searched[run_end]) ++run_end;
      find_in_run(run_first, run_end);
      run_first = run_end;
    }
  });
}

}  // namespace keyplace
