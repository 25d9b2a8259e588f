#include "curvature_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>

namespace keyplace::features_internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Squared distance and hypot each carry < 2 ulp of error; this margin keeps every candidate
// that might be shorter than the current key (only those get the exact hypot comparison).
constexpr double kBoundSlack = 1.0 + 1e-13;

// Builds a CSR adjacency from an undirected edge list (both directions).
void BuildCsr(int n, const std::vector<int>& a, const std::vector<int>& b,
              std::vector<int>& offsets, std::vector<int>& targets, std::vector<int>& fill) {
  offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  for (std::size_t e = 0; e < a.size(); ++e) {
    ++offsets[a[e] + 1];
    ++offsets[b[e] + 1];
  }
  for (int v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  targets.resize(static_cast<std::size_t>(offsets[n]));
  fill.assign(offsets.begin(), offsets.end() - 1);
  for (std::size_t e = 0; e < a.size(); ++e) {
    targets[fill[a[e]]++] = b[e];
    targets[fill[b[e]]++] = a[e];
  }
}

// One round of Prim's algorithm from vertex 0 on the complete Euclidean graph minus the edges
// already taken (and minus the edge (0, n-1)); appends the tree edges to the workspace edge list
// (as (parent, vertex) in vertex order, like FLIRTLib). Edge weights are hypot(dx, dy) and the
// visiting order, comparisons and heap follow Boost's prim_minimum_spanning_tree on an adjacency
// matrix, so that exactly equal edge lengths -- common with centimetre ranges -- are resolved the
// same way. Dense O(n^2); a squared-distance test skips the hypot of clearly longer edges.
void PrimRound(int n, CurvatureWorkspace& ws) {
  // Removed edges = the union so far plus (0, n-1).
  ws.edge_a.push_back(0);
  ws.edge_b.push_back(n - 1);
  BuildCsr(n, ws.edge_a, ws.edge_b, ws.removed_offsets, ws.removed_targets, ws.removed_fill);
  ws.edge_a.pop_back();
  ws.edge_b.pop_back();

  enum : unsigned char { kWhite, kGray, kBlack };
  ws.prim_color.assign(n, kWhite);
  ws.prim_key.assign(n, kInf);
  ws.prim_key_bound.assign(n, kInf);
  ws.prim_parent.resize(n);
  ws.prim_removed_mark.assign(n, -1);
  for (int v = 0; v < n; ++v) ws.prim_parent[v] = v;
  unsigned char* color = ws.prim_color.data();
  double* key = ws.prim_key.data();
  double* key_bound = ws.prim_key_bound.data();
  int* parent = ws.prim_parent.data();
  int* removed_mark = ws.prim_removed_mark.data();
  const double* x = ws.x.data();
  const double* y = ws.y.data();
  QuaternaryHeap& heap = ws.prim_heap;
  heap.Reset(n, key);

  key[0] = 0.0;
  color[0] = kGray;
  heap.Push(0);
  while (!heap.Empty()) {
    const int u = heap.Top();
    heap.Pop();
    for (int r = ws.removed_offsets[u]; r < ws.removed_offsets[u + 1]; ++r) {
      removed_mark[ws.removed_targets[r]] = u;
    }
    const double ux = x[u];
    const double uy = y[u];
    for (int v = 0; v < n; ++v) {
      if (v == u || removed_mark[v] == u || color[v] == kBlack) continue;
      const double dx = x[v] - ux;
      const double dy = y[v] - uy;
      if (color[v] == kWhite) {
        const double weight = std::hypot(dx, dy);
        if (weight < key[v]) {
          key[v] = weight;
          key_bound[v] = weight * weight * kBoundSlack;
          parent[v] = u;
        }
        color[v] = kGray;
        heap.Push(v);
      } else if (dx * dx + dy * dy <= key_bound[v]) {
        const double weight = std::hypot(dx, dy);
        if (weight < key[v]) {
          key[v] = weight;
          key_bound[v] = weight * weight * kBoundSlack;
          parent[v] = u;
          heap.DecreaseKey(v);
        }
      }
    }
    color[u] = kBlack;
  }
  for (int v = 1; v < n; ++v) {
    if (parent[v] == v) continue;  // unreachable (only in tiny point sets)
    ws.edge_a.push_back(parent[v]);
    ws.edge_b.push_back(v);
  }
}

// Dijkstra from every vertex on the spanning-tree union, truncated at the largest radius. Each
// row holds the settled vertices in settle order (non-decreasing distance) with their squared
// distance; row_scale_count[i * L + l] is the length of the prefix within radii[l].
// The graph is nearly a chain, so the frontier stays small (about 5-10 vertices): an unsorted
// array with a linear minimum search beats a heap here.
void TruncatedGeodesicRows(int n, const std::vector<double>& radii, CurvatureWorkspace& ws) {
  const int num_scales = static_cast<int>(radii.size());
  const double max_radius = radii.back();
  ws.row_offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  ws.row_scale_count.resize(static_cast<std::size_t>(n) * num_scales);
  ws.row_vertex.clear();
  ws.row_dist2.clear();
  ws.dijkstra_dist.resize(n);
  ws.dijkstra_stamp.assign(n, -1);
  ws.dijkstra_slot.resize(n);
  ws.frontier_vertex.resize(n);
  ws.frontier_dist.resize(n);
  double* dist = ws.dijkstra_dist.data();
  int* stamp = ws.dijkstra_stamp.data();
  int* slot = ws.dijkstra_slot.data();  // frontier position, or -1 once settled
  int* frontier_vertex = ws.frontier_vertex.data();
  double* frontier_dist = ws.frontier_dist.data();
  const int* adj_offsets = ws.adj_offsets.data();
  const int* adj_targets = ws.adj_targets.data();
  const double* adj_weights = ws.adj_weights.data();

  for (int source = 0; source < n; ++source) {
    const std::size_t row_begin = ws.row_vertex.size();
    stamp[source] = source;
    dist[source] = 0.0;
    slot[source] = 0;
    frontier_vertex[0] = source;
    frontier_dist[0] = 0.0;
    int frontier_size = 1;
    while (frontier_size > 0) {
      int best = 0;
      for (int f = 1; f < frontier_size; ++f) {
        if (frontier_dist[f] < frontier_dist[best]) best = f;
      }
      const int v = frontier_vertex[best];
      const double d = frontier_dist[best];
      --frontier_size;
      frontier_vertex[best] = frontier_vertex[frontier_size];
      frontier_dist[best] = frontier_dist[frontier_size];
      slot[frontier_vertex[best]] = best;
      slot[v] = -1;
      ws.row_vertex.push_back(v);
      ws.row_dist2.push_back(d * d);
      for (int e = adj_offsets[v]; e < adj_offsets[v + 1]; ++e) {
        const int t = adj_targets[e];
        const double nd = d + adj_weights[e];
        if (nd > max_radius) continue;
        if (stamp[t] != source) {
          stamp[t] = source;
          dist[t] = nd;
          slot[t] = frontier_size;
          frontier_vertex[frontier_size] = t;
          frontier_dist[frontier_size] = nd;
          ++frontier_size;
        } else if (nd < dist[t] && slot[t] >= 0) {
          dist[t] = nd;
          frontier_dist[slot[t]] = nd;
        }
      }
    }
    const std::size_t row_end = ws.row_vertex.size();
    ws.row_offsets[source + 1] = static_cast<int>(row_end);
    // Prefix lengths per scale (rows are sorted by distance).
    std::size_t k = row_begin;
    for (int l = 0; l < num_scales; ++l) {
      const double r2 = radii[l] * radii[l];
      while (k < row_end && ws.row_dist2[k] <= r2) ++k;
      ws.row_scale_count[static_cast<std::size_t>(source) * num_scales + l] =
          static_cast<int>(k - row_begin);
    }
  }
}

}  // namespace

void ComputeCurvature(const CurvatureParams& params, CurvatureWorkspace& ws,
                      CurvatureResult& result) {
  const int n = static_cast<int>(ws.x.size());
  const int num_scales = static_cast<int>(params.sigmas_m.size());
  result.ax.resize(num_scales);
  result.ay.resize(num_scales);
  result.signal.resize(num_scales);

  // 1. Union of num_trees successive minimum spanning trees of the complete graph.
  ws.edge_a.clear();
  ws.edge_b.clear();
  for (int round = 0; round < params.num_trees; ++round) PrimRound(n, ws);
  ws.edge_weight.resize(ws.edge_a.size());  // the same hypot values Prim compared
  for (std::size_t e = 0; e < ws.edge_a.size(); ++e) {
    ws.edge_weight[e] = std::hypot(ws.x[ws.edge_a[e]] - ws.x[ws.edge_b[e]],
                                   ws.y[ws.edge_a[e]] - ws.y[ws.edge_b[e]]);
  }
  BuildCsr(n, ws.edge_a, ws.edge_b, ws.adj_offsets, ws.adj_targets, ws.adj_fill);
  ws.adj_weights.resize(ws.adj_targets.size());
  {
    std::vector<int>& fill = ws.adj_fill;
    fill.assign(ws.adj_offsets.begin(), ws.adj_offsets.end() - 1);
    for (std::size_t e = 0; e < ws.edge_a.size(); ++e) {
      ws.adj_weights[fill[ws.edge_a[e]]++] = ws.edge_weight[e];
      ws.adj_weights[fill[ws.edge_b[e]]++] = ws.edge_weight[e];
    }
  }

  // 2. Geodesic distances up to the largest kernel radius.
  std::vector<double> radii(num_scales);
  for (int l = 0; l < num_scales; ++l) radii[l] = params.cutoff_sigmas * params.sigmas_m[l];
  TruncatedGeodesicRows(n, radii, ws);

  // 3. Per scale: A(i) = sum_j e_ij / D_j p_j / sum_j e_ij / D_j, D_j = sum_k e_jk.
  ws.kernel.resize(ws.row_vertex.size());
  ws.inv_density.resize(n);
  const int* row_offsets = ws.row_offsets.data();
  const int* row_vertex = ws.row_vertex.data();
  const double* row_dist2 = ws.row_dist2.data();
  double* kernel = ws.kernel.data();
  double* inv_density = ws.inv_density.data();
  const double* x = ws.x.data();
  const double* y = ws.y.data();
  for (int l = 0; l < num_scales; ++l) {
    const double sigma = params.sigmas_m[l];
    const double neg_inv_two_sigma2 = -1.0 / (2.0 * sigma * sigma);
    for (int i = 0; i < n; ++i) {
      const int begin = row_offsets[i];
      const int end = begin + ws.row_scale_count[static_cast<std::size_t>(i) * num_scales + l];
      double density = 0.0;
      for (int k = begin; k < end; ++k) {
        const double e = std::exp(row_dist2[k] * neg_inv_two_sigma2);
        kernel[k] = e;
        density += e;
      }
      inv_density[i] = 1.0 / density;
    }
    auto& ax = result.ax[l];
    auto& ay = result.ay[l];
    auto& signal = result.signal[l];
    ax.resize(n);
    ay.resize(n);
    signal.resize(n);
    const double two_over_sigma = 2.0 * (1.0 / sigma);
    for (int i = 0; i < n; ++i) {
      const int begin = row_offsets[i];
      const int end = begin + ws.row_scale_count[static_cast<std::size_t>(i) * num_scales + l];
      double sw = 0.0, sx = 0.0, sy = 0.0;
      for (int k = begin; k < end; ++k) {
        const int j = row_vertex[k];
        const double w = kernel[k] * inv_density[j];
        sw += w;
        sx += w * x[j];
        sy += w * y[j];
      }
      const double inv_sw = 1.0 / sw;
      ax[i] = sx * inv_sw;
      ay[i] = sy * inv_sw;
      const double t = two_over_sigma * std::hypot(ax[i] - x[i], ay[i] - y[i]);
      signal[i] = t * std::exp(-t);
    }
  }
}

}  // namespace keyplace::features_internal
