#include "curvature_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>

namespace keyplace::features_internal {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Squared distances carry a few ulp of error: candidates within this relative margin of the
// current key are compared exactly.
constexpr double kGateSlack = 1.0 + kCloseRelative;

// exp(-x) for x >= 0 (0 beyond 700), within about 2 ulp of std::exp but without libm's call and
// error handling: exp(-x) = 2^-(m / 128) exp(-r), m = round(128 x / ln 2), with a 128-entry table
// of 2^-(j / 128) and a degree-5 polynomial on |r| <= ln2 / 256 (truncation error < 1e-18).
class ExpNegativeTable {
 public:
  ExpNegativeTable() {
    for (int j = 0; j < kSize; ++j) table_[j] = std::exp2(-static_cast<double>(j) / kSize);
  }
  double operator()(double x) const {
    if (!(x < 700.0)) return 0.0;  // below 1e-304: nothing at the scale of the central weight
    // x >= 0 (a squared distance over 2 sigma^2), so truncating x + 0.5 rounds to nearest.
    const std::int64_t m =
        static_cast<std::int64_t>(x * kSizeOverLn2 + 0.5);  // NOLINT(bugprone-incorrect-roundings)
    const double md = static_cast<double>(m);
    const double r = (x - md * kLn2OverSizeHi) - md * kLn2OverSizeLo;
    const double p =
        1.0 - r * (1.0 - r * (0.5 - r * (1.0 / 6.0 - r * (1.0 / 24.0 - r * (1.0 / 120.0)))));
    // 2^-(m >> 7) assembled in the exponent field (normal range for x < 700).
    const std::uint64_t bits = static_cast<std::uint64_t>(1023 - (m >> kShift)) << 52;
    double power;
    std::memcpy(&power, &bits, sizeof(power));
    return table_[m & (kSize - 1)] * p * power;
  }

 private:
  static constexpr int kShift = 7;
  static constexpr int kSize = 1 << kShift;
  static constexpr double kSizeOverLn2 = kSize / 0.693147180559945309417232121458176568;
  // ln(2) / 128 split into 32 significant bits (m * hi is exact) and the rest.
  static constexpr double kLn2OverSizeHi = 0x1.62e42feep-8;
  static constexpr double kLn2OverSizeLo = 0x1.a39ef35793c76p-40;
  double table_[kSize];
};

const ExpNegativeTable kExpNegative;

inline double ExpNegative(double x) { return kExpNegative(x); }

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

// Slow path of PrimRound (used only when two candidate edges are exactly equal at a selection):
// FLIRTLib runs Boost's prim_minimum_spanning_tree on an adjacency matrix with hypot(dx, dy)
// weights. We follow its visiting order, strict comparisons and 4-ary heap, so that exactly
// equal edge lengths -- common with centimetre ranges on regular structures -- resolve the same
// way. Keys are kept as squared distances; whenever two of them are too close for their order
// to be certain, the comparison falls back to the exact hypot values (EdgeLess). Dense O(n^2).
void PrimRoundBoostOrder(int n, CurvatureWorkspace& ws) {
  const double* x = ws.x.data();
  const double* y = ws.y.data();
  ws.prim_key2.assign(n, kInf);
  ws.prim_gate.assign(n, kInf);  // +inf: white; key2 * slack: gray; -1: black or edge removed
  ws.prim_parent.resize(n);
  for (int v = 0; v < n; ++v) ws.prim_parent[v] = v;
  double* key2 = ws.prim_key2.data();
  double* gate = ws.prim_gate.data();
  int* parent = ws.prim_parent.data();
  const PrimKeyOrder order{x, y, key2, parent};
  QuaternaryHeap<PrimKeyOrder>& heap = ws.prim_heap;
  heap.Reset(n, order);

  key2[0] = 0.0;
  gate[0] = -1.0;
  heap.Push(0);
  while (!heap.Empty()) {
    const int u = heap.Top();
    heap.Pop();
    gate[u] = -1.0;  // black
    const int removed_begin = ws.removed_offsets[u];
    const int removed_end = ws.removed_offsets[u + 1];
    ws.prim_saved_gate.clear();
    for (int r = removed_begin; r < removed_end; ++r) {
      const int t = ws.removed_targets[r];
      ws.prim_saved_gate.push_back(gate[t]);
      gate[t] = -1.0;
    }
    const double ux = x[u];
    const double uy = y[u];
    for (int v = 0; v < n; ++v) {
      const double dx = x[v] - ux;
      const double dy = y[v] - uy;
      const double d2 = dx * dx + dy * dy;
      if (!(d2 <= gate[v])) continue;  // black, removed, or clearly not shorter
      if (gate[v] == kInf) {           // white: discovered through this edge
        key2[v] = d2;
        parent[v] = u;
        gate[v] = d2 * kGateSlack;
        heap.Push(v);
      } else if (EdgeLess(x, y, u, v, d2, parent[v], v, key2[v])) {
        key2[v] = d2;
        parent[v] = u;
        gate[v] = d2 * kGateSlack;
        heap.DecreaseKey(v);
      }
    }
    for (int r = removed_begin; r < removed_end; ++r) {
      gate[ws.removed_targets[r]] = ws.prim_saved_gate[r - removed_begin];
    }
  }
}

// Fast path of PrimRound: textbook dense Prim with the not-yet-connected vertices in compact
// arrays. Keys are squared distances, compared exactly (EdgeLess) when close. As long as every
// selection has a unique minimum the result is the one of any correct Prim, in particular of
// Boost's. Returns false, with the parents unusable, when a selection meets an exact tie.
bool PrimRoundUniqueMinima(int n, CurvatureWorkspace& ws) {
  int m = n - 1;  // vertices not in the tree, at compact positions 0..m-1
  ws.prim_vertex.resize(n);
  ws.prim_position.resize(n);
  ws.prim_x.resize(n);
  ws.prim_y.resize(n);
  ws.prim_key2.assign(n, kInf);
  ws.prim_key_parent.resize(n);
  ws.prim_parent.resize(n);
  for (int v = 0; v < n; ++v) ws.prim_parent[v] = v;
  ws.prim_position[0] = -1;
  for (int v = 1; v < n; ++v) {
    ws.prim_vertex[v - 1] = v;
    ws.prim_position[v] = v - 1;
    ws.prim_x[v - 1] = ws.x[v];
    ws.prim_y[v - 1] = ws.y[v];
    ws.prim_key_parent[v - 1] = v;
  }
  const double* x = ws.x.data();
  const double* y = ws.y.data();
  int* vertex = ws.prim_vertex.data();
  double* px = ws.prim_x.data();
  double* py = ws.prim_y.data();
  double* key2 = ws.prim_key2.data();           // by compact position
  int* key_parent = ws.prim_key_parent.data();  // by compact position
  int* parent = ws.prim_parent.data();          // by vertex, set when it joins the tree

  int u = 0;
  while (m > 0) {
    const double ux = x[u];
    const double uy = y[u];
    // Edges removed from the complete graph: hide their endpoints for this step (a NaN
    // coordinate fails every comparison).
    const int removed_begin = ws.removed_offsets[u];
    const int removed_end = ws.removed_offsets[u + 1];
    for (int r = removed_begin; r < removed_end; ++r) {
      const int p = ws.prim_position[ws.removed_targets[r]];
      if (p >= 0) px[p] = kNaN;
    }
    // Relax the edges from u and select the smallest key, tracking the runner-up to detect
    // near-equal minima. Clear decisions are branch-free; near-equal keys take the exact path.
    double min1 = kInf, min2 = kInf;
    int best = -1;
    for (int p = 0; p < m; ++p) {
      const double dx = px[p] - ux;
      const double dy = py[p] - uy;
      const double d2 = dx * dx + dy * dy;
      double key = key2[p];
      const bool shorter = d2 < key * (1.0 - kCloseRelative);
      key = shorter ? d2 : key;
      key_parent[p] = shorter ? u : key_parent[p];
      if (__builtin_expect(!shorter && d2 <= key * (1.0 + kCloseRelative), 0)) {
        if (EdgeLess(x, y, u, vertex[p], d2, key_parent[p], vertex[p], key)) {
          key = d2;
          key_parent[p] = u;
        }
      }
      key2[p] = key;
      const bool smallest = key < min1;
      min2 = smallest ? min1 : (key < min2 ? key : min2);
      min1 = smallest ? key : min1;
      best = smallest ? p : best;
    }
    for (int r = removed_begin; r < removed_end; ++r) {
      const int t = ws.removed_targets[r];
      const int p = ws.prim_position[t];
      if (p >= 0) px[p] = x[t];
    }
    if (best < 0) break;  // the rest is unreachable (only in tiny point sets)
    if (min2 <= min1 * (1.0 + kCloseRelative)) {
      // Near-equal minima: order them by the exact weights; an exact tie is left to the
      // Boost-order emulation.
      const int bv = vertex[best];
      const double best_weight =
          std::hypot(x[bv] - x[key_parent[best]], y[bv] - y[key_parent[best]]);
      for (int p = 0; p < m; ++p) {
        if (p == best || !(key2[p] <= min1 * (1.0 + kCloseRelative))) continue;
        const int v = vertex[p];
        const double weight = std::hypot(x[v] - x[key_parent[p]], y[v] - y[key_parent[p]]);
        if (!(best_weight < weight)) return false;
      }
    }
    const int v = vertex[best];
    parent[v] = key_parent[best];
    // Remove `best` from the compact arrays (swap with the last).
    const int last = m - 1;
    vertex[best] = vertex[last];
    px[best] = px[last];
    py[best] = py[last];
    key2[best] = key2[last];
    key_parent[best] = key_parent[last];
    ws.prim_position[vertex[best]] = best;
    ws.prim_position[v] = -1;
    --m;
    u = v;
  }
  return true;
}

// One round of Prim's algorithm from vertex 0 on the complete Euclidean graph minus the edges
// already taken (and minus the edge (0, n-1)); appends the tree edges to the workspace edge list
// as (parent, vertex) in vertex order, like FLIRTLib.
void PrimRound(int n, CurvatureWorkspace& ws) {
  ws.edge_a.push_back(0);
  ws.edge_b.push_back(n - 1);
  BuildCsr(n, ws.edge_a, ws.edge_b, ws.removed_offsets, ws.removed_targets, ws.removed_fill);
  ws.edge_a.pop_back();
  ws.edge_b.pop_back();
  if (!PrimRoundUniqueMinima(n, ws)) {
    PrimRoundBoostOrder(n, ws);
  }
  const int* parent = ws.prim_parent.data();
  for (int v = 1; v < n; ++v) {
    if (parent[v] == v) continue;  // unreachable (only in tiny point sets)
    ws.edge_a.push_back(parent[v]);
    ws.edge_b.push_back(v);
  }
}

// Geodesic distances from every vertex on the spanning-tree union, truncated at the largest
// radius. Row i lists each vertex j > i within the radius once, with its squared distance, grouped
// by scale band: row_scale_count[i * L + l] entries first are those within radii[l].
//
// Each pair is searched once. The search from s runs on the vertices >= s only, seeded with s
// itself and with every edge (v, t) that crosses the cut (v < s <= t) at d(s, v) + w(v, t),
// where d(s, v) = d(v, s) is already known from row v. That is exact: on a shortest path from s
// to j >= s, the part after its last vertex v < s stays at or above s. The search is
// label-correcting (FIFO queue): the graph is nearly a chain and the queue order nearly follows
// the distance, so few vertices are visited twice and no heap is needed. The labels are the
// shortest-path lengths (equal to Dijkstra's up to the rounding of the sums).
//
// d(s, v) of a cut edge is looked up in row v, which keeps for that purpose its distances to the
// vertices t <= reach(v) (the highest neighbour of v: no cut edge from v goes further), sorted
// by t and read with a cursor that only moves forward as s grows. Memory is linear in n plus the
// pairs within the radius (a dense n x n table took 8 n^2 bytes: 3.2 GB for 20 000 beams).
void TruncatedGeodesicRows(int n, const std::vector<double>& radii, CurvatureWorkspace& ws) {
  const int num_scales = static_cast<int>(radii.size());
  const double max_radius = radii.back();
  double radii2[kMaxScales];
  for (int l = 0; l < num_scales; ++l) radii2[l] = radii[l] * radii[l];
  ws.row_offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  ws.row_scale_count.resize(static_cast<std::size_t>(n) * num_scales);
  ws.row_vertex.clear();
  ws.row_dist2.clear();
  ws.labels.assign(n, GeodesicLabel{0.0, -1, 0});
  ws.queue.resize(static_cast<std::size_t>(n) + 1);
  ws.touched.resize(n);
  ws.touched_band.resize(n);
  const int* adj_offsets = ws.adj_offsets.data();
  const AdjacentVertex* adjacent = ws.adjacent.data();
  // reach[v]: the highest neighbour of v (v when none is higher).
  ws.reach.resize(n);
  for (int v = 0; v < n; ++v) {
    int reach = v;
    for (int e = adj_offsets[v]; e < adj_offsets[v + 1]; ++e) {
      reach = std::max(reach, adjacent[e].vertex);
    }
    ws.reach[v] = reach;
  }
  // Row v's d(v, t) for v < t <= reach[v] within the radius, sorted by t, from ahead_offsets[v].
  ws.ahead_offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  ws.ahead_cursor.resize(n);
  ws.ahead.clear();
  GeodesicLabel* label = ws.labels.data();
  int* queue = ws.queue.data();  // ring buffer of capacity n + 1
  int* touched = ws.touched.data();
  int* touched_band = ws.touched_band.data();
  const int capacity = n + 1;
  // d(v, s) from row v (v < s; s never decreases between calls for the same v), +inf when s lies
  // beyond the radius from v.
  const auto distance_ahead = [&ws](int v, int s) {
    const int end = ws.ahead_offsets[v + 1];
    int& cursor = ws.ahead_cursor[v];
    while (cursor < end && ws.ahead[cursor].vertex < s) ++cursor;
    return cursor < end && ws.ahead[cursor].vertex == s ? ws.ahead[cursor].weight : kInf;
  };
  int band_start[kMaxScales];
  // Edges (v, t) with v < s <= t for the current s, as (v, index into adjacent).
  std::vector<std::pair<int, int>>& crossing = ws.crossing_edges;
  crossing.clear();

  for (int source = 0; source < n; ++source) {
    int num_touched = 0;
    int head = 0, tail = 0;
    label[source] = GeodesicLabel{0.0, source, 1};
    touched[num_touched++] = source;
    queue[tail++] = source;
    // Update the cut: add the edges of source - 1 going up, drop those ending below source.
    if (source > 0) {
      const int v = source - 1;
      for (int e = adj_offsets[v]; e < adj_offsets[v + 1]; ++e) {
        if (adjacent[e].vertex > v) crossing.emplace_back(v, e);
      }
      std::size_t kept = 0;
      for (const auto& edge : crossing) {
        if (adjacent[edge.second].vertex >= source) crossing[kept++] = edge;
      }
      crossing.resize(kept);
    }
    // Seeds through the vertices below source.
    for (const auto& [v, e] : crossing) {
      const double d = distance_ahead(v, source) + adjacent[e].weight;
      if (!(d <= max_radius)) continue;
      const int t = adjacent[e].vertex;
      GeodesicLabel& target = label[t];
      if (target.stamp != source) {
        target = GeodesicLabel{d, source, 1};
        touched[num_touched++] = t;
        queue[tail] = t;
        tail = tail + 1 == capacity ? 0 : tail + 1;
      } else if (d < target.dist) {
        target.dist = d;
      }
    }
    while (head != tail) {
      const int v = queue[head];
      head = head + 1 == capacity ? 0 : head + 1;
      label[v].queued = 0;
      const double d = label[v].dist;
      for (int e = adj_offsets[v]; e < adj_offsets[v + 1]; ++e) {
        const int t = adjacent[e].vertex;
        const double nd = d + adjacent[e].weight;
        if (t < source || nd > max_radius) continue;
        GeodesicLabel& target = label[t];
        if (target.stamp != source) {
          target.stamp = source;
          touched[num_touched++] = t;
        } else if (!(nd < target.dist)) {
          continue;
        }
        target.dist = nd;
        if (!target.queued) {
          target.queued = 1;
          queue[tail] = t;
          tail = tail + 1 == capacity ? 0 : tail + 1;
        }
      }
    }
    // Row: the vertices j > source, grouped by scale band (counting sort).
    int band_count[kMaxScales] = {};
    const std::size_t ahead_begin = ws.ahead.size();
    for (int k = 1; k < num_touched; ++k) {  // touched[0] is the source
      const int t = touched[k];
      const double d = label[t].dist;
      if (t <= ws.reach[source]) ws.ahead.push_back(AdjacentVertex{d, t});
      const double d2 = d * d;
      int band = 0;
      while (d2 > radii2[band]) ++band;  // d <= max_radius, so band < num_scales
      touched_band[k] = band;
      ++band_count[band];
    }
    const std::size_t row_begin = ws.row_vertex.size();
    int total = 0;
    for (int l = 0; l < num_scales; ++l) {
      band_start[l] = total;
      total += band_count[l];
      ws.row_scale_count[static_cast<std::size_t>(source) * num_scales + l] = total;
    }
    ws.row_vertex.resize(row_begin + total);
    ws.row_dist2.resize(row_begin + total);
    int* row_vertex = ws.row_vertex.data() + row_begin;
    double* row_dist2 = ws.row_dist2.data() + row_begin;
    for (int k = 1; k < num_touched; ++k) {
      const int t = touched[k];
      const int slot = band_start[touched_band[k]]++;
      row_vertex[slot] = t;
      row_dist2[slot] = label[t].dist * label[t].dist;
    }
    ws.row_offsets[source + 1] = static_cast<int>(ws.row_vertex.size());
    std::sort(ws.ahead.begin() + static_cast<std::ptrdiff_t>(ahead_begin), ws.ahead.end(),
              [](const AdjacentVertex& a, const AdjacentVertex& b) { return a.vertex < b.vertex; });
    ws.ahead_offsets[source + 1] = static_cast<int>(ws.ahead.size());
    ws.ahead_cursor[source] = ws.ahead_offsets[source];
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
  ws.tree_end.clear();
  for (int round = 0; round < params.num_trees; ++round) {
    PrimRound(n, ws);
    ws.tree_end.push_back(static_cast<int>(ws.edge_a.size()));
  }
  ws.edge_weight.resize(ws.edge_a.size());  // the same hypot values Prim compared
  for (std::size_t e = 0; e < ws.edge_a.size(); ++e) {
    ws.edge_weight[e] = std::hypot(ws.x[ws.edge_a[e]] - ws.x[ws.edge_b[e]],
                                   ws.y[ws.edge_a[e]] - ws.y[ws.edge_b[e]]);
  }
  BuildCsr(n, ws.edge_a, ws.edge_b, ws.adj_offsets, ws.adj_targets, ws.adj_fill);
  ws.adjacent.resize(ws.adj_targets.size());
  {
    std::vector<int>& fill = ws.adj_fill;
    fill.assign(ws.adj_offsets.begin(), ws.adj_offsets.end() - 1);
    for (std::size_t e = 0; e < ws.edge_a.size(); ++e) {
      ws.adjacent[fill[ws.edge_a[e]]++] = AdjacentVertex{ws.edge_weight[e], ws.edge_b[e]};
      ws.adjacent[fill[ws.edge_b[e]]++] = AdjacentVertex{ws.edge_weight[e], ws.edge_a[e]};
    }
  }

  // 2. Geodesic distances up to the largest kernel radius.
  std::vector<double> radii(num_scales);
  for (int l = 0; l < num_scales; ++l) radii[l] = params.cutoff_sigmas * params.sigmas_m[l];
  TruncatedGeodesicRows(n, radii, ws);

  // 3. Per scale: A(i) = sum_j e_ij / D_j p_j / sum_j e_ij / D_j with D_j = sum_k e_jk and
  // e_ij = exp(-d_ij^2 / (2 sigma^2)), j and k running over the vertices within the cutoff
  // (including the vertex itself, e_ii = 1). Each pair is stored once and used both ways.
  ws.kernel.resize(ws.row_vertex.size());
  ws.density.resize(n);
  ws.inv_density.resize(n);
  ws.sum_w.resize(n);
  ws.sum_wx.resize(n);
  ws.sum_wy.resize(n);
  const int* row_offsets = ws.row_offsets.data();
  const int* row_vertex = ws.row_vertex.data();
  const double* row_dist2 = ws.row_dist2.data();
  const int* row_scale_count = ws.row_scale_count.data();
  double* kernel = ws.kernel.data();
  double* density = ws.density.data();
  double* inv_density = ws.inv_density.data();
  double* sum_w = ws.sum_w.data();
  double* sum_wx = ws.sum_wx.data();
  double* sum_wy = ws.sum_wy.data();
  const double* x = ws.x.data();
  const double* y = ws.y.data();
  for (int l = 0; l < num_scales; ++l) {
    const double sigma = params.sigmas_m[l];
    const double inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
    std::fill(density, density + n, 1.0);
    for (int i = 0; i < n; ++i) {
      const int begin = row_offsets[i];
      const int end = begin + row_scale_count[static_cast<std::size_t>(i) * num_scales + l];
      double density_i = 0.0;
      for (int k = begin; k < end; ++k) {
        const double e = ExpNegative(row_dist2[k] * inv_two_sigma2);
        kernel[k] = e;
        density_i += e;
        density[row_vertex[k]] += e;
      }
      density[i] += density_i;
    }
    for (int i = 0; i < n; ++i) {
      inv_density[i] = 1.0 / density[i];
      sum_w[i] = inv_density[i];
      sum_wx[i] = inv_density[i] * x[i];
      sum_wy[i] = inv_density[i] * y[i];
    }
    for (int i = 0; i < n; ++i) {
      const int begin = row_offsets[i];
      const int end = begin + row_scale_count[static_cast<std::size_t>(i) * num_scales + l];
      const double xi = x[i];
      const double yi = y[i];
      const double inv_density_i = inv_density[i];
      double w_i = 0.0, wx_i = 0.0, wy_i = 0.0;
      for (int k = begin; k < end; ++k) {
        const int j = row_vertex[k];
        const double w_ij = kernel[k] * inv_density[j];  // weight of p_j in A(i)
        w_i += w_ij;
        wx_i += w_ij * x[j];
        wy_i += w_ij * y[j];
        const double w_ji = kernel[k] * inv_density_i;  // weight of p_i in A(j)
        sum_w[j] += w_ji;
        sum_wx[j] += w_ji * xi;
        sum_wy[j] += w_ji * yi;
      }
      sum_w[i] += w_i;
      sum_wx[i] += wx_i;
      sum_wy[i] += wy_i;
    }
    auto& ax = result.ax[l];
    auto& ay = result.ay[l];
    auto& signal = result.signal[l];
    ax.resize(n);
    ay.resize(n);
    signal.resize(n);
    const double two_over_sigma = 2.0 * (1.0 / sigma);
    for (int i = 0; i < n; ++i) {
      const double inv_sum = 1.0 / sum_w[i];
      ax[i] = sum_wx[i] * inv_sum;
      ay[i] = sum_wy[i] * inv_sum;
      const double t = two_over_sigma * std::hypot(ax[i] - x[i], ay[i] - y[i]);
      signal[i] = t * std::exp(-t);
    }
  }
}

}  // namespace keyplace::features_internal
