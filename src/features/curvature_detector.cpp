#include "curvature_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>

namespace keyplace::features_internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Moves a blocked vertex out of reach for one Prim step: its squared distance overflows to +inf.
constexpr double kFarAway = 1e200;

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

// One round of Prim's algorithm (root 0) on the complete Euclidean graph minus the edges already
// taken (and minus the edge (0, n-1)); appends the tree edges to the workspace edge list.
// Dense O(n^2): compares squared distances, which order the edges exactly like the distances.
void PrimRound(int n, CurvatureWorkspace& ws) {
  // Removed edges = the union so far plus (0, n-1).
  ws.edge_a.push_back(0);
  ws.edge_b.push_back(n - 1);
  BuildCsr(n, ws.edge_a, ws.edge_b, ws.removed_offsets, ws.removed_targets, ws.removed_fill);
  ws.edge_a.pop_back();
  ws.edge_b.pop_back();

  int m = n - 1;  // vertices not in the tree, at compact positions 0..m-1
  ws.prim_vertex.resize(n);
  ws.prim_parent.resize(n);
  ws.prim_position.resize(n);
  ws.prim_x.resize(n);
  ws.prim_y.resize(n);
  ws.prim_key.resize(n);
  ws.prim_position[0] = -1;
  for (int v = 1; v < n; ++v) {
    const int p = v - 1;
    ws.prim_vertex[p] = v;
    ws.prim_parent[p] = -1;
    ws.prim_position[v] = p;
    ws.prim_x[p] = ws.x[v];
    ws.prim_y[p] = ws.y[v];
    ws.prim_key[p] = kInf;
  }
  int* vertex = ws.prim_vertex.data();
  int* parent = ws.prim_parent.data();
  double* px = ws.prim_x.data();
  double* py = ws.prim_y.data();
  double* key = ws.prim_key.data();

  int u = 0;
  while (m > 0) {
    const double ux = ws.x[u];
    const double uy = ws.y[u];
    const int removed_begin = ws.removed_offsets[u];
    const int removed_end = ws.removed_offsets[u + 1];
    for (int r = removed_begin; r < removed_end; ++r) {
      const int p = ws.prim_position[ws.removed_targets[r]];
      if (p >= 0) px[p] = kFarAway;
    }
    double best = kInf;
    int best_p = -1;
    for (int p = 0; p < m; ++p) {
      const double dx = px[p] - ux;
      const double dy = py[p] - uy;
      const double d2 = dx * dx + dy * dy;
      if (d2 < key[p]) {
        key[p] = d2;
        parent[p] = u;
      }
      if (key[p] < best) {
        best = key[p];
        best_p = p;
      }
    }
    for (int r = removed_begin; r < removed_end; ++r) {
      const int t = ws.removed_targets[r];
      const int p = ws.prim_position[t];
      if (p >= 0) px[p] = ws.x[t];
    }
    if (best_p < 0) break;  // the rest is unreachable (only for tiny point sets)
    const int v = vertex[best_p];
    ws.edge_a.push_back(parent[best_p]);
    ws.edge_b.push_back(v);
    // Remove best_p from the compact arrays (swap with the last).
    const int last = m - 1;
    vertex[best_p] = vertex[last];
    parent[best_p] = parent[last];
    px[best_p] = px[last];
    py[best_p] = py[last];
    key[best_p] = key[last];
    ws.prim_position[vertex[best_p]] = best_p;
    ws.prim_position[v] = -1;
    --m;
    u = v;
  }
}

// Dijkstra from every vertex on the spanning-tree union, truncated at max_radius. Each row holds
// the settled vertices in settle order (non-decreasing distance) with their squared distance;
// row_scale_count[i * L + l] is the length of the prefix within radii[l].
void TruncatedGeodesicRows(int n, const std::vector<double>& radii, CurvatureWorkspace& ws) {
  const int num_scales = static_cast<int>(radii.size());
  const double max_radius = radii.back();
  ws.row_offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  ws.row_scale_count.resize(static_cast<std::size_t>(n) * num_scales);
  ws.row_vertex.clear();
  ws.row_dist2.clear();
  ws.dijkstra_dist.assign(n, kInf);
  ws.dijkstra_touched.clear();
  double* dist = ws.dijkstra_dist.data();
  const int* adj_offsets = ws.adj_offsets.data();
  const int* adj_targets = ws.adj_targets.data();
  const double* adj_weights = ws.adj_weights.data();
  auto& heap = ws.heap;
  const auto heap_order = std::greater<std::pair<double, int>>();

  for (int source = 0; source < n; ++source) {
    const std::size_t row_begin = ws.row_vertex.size();
    dist[source] = 0.0;
    ws.dijkstra_touched.push_back(source);
    heap.clear();
    heap.emplace_back(0.0, source);
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), heap_order);
      const auto [d, v] = heap.back();
      heap.pop_back();
      if (d > dist[v]) continue;  // stale entry
      ws.row_vertex.push_back(v);
      ws.row_dist2.push_back(d * d);
      for (int e = adj_offsets[v]; e < adj_offsets[v + 1]; ++e) {
        const int t = adj_targets[e];
        const double nd = d + adj_weights[e];
        if (nd < dist[t] && nd <= max_radius) {
          if (dist[t] == kInf) ws.dijkstra_touched.push_back(t);
          dist[t] = nd;
          heap.emplace_back(nd, t);
          std::push_heap(heap.begin(), heap.end(), heap_order);
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
    for (const int t : ws.dijkstra_touched) dist[t] = kInf;
    ws.dijkstra_touched.clear();
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
  ws.edge_weight.resize(ws.edge_a.size());
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
