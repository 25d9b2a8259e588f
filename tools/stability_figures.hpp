#pragma once
// The stability illustrations of the paper (Figures 6 and 7), drawn from one real submap of a
// corrected log: the scans and FLIRT keypoints of two of its scans, the stability grid G with its
// scores and stable cells (Figure 6), and the occupancy grid with the stable keypoints and the
// binary 0.5 m histograms of the distribution distance delta (Figure 7).

#include <cstddef>
#include <string>

namespace keyplace::cli {

struct StabilityFigureSummary {
  std::string dataset;  // file name of the log
  int first_scan = 0;   // the submap's scans (0-based, log order)
  int last_scan = 0;
  std::size_t scans = 0;
  std::size_t keypoints_first = 0;  // FLIRT keypoints of the two scans shown (i = first, j = last)
  std::size_t keypoints_last = 0;
  std::size_t history_cells = 0;        // cells of G with a keypoint history
  std::size_t stable = 0;               // stable keypoints (cells with s >= s_min)
  std::size_t same_cluster_cells = 0;   // cells where keypoints of i and j share a cluster ("b")
  std::size_t other_cluster_cells = 0;  // cells holding keypoints of i and j in different ones
  double min_stability = 0.0;           // s_min
  double distribution = 0.0;            // delta of the submap
  double overlap = 0.0;                 // rho when completed
};

/// Builds, with the default mapping configuration and the log's corrected poses, the submap that
/// starts at scan `first_scan` of `log_path` and draws Figure 6 to `fig6_png` and Figure 7 to
/// `fig7_png` (PNG, written atomically). Throws std::invalid_argument naming the log when it has
/// no corrected poses or the submap cannot be completed from that scan.
StabilityFigureSummary DrawStabilityFigures(const std::string& log_path, std::size_t first_scan,
                                            const std::string& fig6_png,
                                            const std::string& fig7_png);

}  // namespace keyplace::cli
