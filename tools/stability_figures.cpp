#include "stability_figures.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/local_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "plot_chart.hpp"

namespace keyplace::cli {
namespace {

constexpr double kPanel = 560.0;   // side of a square panel (px)
constexpr double kHeader = 40.0;   // figure title
constexpr double kCaption = 64.0;  // legend lines under the panels
constexpr int kMaxScans = 400;     // scans read after first_scan (a submap is far shorter)

using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

// A square view of the world (submap frame) onto a panel.
struct View {
  double min_x = 0.0;
  double max_y = 0.0;
  double scale = 1.0;  // px per m
  double x0 = 0.0;     // panel origin on the surface
  double y0 = 0.0;
  Eigen::Vector2d Px(const Eigen::Vector2d& p) const {
    return {x0 + (p.x() - min_x) * scale, y0 + (max_y - p.y()) * scale};
  }
};

View FitView(const std::vector<Eigen::Vector2d>& points, double x0, double y0) {
  double min_x = std::numeric_limits<double>::max(), min_y = min_x;
  double max_x = std::numeric_limits<double>::lowest(), max_y = max_x;
  for (const Eigen::Vector2d& p : points) {
    min_x = std::min(min_x, p.x()), max_x = std::max(max_x, p.x());
    min_y = std::min(min_y, p.y()), max_y = std::max(max_y, p.y());
  }
  if (min_x > max_x) min_x = min_y = -1.0, max_x = max_y = 1.0;
  const double side = std::max({max_x - min_x, max_y - min_y, 1.0}) + 1.0;
  View view;
  view.min_x = (min_x + max_x - side) / 2;
  view.max_y = (min_y + max_y + side) / 2;
  view.scale = (kPanel - 20.0) / side;
  view.x0 = x0 + 10.0;
  view.y0 = y0 + 10.0;
  return view;
}

void Triangle(cairo_t* cr, const Eigen::Vector2d& c, double r) {
  cairo_move_to(cr, c.x(), c.y() - r);
  cairo_line_to(cr, c.x() + 0.87 * r, c.y() + 0.5 * r);
  cairo_line_to(cr, c.x() - 0.87 * r, c.y() + 0.5 * r);
  cairo_close_path(cr);
}

void Star(cairo_t* cr, const Eigen::Vector2d& c, double r) {
  for (int k = 0; k < 10; ++k) {
    const double a = -M_PI / 2 + k * M_PI / 5;
    const double rr = k % 2 == 0 ? r : 0.45 * r;
    const double x = c.x() + rr * std::cos(a);
    const double y = c.y() + rr * std::sin(a);
    if (k == 0) {
      cairo_move_to(cr, x, y);
    } else {
      cairo_line_to(cr, x, y);
    }
  }
  cairo_close_path(cr);
}

void Cell(cairo_t* cr, const View& view, const Eigen::Vector2d& center, double side_m) {
  const Eigen::Vector2d corner = view.Px(center + Eigen::Vector2d(-side_m / 2, side_m / 2));
  cairo_rectangle(cr, corner.x(), corner.y(), side_m * view.scale, side_m * view.scale);
}

void PanelFrame(cairo_t* cr, double x0, double y0, const std::string& label) {
  cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, kPanel - 1, kPanel - 1);
  cairo_stroke(cr);
  DrawText(cr, x0 + 8, y0 + 20, label, 14.0);
}

Surface NewSurface(int width, int height) {
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height),
                  &cairo_surface_destroy);
  cairo_t* cr = cairo_create(surface.get());
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_destroy(cr);
  return surface;
}

}  // namespace

StabilityFigureSummary DrawStabilityFigures(const std::string& log_path, std::size_t first_scan,
                                            const std::string& fig6_png,
                                            const std::string& fig7_png) {
  // Only the scans a submap can take: keypoints of the whole log are not needed.
  LogInputOptions options;
  options.poses = PoseSource::kCorrected;
  options.first_scan = first_scan;
  options.end_scan = first_scan + kMaxScans;
  const LogInputs inputs = PrepareLogInputs(log_path, options);
  const CarmenLog& log = inputs.log;
  const std::vector<Pose2>& poses = inputs.poses;
  const std::vector<std::vector<Keypoint>>& keypoints = inputs.keypoints;
  const MappingConfig config;
  LocalMapper mapper(config);
  const std::optional<Submap> submap = BuildSubmap({log.scans, poses, keypoints}, 0, mapper);
  if (!submap) {
    throw std::invalid_argument(fmt::format("{}: no submap completes from scan {} within {} scans",
                                            log_path, first_scan, kMaxScans));
  }
  const StabilityGrid& grid = mapper.grid();
  const double cell_m = grid.cell_size_m();
  const std::size_t i_local = 0;
  const std::size_t j_local = submap->scan_indices.size() - 1;

  StabilityFigureSummary summary;
  summary.dataset = std::filesystem::path(log_path).filename().string();
  summary.first_scan = static_cast<int>(first_scan);
  summary.last_scan = static_cast<int>(first_scan + j_local);
  summary.scans = submap->scan_indices.size();
  summary.keypoints_first = keypoints[i_local].size();
  summary.keypoints_last = keypoints[j_local].size();
  summary.stable = submap->keypoints.size();
  summary.min_stability = config.min_stability;
  summary.distribution = submap->distribution;
  summary.overlap = submap->overlap;

  // Scan points and keypoints of scans i and j in the submap frame.
  const auto laser_in_submap = [&](std::size_t local) {
    return Between(poses[0], poses[local]) * log.scans[local].T_robot_laser;
  };
  struct ScanView {
    std::vector<Eigen::Vector2d> points;
    std::vector<Eigen::Vector2d> keypoints;
    std::vector<double> scales;
  };
  const auto scan_view = [&](std::size_t local) {
    ScanView view;
    const Pose2 T = laser_in_submap(local);
    const LogScan& scan = log.scans[local];
    for (std::size_t b = 0; b < scan.size(); ++b) {
      if (scan.valid[b] != 0 && scan.ranges_m[b] < 12.0)
        view.points.push_back(T * scan.Endpoint(b));
    }
    for (const Keypoint& k : keypoints[local]) {
      view.keypoints.push_back(T * k.position_m);
      view.scales.push_back(k.scale_m);
    }
    return view;
  };
  const ScanView scan_i = scan_view(i_local);
  const ScanView scan_j = scan_view(j_local);

  // Cells with a history, their stability, and whether scans i and j share a cluster there.
  struct HistoryCell {
    Eigen::Vector2d center;
    double stability = 0.0;
    bool stable = false;
  };
  std::vector<HistoryCell> history;
  std::vector<Eigen::Vector2d> same_cluster, other_cluster;
  const int scan_i_index = static_cast<int>(i_local);  // the mapper saw local indices
  const int scan_j_index = static_cast<int>(j_local);
  std::set<std::pair<int, int>> seen;
  for (const CellIndex& cell : grid.HitCells()) {
    const auto clusters = grid.Clusters(cell);
    if (clusters.empty() || !seen.insert({cell.i, cell.j}).second) continue;
    const double s = grid.Stability(cell);
    history.push_back({grid.CellCenter(cell), s, s >= config.min_stability});
    int cluster_i = -1, cluster_j = -1;
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      for (const GridKeypoint& k : clusters[c]) {
        if (k.scan_index == scan_i_index && cluster_i < 0) cluster_i = static_cast<int>(c);
        if (k.scan_index == scan_j_index && cluster_j < 0) cluster_j = static_cast<int>(c);
      }
    }
    if (cluster_i >= 0 && cluster_j >= 0) {
      (cluster_i == cluster_j ? same_cluster : other_cluster).push_back(grid.CellCenter(cell));
    }
  }
  summary.history_cells = history.size();
  summary.same_cluster_cells = same_cluster.size();
  summary.other_cluster_cells = other_cluster.size();

  std::vector<Eigen::Vector2d> extent = scan_i.points;
  extent.insert(extent.end(), scan_j.points.begin(), scan_j.points.end());
  for (const HistoryCell& h : history) extent.push_back(h.center);

  // --- Figure 6: (a) two scans and their keypoints, (b) the stability grid G.
  {
    const int width = static_cast<int>(2 * kPanel + 30);
    const int height = static_cast<int>(kHeader + kPanel + kCaption);
    Surface surface = NewSurface(width, height);
    cairo_t* cr = cairo_create(surface.get());
    DrawText(cr, 10, 26,
             fmt::format("Figure 6 (ours): {} scans {}..{}, one submap of {} scans, l_g = {:g} m, "
                         "s_min = {:g}",
                         summary.dataset, summary.first_scan, summary.last_scan, summary.scans,
                         cell_m, config.min_stability),
             15.0);
    const double ax = 10, bx = kPanel + 20, py = kHeader;
    const View va = FitView(extent, ax, py);
    const View vb = FitView(extent, bx, py);
    // (a)
    cairo_save(cr);
    cairo_rectangle(cr, ax, py, kPanel, kPanel);
    cairo_clip(cr);
    const auto dots = [&](const std::vector<Eigen::Vector2d>& points, const View& v, double r,
                          double g, double b) {
      cairo_set_source_rgb(cr, r, g, b);
      for (const Eigen::Vector2d& p : points) {
        const Eigen::Vector2d q = v.Px(p);
        cairo_rectangle(cr, q.x() - 1, q.y() - 1, 2, 2);
      }
      cairo_fill(cr);
    };
    dots(scan_i.points, va, 0.1, 0.3, 0.9);
    dots(scan_j.points, va, 0.9, 0.15, 0.1);
    cairo_set_line_width(cr, 2.0);
    for (const Eigen::Vector2d& c : same_cluster) {
      cairo_set_source_rgb(cr, 0.0, 0.65, 0.2);
      Cell(cr, va, c, std::max(cell_m, 6.0 / va.scale));
      cairo_stroke(cr);
    }
    for (const Eigen::Vector2d& c : other_cluster) {
      cairo_set_source_rgb(cr, 0.95, 0.6, 0.0);
      Cell(cr, va, c, std::max(cell_m, 6.0 / va.scale));
      cairo_stroke(cr);
    }
    cairo_set_line_width(cr, 0.8);
    // Each keypoint: its support circle (the scale) and a marker.
    const auto draw_keypoints = [&](const ScanView& scan, double r, double g, double b,
                                    void (*marker)(cairo_t*, const Eigen::Vector2d&, double)) {
      for (std::size_t k = 0; k < scan.keypoints.size(); ++k) {
        const Eigen::Vector2d q = va.Px(scan.keypoints[k]);
        cairo_set_source_rgba(cr, r, g, b, 0.5);
        cairo_arc(cr, q.x(), q.y(), scan.scales[k] * va.scale, 0, 2 * M_PI);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, r, g, b);
        marker(cr, q, 6.0);
        cairo_fill(cr);
      }
    };
    draw_keypoints(scan_i, 0.1, 0.3, 0.9, Triangle);
    draw_keypoints(scan_j, 0.9, 0.15, 0.1, Star);
    for (const auto& [local, colour] : {std::pair{i_local, 0}, std::pair{j_local, 1}}) {
      const Eigen::Vector2d q = va.Px(laser_in_submap(local).translation());
      if (colour == 0) {
        cairo_set_source_rgb(cr, 0.1, 0.3, 0.9);
      } else {
        cairo_set_source_rgb(cr, 0.9, 0.15, 0.1);
      }
      cairo_arc(cr, q.x(), q.y(), 6.0, 0, 2 * M_PI);
      cairo_fill(cr);
    }
    cairo_restore(cr);
    PanelFrame(cr, ax, py, "(a) scans i (blue) and j (red), FLIRT keypoints");
    // (b) G: hit cells grey, history cells shaded by s, stable cells outlined.
    cairo_save(cr);
    cairo_rectangle(cr, bx, py, kPanel, kPanel);
    cairo_clip(cr);
    cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
    for (const CellIndex& cell : grid.HitCells()) Cell(cr, vb, grid.CellCenter(cell), cell_m);
    cairo_fill(cr);
    for (const HistoryCell& h : history) {
      const double t = std::clamp(h.stability, 0.0, 1.0);
      cairo_set_source_rgb(cr, 1.0 - 0.9 * t, 1.0 - 0.55 * t, 1.0 - 0.9 * t);
      Cell(cr, vb, h.center, std::max(cell_m, 5.0 / vb.scale));
      cairo_fill(cr);
    }
    cairo_set_line_width(cr, 2.0);
    cairo_set_source_rgb(cr, 0.85, 0.0, 0.0);
    for (const HistoryCell& h : history) {
      if (!h.stable) continue;
      Cell(cr, vb, h.center, std::max(cell_m, 7.0 / vb.scale));
      cairo_stroke(cr);
    }
    cairo_restore(cr);
    PanelFrame(cr, bx, py, "(b) grid G: stability s of the cells with keypoints");
    const double ly = kHeader + kPanel + 20;
    DrawText(cr, 10, ly,
             fmt::format("(a) {} keypoints in scan i (triangles), {} in scan j (stars), circles = "
                         "scale; cells holding both: green = same history cluster ({}, \"b\"), "
                         "orange = different descriptors ({}, \"a\")",
                         summary.keypoints_first, summary.keypoints_last, same_cluster.size(),
                         other_cluster.size()),
             12.0);
    DrawText(
        cr, 10, ly + 20,
        fmt::format("(b) grey: cells hit by a beam; green: cells with a keypoint history ({}), "
                    "darker = higher s; red outline: s >= s_min ({} stable keypoints)",
                    history.size(), summary.stable),
        12.0);
    cairo_destroy(cr);
    WritePng(fig6_png, surface.get());
  }

  // --- Figure 7: (a) occupancy grid with the stable keypoints, (b) the binary histograms of D.
  {
    const int width = static_cast<int>(2 * kPanel + 30);
    const int height = static_cast<int>(kHeader + kPanel + kCaption);
    Surface surface = NewSurface(width, height);
    cairo_t* cr = cairo_create(surface.get());
    DrawText(cr, 10, 26,
             fmt::format("Figure 7 (ours): spatial distribution of the same submap, delta = {:.3f} "
                         "(cells of D: {:g} m)",
                         summary.distribution, config.distribution_cell_m),
             15.0);
    const double ax = 10, bx = kPanel + 20, py = kHeader;
    const View va = FitView(extent, ax, py);
    const View vb = FitView(extent, bx, py);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, ax, py, kPanel, kPanel);
    cairo_rectangle(cr, bx, py, kPanel, kPanel);
    cairo_fill(cr);
    // (a)
    cairo_save(cr);
    cairo_rectangle(cr, ax, py, kPanel, kPanel);
    cairo_clip(cr);
    cairo_set_source_rgb(cr, 1, 1, 1);
    for (const CellIndex& cell : grid.HitCells()) Cell(cr, va, grid.CellCenter(cell), cell_m);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.95, 0.1, 0.1);
    cairo_set_line_width(cr, 2.0);
    for (const StableKeypoint& k : submap->keypoints) {
      const Eigen::Vector2d q = va.Px(k.position_m);
      cairo_new_sub_path(cr);
      cairo_arc(cr, q.x(), q.y(), 6.0, 0, 2 * M_PI);
    }
    cairo_stroke(cr);
    cairo_restore(cr);
    // (b) D: cells with laser points white, with a keypoint too red.
    const double d = config.distribution_cell_m;
    const auto key = [d](const Eigen::Vector2d& p) {
      return std::pair<int, int>(static_cast<int>(std::floor(p.x() / d)),
                                 static_cast<int>(std::floor(p.y() / d)));
    };
    std::set<std::pair<int, int>> laser_cells, keypoint_cells;
    for (const CellIndex& cell : grid.HitCells()) laser_cells.insert(key(grid.CellCenter(cell)));
    for (const StableKeypoint& k : submap->keypoints) keypoint_cells.insert(key(k.position_m));
    cairo_save(cr);
    cairo_rectangle(cr, bx, py, kPanel, kPanel);
    cairo_clip(cr);
    for (const auto& [ci, cj] : laser_cells) {
      if (keypoint_cells.count({ci, cj}) > 0) {
        cairo_set_source_rgb(cr, 0.9, 0.1, 0.1);
      } else {
        cairo_set_source_rgb(cr, 1, 1, 1);
      }
      Cell(cr, vb, {(ci + 0.5) * d, (cj + 0.5) * d}, d * 0.92);
      cairo_fill(cr);
    }
    cairo_restore(cr);
    const double ly = kHeader + kPanel + 20;
    DrawText(cr, 10, ly,
             fmt::format("(a) occupancy grid of G (white: cells hit by a beam) with the {} stable "
                         "keypoints circled in red",
                         summary.stable),
             12.0);
    DrawText(cr, 10, ly + 20,
             fmt::format("(b) binary histograms on D: {} cells with laser points, red = {} cells "
                         "with a stable keypoint too (white = laser points only)",
                         laser_cells.size(), keypoint_cells.size()),
             12.0);
    cairo_destroy(cr);
    WritePng(fig7_png, surface.get());
  }
  return summary;
}

}  // namespace keyplace::cli
