#pragma once
// Internal: FLIRT's geodesic-graph curvature signal (not installed, not part of the API).

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace keyplace::features_internal {

// Indexed 4-ary min-heap of vertices ordered by `Less(a, b)`, with the sift rules of the Boost
// Graph Library's d_ary_heap_indirect (which FLIRTLib's Prim runs on), so that equal keys pop in
// the same order.
template <typename Less>
class QuaternaryHeap {
 public:
  void Reset(int n, Less less) {
    data_.clear();
    index_.assign(n, -1);
    less_ = less;
  }
  bool Empty() const { return data_.empty(); }
  int Top() const { return data_[0]; }
  void Push(int v) {
    data_.push_back(v);
    index_[v] = static_cast<int>(data_.size()) - 1;
    SiftUp(index_[v]);
  }
  void Pop() {
    index_[data_[0]] = -1;
    if (data_.size() == 1) {
      data_.pop_back();
      return;
    }
    data_[0] = data_.back();
    index_[data_[0]] = 0;
    data_.pop_back();
    SiftDown();
  }
  void DecreaseKey(int v) { SiftUp(index_[v]); }

 private:
  static constexpr int kArity = 4;

  // Counts the levels the element rises first, then shifts the parents down.
  void SiftUp(int index) {
    const int moving = data_[index];
    int levels = 0;
    for (int i = index; i > 0;) {
      const int parent = (i - 1) / kArity;
      if (!less_(moving, data_[parent])) break;
      ++levels;
      i = parent;
    }
    int i = index;
    for (int level = 0; level < levels; ++level) {
      const int parent = (i - 1) / kArity;
      data_[i] = data_[parent];
      index_[data_[i]] = i;
      i = parent;
    }
    data_[i] = moving;
    index_[moving] = i;
  }

  // Swaps the root down with its smallest child (the first one among equals) while smaller.
  void SiftDown() {
    const int size = static_cast<int>(data_.size());
    const int moving = data_[0];
    int index = 0;
    for (;;) {
      const int first_child = index * kArity + 1;
      if (first_child >= size) break;
      const int last_child = std::min(first_child + kArity, size);
      int smallest = first_child;
      for (int c = first_child + 1; c < last_child; ++c) {
        if (less_(data_[c], data_[smallest])) smallest = c;
      }
      if (!less_(data_[smallest], moving)) break;
      std::swap(data_[smallest], data_[index]);
      index_[data_[smallest]] = smallest;
      index_[data_[index]] = index;
      index = smallest;
    }
  }

  std::vector<int> data_;
  std::vector<int> index_;
  Less less_{};
};

// Squared distances carry a few ulp of error; when two are closer than this (relative), their
// order is decided by the exact hypot values that FLIRTLib compares.
constexpr double kCloseRelative = 1e-12;

/// hypot(edge a1-b1) < hypot(edge a2-b2), given the squared lengths of both edges.
inline bool EdgeLess(const double* x, const double* y, int a1, int b1, double d2_1, int a2, int b2,
                     double d2_2) {
  if (d2_1 < d2_2 * (1.0 - kCloseRelative)) return true;
  if (d2_1 > d2_2 * (1.0 + kCloseRelative)) return false;
  return std::hypot(x[a1] - x[b1], y[a1] - y[b1]) < std::hypot(x[a2] - x[b2], y[a2] - y[b2]);
}

/// Orders Prim's vertices by their key edge (parent[v], v).
struct PrimKeyOrder {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* key2 = nullptr;
  const int* parent = nullptr;
  bool operator()(int a, int b) const {
    return EdgeLess(x, y, parent[a], a, key2[a], parent[b], b, key2[b]);
  }
};

constexpr int kMaxScales = 32;

struct AdjacentVertex {
  double weight;
  int vertex;
};

/// Tentative geodesic distance of a vertex in the search from `stamp` (the current source).
struct GeodesicLabel {
  double dist;
  int stamp;
  int queued;
};

/// Scratch buffers of the detector, reused between scans (one per thread).
struct CurvatureWorkspace {
  // Vertex positions (valid beams in scan order).
  std::vector<double> x, y;
  // Prim.
  std::vector<int> prim_parent, prim_vertex, prim_position, prim_key_parent;
  std::vector<double> prim_x, prim_y;
  std::vector<double> prim_key2, prim_gate, prim_saved_gate;
  QuaternaryHeap<PrimKeyOrder> prim_heap;
  // Edges of the spanning-tree union (and its CSR adjacency).
  std::vector<int> edge_a, edge_b;
  std::vector<int> tree_end;  // end of each spanning tree in the edge list
  std::vector<double> edge_weight;
  std::vector<int> removed_offsets, removed_targets, removed_fill;
  std::vector<int> adj_offsets, adj_targets, adj_fill;
  std::vector<AdjacentVertex> adjacent;
  // Truncated geodesic rows: for each source i, the vertices j > i within the cutoff, grouped
  // by scale band (see TruncatedGeodesicRows).
  std::vector<int> row_offsets, row_vertex, row_scale_count;
  std::vector<double> row_dist2;
  std::vector<GeodesicLabel> labels;
  std::vector<int> queue, touched, touched_band;
  // Each row's distances to its vertices up to its highest neighbour (TruncatedGeodesicRows).
  std::vector<int> reach, ahead_offsets, ahead_cursor;
  std::vector<AdjacentVertex> ahead;  // (distance, vertex)
  std::vector<std::pair<int, int>> crossing_edges;
  // Smoothing.
  std::vector<double> kernel, density, inv_density, sum_w, sum_wx, sum_wy;
};

struct CurvatureParams {
  std::vector<double> sigmas_m;
  int num_trees = 3;           // dmst + 1
  double cutoff_sigmas = 8.0;  // kernel truncation radius in sigmas (may be +inf)
};

/// Per scale: smoothed positions (ax, ay) and signal t exp(-t) for every vertex.
struct CurvatureResult {
  std::vector<std::vector<double>> ax, ay, signal;
};

/// Computes the smoothing operator and signal of FLIRTLib's CurvatureDetector for the points
/// (x, y) in workspace.x / workspace.y (n >= 2). `result` is resized to the number of scales.
void ComputeCurvature(const CurvatureParams& params, CurvatureWorkspace& workspace,
                      CurvatureResult& result);

}  // namespace keyplace::features_internal
