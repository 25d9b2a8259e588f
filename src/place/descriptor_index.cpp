#include "place/descriptor_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

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

// At most this many doubles for the query-by-keypoint product of kDense (4 MiB).
constexpr std::size_t kProductBudget = std::size_t{1} << 19;

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void FillRoots(const BetaGridDescriptor& descriptor, double* row) {
  for (int i = 0; i < kBetaGridBins; ++i) {
    row[i] = std::sqrt(std::max(static_cast<double>(descriptor[i]), kPseudoZero));
  }
}

// nanoflann reads the rows of the root matrix through this adaptor (no copy).
struct RootsAdaptor {
  const RowMatrix* roots;

  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(roots->rows()); }
  double kdtree_get_pt(std::size_t index, std::size_t dim) const {
    return (*roots)(static_cast<Eigen::Index>(index), static_cast<Eigen::Index>(dim));
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

}  // namespace

struct SqrtDescriptorIndex::KdTree {
  RootsAdaptor adaptor;
  RootsTree tree;
  explicit KdTree(const RowMatrix& roots)
      : adaptor{&roots},
        tree(kBetaGridBins, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {}
};

SqrtDescriptorIndex::SqrtDescriptorIndex(const std::vector<Place>& places,
                                         PlaceRecognitionConfig::DescriptorIndex kind)
    : kind_(kind) {
  if (kind == PlaceRecognitionConfig::DescriptorIndex::kNone) {
    throw std::invalid_argument("SqrtDescriptorIndex: descriptor_index none has no index");
  }
  for (std::size_t p = 0; p < places.size(); ++p) {
    first_of_place_.push_back(static_cast<int>(descriptors_.size()));
    for (const BetaGridDescriptor& descriptor : places[p].descriptors) {
      descriptors_.push_back(descriptor);
      place_of_.push_back(static_cast<int>(p));
    }
  }
  first_of_place_.push_back(static_cast<int>(descriptors_.size()));
  roots_.resize(static_cast<Eigen::Index>(descriptors_.size()), kBetaGridBins);
  for (std::size_t k = 0; k < descriptors_.size(); ++k) {
    FillRoots(descriptors_[k], roots_.row(static_cast<Eigen::Index>(k)).data());
  }
  squared_norms_ = roots_.rowwise().squaredNorm();
  max_squared_norm_ = squared_norms_.size() > 0 ? squared_norms_.maxCoeff() : 0.0;
  if (kind == PlaceRecognitionConfig::DescriptorIndex::kKdTree && !descriptors_.empty()) {
    tree_ = std::make_unique<KdTree>(roots_);
  }
}

SqrtDescriptorIndex::~SqrtDescriptorIndex() = default;

double SqrtDescriptorIndex::SearchRadius2(double chi2_threshold, double query_squared_norm) const {
  return 2.0 * chi2_threshold * (1.0 + kRadiusSlack) +
         kRadiusSlack * (query_squared_norm + max_squared_norm_);
}

void SqrtDescriptorIndex::AddIfBelow(const BetaGridDescriptor& query, int query_index,
                                     std::size_t keypoint, double chi2_threshold,
                                     std::vector<std::vector<DescriptorPair>>& below) const {
  const double distance = SymmetricChi2IfBelow(query, descriptors_[keypoint], chi2_threshold);
  if (!(distance < chi2_threshold)) return;  // +inf: not below
  const int place = place_of_[keypoint];
  below[static_cast<std::size_t>(place)].push_back(
      {query_index, static_cast<int>(keypoint) - first_of_place_[static_cast<std::size_t>(place)],
       distance});
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
    std::vector<std::pair<std::size_t, double>> found;
    for (std::size_t c = 0; c < query.size(); ++c) {
      const auto row = static_cast<Eigen::Index>(c);
      found.clear();
      tree_->tree.radiusSearch(query_roots.row(row).data(),
                               SearchRadius2(chi2_threshold, query_norms[row]), found,
                               nanoflann::SearchParams(32, 0.0f, false));
      std::sort(found.begin(), found.end());  // by keypoint: the exhaustive order
      for (const auto& [keypoint, distance2] : found) {
        if (searched[static_cast<std::size_t>(place_of_[keypoint])]) {
          AddIfBelow(query[c], static_cast<int>(c), keypoint, chi2_threshold, below);
        }
      }
    }
    return;
  }

  // kDense: ||u - v||^2 = ||u||^2 + ||v||^2 - 2 u.v for a block of query rows against every
  // keypoint at once (one matrix product), then the exact test where it is within the radius.
  const auto n_keypoints = static_cast<std::size_t>(roots_.rows());
  const std::size_t block = std::clamp<std::size_t>(kProductBudget / n_keypoints, 1, 64);
  Eigen::MatrixXd dots;  // keypoint x query row of the block, column-major
  for (std::size_t begin = 0; begin < query.size(); begin += block) {
    const std::size_t rows = std::min(block, query.size() - begin);
    dots.resize(static_cast<Eigen::Index>(n_keypoints), static_cast<Eigen::Index>(rows));
    dots.noalias() =
        roots_ *
        query_roots.middleRows(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(rows))
            .transpose();
    for (std::size_t j = 0; j < rows; ++j) {
      const std::size_t c = begin + j;
      const double query_norm = query_norms[static_cast<Eigen::Index>(c)];
      const double radius2 = SearchRadius2(chi2_threshold, query_norm);
      const double* column = dots.col(static_cast<Eigen::Index>(j)).data();
      for (std::size_t p = 0; p < n_places; ++p) {
        if (!searched[p]) continue;
        const auto end = static_cast<std::size_t>(first_of_place_[p + 1]);
        for (auto k = static_cast<std::size_t>(first_of_place_[p]); k < end; ++k) {
          if (squared_norms_[static_cast<Eigen::Index>(k)] + query_norm - 2.0 * column[k] <
              radius2) {
            AddIfBelow(query[c], static_cast<int>(c), k, chi2_threshold, below);
          }
        }
      }
    }
  }
}

}  // namespace keyplace
