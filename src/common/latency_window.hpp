#pragma once
// Internal: the time a robot node spent on each of its last scans, summarised as the node status
// reports it (RelocalizationNode, SlamNode).

#include <algorithm>
#include <cstddef>
#include <deque>
#include <vector>

#include "common/quantile.hpp"

namespace keyplace {

struct LatencySummary {
  double mean_s = 0.0;
  double p99_s = 0.0;
  double max_s = 0.0;
};

/// Appends a latency, keeping the last `capacity`.
inline void AddLatency(double latency_s, std::size_t capacity, std::deque<double>& latencies_s) {
  latencies_s.push_back(latency_s);
  if (latencies_s.size() > capacity) latencies_s.pop_front();
}

/// Mean, 99th percentile and maximum; zeros for no latencies.
inline LatencySummary SummarizeLatencies(const std::deque<double>& latencies_s) {
  LatencySummary summary;
  if (latencies_s.empty()) return summary;
  const std::vector<double> latencies(latencies_s.begin(), latencies_s.end());
  double sum_s = 0.0;
  for (const double latency_s : latencies) sum_s += latency_s;
  summary.mean_s = sum_s / static_cast<double>(latencies.size());
  summary.p99_s = Quantile(latencies, 0.99);
  summary.max_s = *std::max_element(latencies.begin(), latencies.end());
  return summary;
}

}  // namespace keyplace
