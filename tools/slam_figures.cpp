#include "slam_figures.hpp"

#include "figure_file.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

namespace keyplace::cli {
void DrawTrajectoryFigure(const std::string& path, const std::string& title,
                          const std::vector<Eigen::Vector2d>& estimated,
                          const std::vector<Eigen::Vector2d>& truth,
                          const std::vector<Eigen::Vector2d>& loops_used) {
  double min_x = std::numeric_limits<double>::max(), min_y = min_x;
  double max_x = std::numeric_limits<double>::lowest(), max_y = max_x;
  for (const auto* set : {&estimated, &truth}) {
    for (const Eigen::Vector2d& p : *set) {
      min_x = std::min(min_x, p.x()), max_x = std::max(max_x, p.x());
      min_y = std::min(min_y, p.y()), max_y = std::max(max_y, p.y());
    }
  }
  if (min_x > max_x) min_x = min_y = 0.0, max_x = max_y = 1.0;
  const double margin = 40.0, top = 40.0;
  const double span = std::max({max_x - min_x, max_y - min_y, 1.0});
  const double scale = 1000.0 / span;
  const int width = static_cast<int>((max_x - min_x) * scale + 2 * margin);
  const int height = static_cast<int>((max_y - min_y) * scale + 2 * margin + top);
  auto to_px = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(margin + (p.x() - min_x) * scale,
                           top + margin + (max_y - p.y()) * scale);
  };
  WriteFigure(path, width, height, [&](cairo_t* cr) {
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);  // dark background: white discs show
    cairo_rectangle(cr, 0, top, width, height - top);
    cairo_fill(cr);
    auto dots = [&](const std::vector<Eigen::Vector2d>& points, double r, double g, double b,
                    double radius) {
      cairo_set_source_rgb(cr, r, g, b);
      for (const Eigen::Vector2d& p : points) {
        const Eigen::Vector2d q = to_px(p);
        cairo_arc(cr, q.x(), q.y(), radius, 0, 2 * M_PI);
        cairo_fill(cr);
      }
    };
    dots(truth, 0.2, 0.8, 0.2, 1.5);
    dots(estimated, 0.9, 0.15, 0.1, 1.5);
    cairo_set_line_width(cr, 1.0);
    for (const Eigen::Vector2d& p : loops_used) {
      const Eigen::Vector2d q = to_px(p);
      cairo_set_source_rgb(cr, 1, 1, 1);
      cairo_arc(cr, q.x(), q.y(), 5.0, 0, 2 * M_PI);
      cairo_fill(cr);
    }
    if (!estimated.empty()) dots({estimated.front()}, 0.2, 1.0, 0.2, 9.0);
    if (!loops_used.empty()) dots({loops_used.front()}, 0.2, 1.0, 0.2, 5.0);
    FigureText(cr, 10, 25, title);
    FigureText(
        cr, 10, height - 10.0,
        fmt::format("red: SLAM, green: ground truth, white: loops used; {:.0f} m across", span),
        12.0);
  });
}

void DrawHistogramFigure(const std::string& path, const std::string& title,
                         const std::array<std::size_t, 5>& counts) {
  const int width = 600, height = 420;
  const double left = 60, bottom = 360, top = 60, bar_w = 90;
  const std::size_t most =
      std::max<std::size_t>(1, *std::max_element(counts.begin(), counts.end()));
  static const char* kLabels[] = {"[0,10)", "[10,20)", "[20,30)", "[30,40)", "[40,100]"};
  WriteFigure(path, width, height, [&](cairo_t* cr) {
    for (std::size_t k = 0; k < counts.size(); ++k) {
      const double h = (bottom - top) * static_cast<double>(counts[k]) / most;
      cairo_set_source_rgb(cr, 0.25, 0.45, 0.8);
      cairo_rectangle(cr, left + k * (bar_w + 15), bottom - h, bar_w, h);
      cairo_fill(cr);
      FigureText(cr, left + k * (bar_w + 15) + 10, bottom + 20, kLabels[k], 13.0);
      FigureText(cr, left + k * (bar_w + 15) + 30, bottom - h - 6, std::to_string(counts[k]), 13.0);
    }
    FigureText(cr, 10, 25, title);
    FigureText(cr, left, height - 12.0, "overlap rate of matched submaps (%)", 12.0);
  });
}

void DrawCurvesFigure(const std::string& path, const std::string& title,
                      const std::vector<CurvePanel>& panels) {
  const double panel_w = 520, panel_h = 380, top = 40;
  const int width = static_cast<int>(panel_w * std::max<std::size_t>(1, panels.size()));
  const int height = static_cast<int>(panel_h + top);
  WriteFigure(path, width, height, [&](cairo_t* cr) {
    FigureText(cr, 10, 25, title);
    for (std::size_t p = 0; p < panels.size(); ++p) {
      const CurvePanel& panel = panels[p];
      const double x0 = p * panel_w + 70, x1 = (p + 1) * panel_w - 20;
      const double y0 = top + panel_h - 50, y1 = top + 20;
      auto fx = [&](double x) { return panel.log_x ? std::log10(std::max(x, 1e-12)) : x; };
      double min_x = std::numeric_limits<double>::max(),
             max_x = std::numeric_limits<double>::lowest();
      double max_y = 0.0;
      for (std::size_t i = 0; i < panel.x.size(); ++i) {
        min_x = std::min(min_x, fx(panel.x[i]));
        max_x = std::max(max_x, fx(panel.x[i]));
        max_y = std::max(max_y, panel.y[i]);
      }
      if (panel.x.empty()) min_x = 0, max_x = 1;
      if (max_x <= min_x) max_x = min_x + 1;
      if (max_y <= 0) max_y = 1;
      auto px = [&](double x, double y) {
        return Eigen::Vector2d(x0 + (fx(x) - min_x) / (max_x - min_x) * (x1 - x0),
                               y0 - y / max_y * (y0 - y1));
      };
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_set_line_width(cr, 1.0);
      cairo_move_to(cr, x0, y1);
      cairo_line_to(cr, x0, y0);
      cairo_line_to(cr, x1, y0);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0.8, 0.1, 0.1);
      cairo_set_line_width(cr, 1.5);
      for (std::size_t i = 0; i < panel.x.size(); ++i) {
        const Eigen::Vector2d q = px(panel.x[i], panel.y[i]);
        if (i == 0) {
          cairo_move_to(cr, q.x(), q.y());
        } else {
          cairo_line_to(cr, q.x(), q.y());
        }
      }
      cairo_stroke(cr);
      if (panel.x.size() <= 50) {
        for (std::size_t i = 0; i < panel.x.size(); ++i) {
          const Eigen::Vector2d q = px(panel.x[i], panel.y[i]);
          cairo_arc(cr, q.x(), q.y(), 3.0, 0, 2 * M_PI);
          cairo_fill(cr);
        }
      }
      FigureText(cr, x0 - 60, y1 - 5, fmt::format("{} (max {:.3g})", panel.y_label, max_y), 12.0);
      FigureText(cr, x0, y0 + 35,
                 fmt::format("{}{}: {:.3g} .. {:.3g}", panel.x_label, panel.log_x ? " (log)" : "",
                             panel.log_x ? std::pow(10.0, min_x) : min_x,
                             panel.log_x ? std::pow(10.0, max_x) : max_x),
                 12.0);
    }
  });
}

}  // namespace keyplace::cli
