// Brute-force oracle for the fast detector: the spanning trees are checked against Kruskal, and
// the smoothing against a dense all-pairs computation (Floyd-Warshall on the tree union, every
// vertex pair weighted, FLIRTLib's own normalisations), on real scans of both logs.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

const CarmenLog& LoadLog(const std::string& dataset) {
  static std::map<std::string, CarmenLog> cache;
  auto it = cache.find(dataset);
  if (it == cache.end()) {
    const std::string path = testing::SharedFile("data/" + dataset + "-corrected.log.gz");
    it = cache.emplace(dataset, ReadCarmenLog(path)).first;
  }
  return it->second;
}

// The laser pose as printed in the log (see flirt_reference_test.cpp).
Pose2 LaserPose(const LogScan& scan) {
  const Pose2 pose = *scan.corrected_pose * scan.T_robot_laser;
  const auto snap = [](double value) { return std::round(value * 1e6) / 1e6; };
  return {snap(pose.x), snap(pose.y), snap(pose.theta)};
}

struct UnionFind {
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int Find(int v) { return parent[v] == v ? v : parent[v] = Find(parent[v]); }
  bool Unite(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return false;
    parent[a] = b;
    return true;
  }
  std::vector<int> parent;
};

double Length(const std::vector<Eigen::Vector2d>& p, int a, int b) {
  return std::hypot(p[a].x() - p[b].x(), p[a].y() - p[b].y());
}

// Each tree spans all vertices, avoids the edge (0, n-1) and the earlier trees, and weighs as
// much as Kruskal's minimum spanning tree of the same remaining complete graph.
void CheckSpanningTrees(const FlirtSignals& s) {
  const int n = static_cast<int>(s.vertices_m.size());
  std::vector<std::vector<bool>> removed(n, std::vector<bool>(n, false));
  removed[0][n - 1] = removed[n - 1][0] = true;
  for (const auto& tree : s.spanning_trees) {
    ASSERT_EQ(static_cast<int>(tree.size()), n - 1);
    UnionFind forest(n);
    double weight = 0.0;
    for (const auto& [a, b] : tree) {
      ASSERT_FALSE(removed[a][b]) << "edge " << a << "-" << b << " used twice";
      ASSERT_TRUE(forest.Unite(a, b)) << "cycle at " << a << "-" << b;
      weight += Length(s.vertices_m, a, b);
    }
    std::vector<std::pair<double, std::pair<int, int>>> edges;
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        if (!removed[a][b]) edges.push_back({Length(s.vertices_m, a, b), {a, b}});
      }
    }
    std::sort(edges.begin(), edges.end());
    UnionFind kruskal(n);
    double kruskal_weight = 0.0;
    for (const auto& [w, e] : edges) {
      if (kruskal.Unite(e.first, e.second)) kruskal_weight += w;
    }
    EXPECT_NEAR(weight, kruskal_weight, 1e-9 * kruskal_weight);
    for (const auto& [a, b] : tree) removed[a][b] = removed[b][a] = true;
  }
}

// FLIRTLib's smoothing, literally: all pairs, densities with the sqrt(2 pi) sigma normaliser.
void CheckSmoothing(const FlirtSignals& s) {
  const int n = static_cast<int>(s.vertices_m.size());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> d(n, std::vector<double>(n, inf));
  for (int v = 0; v < n; ++v) d[v][v] = 0.0;
  for (const auto& tree : s.spanning_trees) {
    for (const auto& [a, b] : tree) d[a][b] = d[b][a] = Length(s.vertices_m, a, b);
  }
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < n; ++i) {
      const double dik = d[i][k];
      if (dik == inf) continue;
      for (int j = 0; j < n; ++j) d[i][j] = std::min(d[i][j], dik + d[k][j]);
    }
  }
  for (std::size_t level = 0; level < s.sigma_m.size(); ++level) {
    const double sigma = s.sigma_m[level];
    const double normalizer = std::sqrt(2.0 * M_PI) * sigma;
    std::vector<std::vector<double>> w(n, std::vector<double>(n));
    std::vector<double> density(n, 0.0);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        w[i][j] = normalizer * std::exp(-d[i][j] * d[i][j] / (2.0 * sigma * sigma));
        density[i] += w[i][j];
      }
    }
    std::vector<double> signal(n);
    double max_position_error = 0.0, max_signal_error = 0.0;
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      Eigen::Vector2d a = Eigen::Vector2d::Zero();
      for (int j = 0; j < n; ++j) {
        const double weight = w[i][j] / (density[i] * density[j]);
        sum += weight;
        a += weight * s.vertices_m[j];
      }
      a /= sum;
      const double t = 2.0 / sigma * (a - s.vertices_m[i]).norm();
      signal[i] = t * std::exp(-t);
      max_position_error = std::max(max_position_error, (a - s.smoothed_m[level][i]).norm());
      max_signal_error = std::max(max_signal_error, std::fabs(signal[i] - s.signal[level][i]));
    }
    EXPECT_LT(max_position_error, 1e-9) << "scale " << level;
    EXPECT_LT(max_signal_error, 1e-9) << "scale " << level;
    std::vector<int> peaks;
    for (int v = 2; v + 2 < n; ++v) {
      if (signal[v] > 0.34 && signal[v] - signal[v - 1] > 0.001 &&
          signal[v] - signal[v + 1] > 0.001) {
        peaks.push_back(v);
      }
    }
    EXPECT_EQ(peaks, s.peak_vertices[level]) << "scale " << level;
  }
}

void CheckScans(const std::string& dataset, const std::vector<int>& scan_indices) {
  const CarmenLog& log = LoadLog(dataset);
  const FlirtExtractor fast;
  FlirtConfig untruncated_config;
  untruncated_config.kernel_cutoff_sigmas = std::numeric_limits<double>::infinity();
  const FlirtExtractor untruncated(untruncated_config);
  for (const int index : scan_indices) {
    SCOPED_TRACE(dataset + " scan " + std::to_string(index));
    const LogScan& scan = log.scans.at(index);
    const FlirtSignals signals = fast.ComputeSignals(scan, LaserPose(scan));
    ASSERT_EQ(signals.spanning_trees.size(), 3u);
    CheckSpanningTrees(signals);
    CheckSmoothing(signals);
    // Truncated kernel (default) and exact kernel give the same keypoints.
    const auto a = fast.Extract(scan, LaserPose(scan));
    const auto b = untruncated.Extract(scan, LaserPose(scan));
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].beam_index, b[k].beam_index);
      EXPECT_EQ(a[k].scale_level, b[k].scale_level);
      EXPECT_NEAR(a[k].orientation_rad, b[k].orientation_rad, 1e-9);
      EXPECT_LT(SymmetricChi2(a[k].descriptor, b[k].descriptor), 1e-12);
    }
  }
}

TEST(FlirtOracle, Fr079MatchesBruteForce) { CheckScans("fr079", {0, 25, 700, 1400}); }
TEST(FlirtOracle, IntelMatchesBruteForce) { CheckScans("intel", {0, 27, 1300, 2600}); }

}  // namespace
}  // namespace keyplace
