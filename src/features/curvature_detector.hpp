#pragma once
// Internal: FLIRT's geodesic-graph curvature signal (not installed, not part of the API).

#include <vector>

namespace keyplace::features_internal {

/// Scratch buffers of the detector, reused between scans (one per thread).
struct CurvatureWorkspace {
  // Vertex positions (valid beams in scan order).
  std::vector<double> x, y;
  // Prim: compact arrays of the vertices not yet in the tree.
  std::vector<int> prim_vertex, prim_parent, prim_position;
  std::vector<double> prim_x, prim_y, prim_key;
  // Edges of the spanning-tree union (and its CSR adjacency).
  std::vector<int> edge_a, edge_b;
  std::vector<double> edge_weight;
  std::vector<int> removed_offsets, removed_targets, removed_fill;
  std::vector<int> adj_offsets, adj_targets, adj_fill;
  std::vector<double> adj_weights;
  // Truncated geodesic rows: for each source, the vertices within the cutoff in settle order.
  std::vector<int> row_offsets, row_vertex, row_scale_count;
  std::vector<double> row_dist2;
  std::vector<double> dijkstra_dist;
  std::vector<int> dijkstra_touched;
  std::vector<std::pair<double, int>> heap;
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
