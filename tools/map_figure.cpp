#include "map_figure.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <fmt/core.h>

#include "figure_file.hpp"

namespace keyplace::cli {
namespace {

struct Bounds {
  double min_x = std::numeric_limits<double>::max();
  double min_y = std::numeric_limits<double>::max();
  double max_x = std::numeric_limits<double>::lowest();
  double max_y = std::numeric_limits<double>::lowest();
  void Add(const Eigen::Vector2d& p) {
    min_x = std::min(min_x, p.x());
    min_y = std::min(min_y, p.y());
    max_x = std::max(max_x, p.x());
    max_y = std::max(max_y, p.y());
  }
  bool empty() const { return min_x > max_x; }
};

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A colour per submap that neighbours can tell apart (golden-angle hue steps).
void SubmapColour(cairo_t* cr, int id) {
  const double hue = std::fmod(id * 137.508, 360.0) / 60.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(hue)) {
    case 0:
      r = 1, g = x;
      break;
    case 1:
      r = x, g = 1;
      break;
    case 2:
      g = 1, b = x;
      break;
    case 3:
      g = x, b = 1;
      break;
    case 4:
      r = x, b = 1;
      break;
    default:
      r = 1, b = x;
      break;
  }
  cairo_set_source_rgb(cr, 0.85 * r, 0.85 * g, 0.85 * b);
}

// World points of the scans that went into submaps (every other beam is plenty to look at).
std::vector<Eigen::Vector2d> MapScanPoints(const GlobalMap& map, const std::vector<LogScan>& scans,
                                           const std::vector<Pose2>& poses,
                                           std::size_t first_scan) {
  std::vector<Eigen::Vector2d> points;
  for (const Submap& submap : map.submaps) {
    for (const int file_index : submap.scan_indices) {
      const int index = file_index - static_cast<int>(first_scan);
      if (index < 0 || static_cast<std::size_t>(index) >= scans.size() ||
          static_cast<std::size_t>(index) >= poses.size()) {
        continue;
      }
      const LaserScan& scan = scans[index];
      const Pose2 T_world_laser = poses[index] * scan.T_robot_laser;
      for (std::size_t b = 0; b < scan.size(); b += 2) {
        if (scan.valid[b] == 0 || scan.ranges_m[b] > 30.0) continue;
        points.push_back(T_world_laser * scan.Endpoint(b));
      }
    }
  }
  return points;
}

// The world rectangle of the figure: scan points, submap origins and stable keypoints.
Bounds MapBounds(const GlobalMap& map, const std::vector<Eigen::Vector2d>& points) {
  Bounds bounds;
  for (const Eigen::Vector2d& point : points) bounds.Add(point);
  for (const Submap& submap : map.submaps) {
    bounds.Add(submap.origin().translation());
    for (const auto& keypoint : submap.keypoints) bounds.Add(submap.origin() * keypoint.position_m);
  }
  if (bounds.empty()) bounds.Add({0, 0});
  return bounds;
}

// Where the world goes on the figure: a header strip, then the bounds with a margin.
struct MapLayout {
  Bounds bounds;
  double margin_m = 1.0;
  double scale = 1.0;  // px per m
  int header_px = 36;
  int width_px = 0;
  int height_px = 0;

  Eigen::Vector2d Px(const Eigen::Vector2d& p) const {
    return {(p.x() - bounds.min_x + margin_m) * scale,
            header_px + (bounds.max_y + margin_m - p.y()) * scale};
  }
};

MapLayout FitMap(const Bounds& bounds, const MapFigureOptions& options) {
  MapLayout layout;
  layout.bounds = bounds;
  const double width_m = bounds.max_x - bounds.min_x + 2 * layout.margin_m;
  const double height_m = bounds.max_y - bounds.min_y + 2 * layout.margin_m;
  layout.scale = std::min(options.pixels_per_m, options.max_side_px / std::max(width_m, height_m));
  layout.width_px = static_cast<int>(std::ceil(width_m * layout.scale));
  layout.height_px = static_cast<int>(std::ceil(height_m * layout.scale)) + layout.header_px;
  return layout;
}

// Scan points, light.
void DrawScanPoints(cairo_t* cr, const MapLayout& layout,
                    const std::vector<Eigen::Vector2d>& points) {
  cairo_set_source_rgba(cr, 0.55, 0.55, 0.55, 0.35);
  const double dot = std::max(0.6, 0.03 * layout.scale);
  for (const auto& point : points) {
    const Eigen::Vector2d p = layout.Px(point);
    cairo_rectangle(cr, p.x() - dot / 2, p.y() - dot / 2, dot, dot);
  }
  cairo_fill(cr);
}

// Trajectory through the submap origins.
void DrawTrajectory(cairo_t* cr, const MapLayout& layout, const GlobalMap& map) {
  cairo_set_source_rgba(cr, 0.1, 0.1, 0.1, 0.6);
  cairo_set_line_width(cr, 1.0);
  for (std::size_t s = 0; s < map.submaps.size(); ++s) {
    const Eigen::Vector2d p = layout.Px(map.submaps[s].origin().translation());
    if (s == 0) {
      cairo_move_to(cr, p.x(), p.y());
    } else {
      cairo_line_to(cr, p.x(), p.y());
    }
  }
  cairo_stroke(cr);
}

// Stable keypoints, coloured by submap.
void DrawKeypoints(cairo_t* cr, const MapLayout& layout, const GlobalMap& map) {
  const double radius = std::max(1.5, 0.06 * layout.scale);
  for (const Submap& submap : map.submaps) {
    SubmapColour(cr, submap.id);
    for (const auto& keypoint : submap.keypoints) {
      const Eigen::Vector2d p = layout.Px(submap.origin() * keypoint.position_m);
      cairo_new_sub_path(cr);
      cairo_arc(cr, p.x(), p.y(), radius, 0, 2 * M_PI);
    }
    cairo_fill(cr);
  }
}

// Submap origins: small black triangles pointing along the robot heading.
void DrawOrigins(cairo_t* cr, const MapLayout& layout, const GlobalMap& map) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  const double scale = layout.scale;
  const double size = std::max(3.0, 0.15 * scale);
  for (const Submap& submap : map.submaps) {
    const Pose2& origin = submap.origin();
    const Eigen::Vector2d tip = layout.Px(origin * Eigen::Vector2d(size / scale, 0));
    const Eigen::Vector2d left =
        layout.Px(origin * Eigen::Vector2d(-size / scale, 0.6 * size / scale));
    const Eigen::Vector2d right =
        layout.Px(origin * Eigen::Vector2d(-size / scale, -0.6 * size / scale));
    cairo_move_to(cr, tip.x(), tip.y());
    cairo_line_to(cr, left.x(), left.y());
    cairo_line_to(cr, right.x(), right.y());
    cairo_close_path(cr);
  }
  cairo_fill(cr);
}

// Header: title and a 5 m scale bar.
void DrawHeader(cairo_t* cr, const MapLayout& layout, const GlobalMap& map,
                const std::string& title_option) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 14);
  cairo_move_to(cr, 8, 22);
  const std::string title =
      title_option.empty()
          ? fmt::format("{} submaps, {} stable keypoints", map.submaps.size(), map.KeypointCount())
          : title_option;
  cairo_show_text(cr, title.c_str());
  const double bar_px = 5.0 * layout.scale;
  cairo_set_line_width(cr, 2.0);
  cairo_move_to(cr, layout.width_px - bar_px - 10, 24);
  cairo_line_to(cr, layout.width_px - 10, 24);
  cairo_stroke(cr);
  cairo_move_to(cr, layout.width_px - bar_px - 10, 16);
  cairo_show_text(cr, "5 m");
}

}  // namespace

void DrawMapFigure(const std::string& path, const GlobalMap& map, const std::vector<LogScan>& scans,
                   const std::vector<Pose2>& poses, const MapFigureOptions& options) {
  if (!EndsWith(path, ".svg") && !EndsWith(path, ".png")) {
    throw std::invalid_argument(path + ": figure file name must end in .png or .svg");
  }
  const std::vector<Eigen::Vector2d> points = MapScanPoints(map, scans, poses, options.first_scan);
  const MapLayout layout = FitMap(MapBounds(map, points), options);

  WriteFigure(path, layout.width_px, layout.height_px, [&](cairo_t* cr) {
    DrawScanPoints(cr, layout, points);
    DrawTrajectory(cr, layout, map);
    DrawKeypoints(cr, layout, map);
    DrawOrigins(cr, layout, map);
    DrawHeader(cr, layout, map, options.title);
  });
}

}  // namespace keyplace::cli
