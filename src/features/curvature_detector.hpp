#pragma once
// Internal: FLIRT's geodesic-graph curvature signal (not installed, not part of the API).

#include <algorithm>
#include <utility>
#include <vector>

namespace keyplace::features_internal {

// Indexed 4-ary min-heap on key[], with the sift rules of the Boost Graph Library's
// d_ary_heap_indirect (which FLIRTLib's Prim runs on), so that equal keys pop in the same order.
class QuaternaryHeap {
 public:
  void Reset(int n, const double* key) {
    data_.clear();
    index_.assign(n, -1);
    key_ = key;
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
    const double moving_key = key_[moving];
    int levels = 0;
    for (int i = index; i > 0;) {
      const int parent = (i - 1) / kArity;
      if (!(moving_key < key_[data_[parent]])) break;
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

  // Swaps the root down with its smallest child (first one on equal keys) while smaller.
  void SiftDown() {
    const int size = static_cast<int>(data_.size());
    const double moving_key = key_[data_[0]];
    int index = 0;
    for (;;) {
      const int first_child = index * kArity + 1;
      if (first_child >= size) break;
      const int last_child = std::min(first_child + kArity, size);
      int smallest = first_child;
      double smallest_key = key_[data_[first_child]];
      for (int c = first_child + 1; c < last_child; ++c) {
        if (key_[data_[c]] < smallest_key) {
          smallest = c;
          smallest_key = key_[data_[c]];
        }
      }
      if (!(smallest_key < moving_key)) break;
      std::swap(data_[smallest], data_[index]);
      index_[data_[smallest]] = smallest;
      index_[data_[index]] = index;
      index = smallest;
    }
  }

  std::vector<int> data_;
  std::vector<int> index_;
  const double* key_ = nullptr;
};

/// Scratch buffers of the detector, reused between scans (one per thread).
struct CurvatureWorkspace {
  // Vertex positions (valid beams in scan order).
  std::vector<double> x, y;
  // Prim.
  std::vector<unsigned char> prim_color;
  std::vector<int> prim_parent, prim_removed_mark;
  std::vector<double> prim_key, prim_key_bound;
  QuaternaryHeap prim_heap;
  // Edges of the spanning-tree union (and its CSR adjacency).
  std::vector<int> edge_a, edge_b;
  std::vector<double> edge_weight;
  std::vector<int> removed_offsets, removed_targets, removed_fill;
  std::vector<int> adj_offsets, adj_targets, adj_fill;
  std::vector<double> adj_weights;
  // Truncated geodesic rows: for each source, the vertices within the cutoff in settle order.
  std::vector<int> row_offsets, row_vertex, row_scale_count;
  std::vector<double> row_dist2;
  std::vector<double> dijkstra_dist, frontier_dist;
  std::vector<int> dijkstra_stamp, dijkstra_slot, frontier_vertex;
  // Smoothing.
  std::vector<double> kernel, inv_density;
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
