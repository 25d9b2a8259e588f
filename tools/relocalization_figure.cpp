#include "relocalization_figure.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "figure_file.hpp"

namespace keyplace::cli {
namespace {

struct Frame {
  double min_x = 0.0, max_y = 0.0, scale = 1.0;
  double margin = 40.0, top = 40.0;
  int width = 0, height = 0;

  Eigen::Vector2d Pixel(const Eigen::Vector2d& p) const {
    return {margin + (p.x() - min_x) * scale, top + margin + (max_y - p.y()) * scale};
  }
};

Frame FrameAround(const std::vector<Eigen::Vector2d>& map_positions,
                  const std::vector<StartDrawing>& starts) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d high = Eigen::Vector2d::Constant(std::numeric_limits<double>::lowest());
  auto extend = [&](const std::vector<Eigen::Vector2d>& points) {
    for (const Eigen::Vector2d& p : points) low = low.cwiseMin(p), high = high.cwiseMax(p);
  };
  extend(map_positions);
  for (const StartDrawing& s : starts) {
    extend(s.path_to_fix);
    extend(s.correct_fixes);
    extend(s.wrong_fixes);
  }
  if (low.x() > high.x()) low.setZero(), high.setOnes();
  Frame frame;
  const double span = std::max({high.x() - low.x(), high.y() - low.y(), 1.0});
  frame.scale = 1000.0 / span;
  frame.min_x = low.x();
  frame.max_y = high.y();
  frame.width = static_cast<int>((high.x() - low.x()) * frame.scale + 2 * frame.margin);
  frame.height =
      static_cast<int>((high.y() - low.y()) * frame.scale + 2 * frame.margin + frame.top + 20.0);
  return frame;
}

void Dots(cairo_t* cr, const Frame& frame, const std::vector<Eigen::Vector2d>& points,
          double radius_px) {
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d q = frame.Pixel(p);
    cairo_new_sub_path(cr);
    cairo_arc(cr, q.x(), q.y(), radius_px, 0, 2 * M_PI);
  }
  cairo_fill(cr);
}

void Path(cairo_t* cr, const Frame& frame, const std::vector<Eigen::Vector2d>& points) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d q = frame.Pixel(points[i]);
    if (i == 0) {
      cairo_move_to(cr, q.x(), q.y());
    } else {
      cairo_line_to(cr, q.x(), q.y());
    }
  }
  cairo_stroke(cr);
}

}  // namespace

void DrawRelocalizationFigure(const std::string& path, const std::string& title,
                              const std::vector<Eigen::Vector2d>& map_positions,
                              const std::vector<StartDrawing>& starts) {
  const Frame frame = FrameAround(map_positions, starts);
  WriteFigure(path, frame.width, frame.height, [&](cairo_t* cr) {
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    Dots(cr, frame, map_positions, 1.2);
    cairo_set_line_width(cr, 1.5);
    for (const StartDrawing& start : starts) {
      cairo_set_source_rgb(cr, 0.2, 0.35, 0.85);
      Path(cr, frame, start.path_to_fix);
      cairo_set_source_rgb(cr, 0, 0, 0);
      if (!start.path_to_fix.empty()) Dots(cr, frame, {start.path_to_fix.front()}, 3.0);
      cairo_set_source_rgb(cr, 0.1, 0.65, 0.2);
      Dots(cr, frame, start.correct_fixes, 4.0);
    }
    cairo_set_source_rgb(cr, 0.9, 0.1, 0.1);  // on top: wrong fixes must show
    for (const StartDrawing& start : starts) Dots(cr, frame, start.wrong_fixes, 6.0);
    FigureText(cr, 10, 25, title);
    FigureText(cr, 10, frame.height - 10.0,
               "grey: map scans, black: starts, blue: true path to the first fix, green: "
               "correct fixes, red: wrong fixes",
               12.0);
  });
}

}  // namespace keyplace::cli
