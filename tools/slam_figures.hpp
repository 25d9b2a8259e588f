#pragma once
// Pictures of a SLAM run (paper Figures 10-12): trajectory vs ground truth with loop positions,
// overlap histogram, RPE RMSE vs Delta, ATE vs path length (cairo, PNG or SVG by extension,
// written atomically).

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace keyplace::cli {

/// Figure 10 (left): estimated trajectory (red) over the ground truth (green), both in the truth
/// frame; white discs at the loops used, a large green disc at the start and a small one at the
/// first loop.
void DrawTrajectoryFigure(const std::string& path, const std::string& title,
                          const std::vector<Eigen::Vector2d>& estimated,
                          const std::vector<Eigen::Vector2d>& truth,
                          const std::vector<Eigen::Vector2d>& loops_used);

/// Figure 10 (right): counts in the bins [0,10), [10,20), [20,30), [30,40), [40,100] %.
void DrawHistogramFigure(const std::string& path, const std::string& title,
                         const std::array<std::size_t, 5>& counts);

/// Figures 11 and 12: one or two y series over x, drawn side by side (left: translation, right:
/// rotation), as polylines with markers.
struct CurvePanel {
  std::string x_label;
  std::string y_label;
  std::vector<double> x;
  std::vector<double> y;
  bool log_x = false;
};
void DrawCurvesFigure(const std::string& path, const std::string& title,
                      const std::vector<CurvePanel>& panels);

}  // namespace keyplace::cli
