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

// Both figures: two panels side by side under a title, two caption lines below.
constexpr double kPanelA = 10.0;           // left edge of panel (a)
constexpr double kPanelB = kPanel + 20.0;  // left edge of panel (b)
constexpr double kCaptionY = kHeader + kPanel + 20;

Surface NewFigureSurface() {
  return NewSurface(static_cast<int>(2 * kPanel + 30),
                    static_cast<int>(kHeader + kPanel + kCaption));
}

// Restricts drawing to the panel at (x0, kHeader) until the matching cairo_restore.
void ClipToPanel(cairo_t* cr, double x0) {
  cairo_save(cr);
  cairo_rectangle(cr, x0, kHeader, kPanel, kPanel);
  cairo_clip(cr);
}

struct Rgb {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
};
constexpr Rgb kBlue{0.1, 0.3, 0.9};  // scan i
constexpr Rgb kRed{0.9, 0.15, 0.1};  // scan j

void SetColour(cairo_t* cr, const Rgb& c) { cairo_set_source_rgb(cr, c.r, c.g, c.b); }

// A scan of the submap as drawn, in the submap frame.
struct ScanView {
  std::vector<Eigen::Vector2d> points;  // beam endpoints closer than 12 m
  std::vector<Eigen::Vector2d> keypoints;
  std::vector<double> scales;  // of the keypoints (m)
  Eigen::Vector2d laser;       // the laser's position
};

// A cell of G with a keypoint history.
struct HistoryCell {
  Eigen::Vector2d center;
  double stability = 0.0;
  bool stable = false;
};

using DistributionCells = std::set<std::pair<int, int>>;  // cells of D by (i, j)

// Everything Figures 6 and 7 show of the submap, in the submap frame.
struct FigureData {
  StabilityFigureSummary summary;
  double cell_m = 0.0;                     // l_g, side of the cells of G
  double distribution_cell_m = 0.0;        // side of the cells of D
  ScanView scan_i;                         // the submap's first scan
  ScanView scan_j;                         // and its last
  std::vector<Eigen::Vector2d> hit_cells;  // centres of the cells of G hit by a beam
  std::vector<HistoryCell> history;
  std::vector<Eigen::Vector2d> same_cluster;      // cells where i and j share a history cluster
  std::vector<Eigen::Vector2d> other_cluster;     // cells holding i and j in different ones
  std::vector<Eigen::Vector2d> stable_keypoints;  // positions of the keypoints of F
  DistributionCells laser_cells;                  // cells of D with laser points
  DistributionCells keypoint_cells;               // cells of D with a stable keypoint
  std::vector<Eigen::Vector2d> extent;            // what both panels of a figure fit
};

// Only the scans a submap can take: keypoints of the whole log are not needed.
LogInputs ReadSubmapScans(const std::string& log_path, std::size_t first_scan) {
  LogInputOptions options;
  options.poses = PoseSource::kCorrected;
  options.first_scan = first_scan;
  options.end_scan = first_scan + kMaxScans;
  return PrepareLogInputs(log_path, options);
}

// Scan `local` (index in `inputs`, scan 0 is the submap frame) with its keypoints.
ScanView ViewOfScan(const LogInputs& inputs, std::size_t local) {
  ScanView view;
  const LogScan& scan = inputs.log.scans[local];
  const Pose2 T = Between(inputs.poses[0], inputs.poses[local]) * scan.T_robot_laser;
  for (std::size_t b = 0; b < scan.size(); ++b) {
    if (scan.valid[b] != 0 && scan.ranges_m[b] < 12.0) view.points.push_back(T * scan.Endpoint(b));
  }
  for (const Keypoint& k : inputs.keypoints[local]) {
    view.keypoints.push_back(T * k.position_m);
    view.scales.push_back(k.scale_m);
  }
  view.laser = T.translation();
  return view;
}

// The cells of G with a history, their stability, and whether scans i and j (local indices, as
// the mapper saw them) share a cluster there.
void CollectHistory(const StabilityGrid& grid, double min_stability, int scan_i, int scan_j,
                    FigureData& data) {
  std::set<std::pair<int, int>> seen;
  for (const CellIndex& cell : grid.HitCells()) {
    const auto clusters = grid.Clusters(cell);
    if (clusters.empty() || !seen.insert({cell.i, cell.j}).second) continue;
    const double s = grid.Stability(cell);
    data.history.push_back({grid.CellCenter(cell), s, s >= min_stability});
    int cluster_i = -1, cluster_j = -1;
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      for (const GridKeypoint& k : clusters[c]) {
        if (k.scan_index == scan_i && cluster_i < 0) cluster_i = static_cast<int>(c);
        if (k.scan_index == scan_j && cluster_j < 0) cluster_j = static_cast<int>(c);
      }
    }
    if (cluster_i >= 0 && cluster_j >= 0) {
      (cluster_i == cluster_j ? data.same_cluster : data.other_cluster)
          .push_back(grid.CellCenter(cell));
    }
  }
}

// The binary histograms of D: cells with laser points and cells with a stable keypoint.
void CollectDistributionCells(FigureData& data) {
  const double d = data.distribution_cell_m;
  const auto key = [d](const Eigen::Vector2d& p) {
    return std::pair<int, int>(static_cast<int>(std::floor(p.x() / d)),
                               static_cast<int>(std::floor(p.y() / d)));
  };
  for (const Eigen::Vector2d& c : data.hit_cells) data.laser_cells.insert(key(c));
  for (const Eigen::Vector2d& k : data.stable_keypoints) data.keypoint_cells.insert(key(k));
}

StabilityFigureSummary Summarize(const std::string& log_path, std::size_t first_scan,
                                 const LogInputs& inputs, const MappingConfig& config,
                                 const Submap& submap) {
  const std::size_t j_local = submap.scan_indices.size() - 1;
  StabilityFigureSummary summary;
  summary.dataset = std::filesystem::path(log_path).filename().string();
  summary.first_scan = static_cast<int>(first_scan);
  summary.last_scan = static_cast<int>(first_scan + j_local);
  summary.scans = submap.scan_indices.size();
  summary.keypoints_first = inputs.keypoints[0].size();
  summary.keypoints_last = inputs.keypoints[j_local].size();
  summary.stable = submap.keypoints.size();
  summary.min_stability = config.min_stability;
  summary.distribution = submap.distribution;
  summary.overlap = submap.overlap;
  return summary;
}

// What the figures show of `submap`, built by a mapper whose grid is `grid` from `inputs`.
FigureData CollectFigureData(const std::string& log_path, std::size_t first_scan,
                             const LogInputs& inputs, const MappingConfig& config,
                             const StabilityGrid& grid, const Submap& submap) {
  FigureData data;
  data.summary = Summarize(log_path, first_scan, inputs, config, submap);
  data.cell_m = grid.cell_size_m();
  data.distribution_cell_m = config.distribution_cell_m;
  const std::size_t j_local = submap.scan_indices.size() - 1;
  data.scan_i = ViewOfScan(inputs, 0);
  data.scan_j = ViewOfScan(inputs, j_local);
  for (const CellIndex& cell : grid.HitCells()) data.hit_cells.push_back(grid.CellCenter(cell));
  CollectHistory(grid, config.min_stability, 0, static_cast<int>(j_local), data);
  for (const StableKeypoint& k : submap.keypoints) data.stable_keypoints.push_back(k.position_m);
  CollectDistributionCells(data);
  data.summary.history_cells = data.history.size();
  data.summary.same_cluster_cells = data.same_cluster.size();
  data.summary.other_cluster_cells = data.other_cluster.size();

  data.extent = data.scan_i.points;
  data.extent.insert(data.extent.end(), data.scan_j.points.begin(), data.scan_j.points.end());
  for (const HistoryCell& h : data.history) data.extent.push_back(h.center);
  return data;
}

// --- Drawing.

void Dots(cairo_t* cr, const std::vector<Eigen::Vector2d>& points, const View& view,
          const Rgb& colour) {
  SetColour(cr, colour);
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d q = view.Px(p);
    cairo_rectangle(cr, q.x() - 1, q.y() - 1, 2, 2);
  }
  cairo_fill(cr);
}

// Outlines of the cells centred at `centers`, at least 6 px wide.
void ClusterCells(cairo_t* cr, const View& view, const std::vector<Eigen::Vector2d>& centers,
                  double cell_m, const Rgb& colour) {
  for (const Eigen::Vector2d& c : centers) {
    SetColour(cr, colour);
    Cell(cr, view, c, std::max(cell_m, 6.0 / view.scale));
    cairo_stroke(cr);
  }
}

using Marker = void (*)(cairo_t*, const Eigen::Vector2d&, double);

// Each keypoint: its support circle (the scale) and a marker.
void ScanKeypoints(cairo_t* cr, const View& view, const ScanView& scan, const Rgb& colour,
                   Marker marker) {
  for (std::size_t k = 0; k < scan.keypoints.size(); ++k) {
    const Eigen::Vector2d q = view.Px(scan.keypoints[k]);
    cairo_set_source_rgba(cr, colour.r, colour.g, colour.b, 0.5);
    cairo_arc(cr, q.x(), q.y(), scan.scales[k] * view.scale, 0, 2 * M_PI);
    cairo_stroke(cr);
    SetColour(cr, colour);
    marker(cr, q, 6.0);
    cairo_fill(cr);
  }
}

void LaserDot(cairo_t* cr, const View& view, const Eigen::Vector2d& laser, const Rgb& colour) {
  const Eigen::Vector2d q = view.Px(laser);
  SetColour(cr, colour);
  cairo_arc(cr, q.x(), q.y(), 6.0, 0, 2 * M_PI);
  cairo_fill(cr);
}

// Figure 6 (a): scans i and j, their keypoints and the cells where both have one.
void DrawScansPanel(cairo_t* cr, const FigureData& data, const View& view) {
  ClipToPanel(cr, kPanelA);
  Dots(cr, data.scan_i.points, view, kBlue);
  Dots(cr, data.scan_j.points, view, kRed);
  cairo_set_line_width(cr, 2.0);
  ClusterCells(cr, view, data.same_cluster, data.cell_m, {0.0, 0.65, 0.2});
  ClusterCells(cr, view, data.other_cluster, data.cell_m, {0.95, 0.6, 0.0});
  cairo_set_line_width(cr, 0.8);
  ScanKeypoints(cr, view, data.scan_i, kBlue, Triangle);
  ScanKeypoints(cr, view, data.scan_j, kRed, Star);
  LaserDot(cr, view, data.scan_i.laser, kBlue);
  LaserDot(cr, view, data.scan_j.laser, kRed);
  cairo_restore(cr);
  PanelFrame(cr, kPanelA, kHeader, "(a) scans i (blue) and j (red), FLIRT keypoints");
}

// Figure 6 (b), G: hit cells grey, history cells shaded by s, stable cells outlined.
void DrawGridPanel(cairo_t* cr, const FigureData& data, const View& view) {
  ClipToPanel(cr, kPanelB);
  cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
  for (const Eigen::Vector2d& c : data.hit_cells) Cell(cr, view, c, data.cell_m);
  cairo_fill(cr);
  for (const HistoryCell& h : data.history) {
    const double t = std::clamp(h.stability, 0.0, 1.0);
    cairo_set_source_rgb(cr, 1.0 - 0.9 * t, 1.0 - 0.55 * t, 1.0 - 0.9 * t);
    Cell(cr, view, h.center, std::max(data.cell_m, 5.0 / view.scale));
    cairo_fill(cr);
  }
  cairo_set_line_width(cr, 2.0);
  cairo_set_source_rgb(cr, 0.85, 0.0, 0.0);
  for (const HistoryCell& h : data.history) {
    if (!h.stable) continue;
    Cell(cr, view, h.center, std::max(data.cell_m, 7.0 / view.scale));
    cairo_stroke(cr);
  }
  cairo_restore(cr);
  PanelFrame(cr, kPanelB, kHeader, "(b) grid G: stability s of the cells with keypoints");
}

// Figure 6: (a) two scans and their keypoints, (b) the stability grid G.
void DrawFigure6(const FigureData& data, const std::string& png) {
  const StabilityFigureSummary& summary = data.summary;
  Surface surface = NewFigureSurface();
  cairo_t* cr = cairo_create(surface.get());
  DrawText(cr, 10, 26,
           fmt::format("Figure 6 (ours): {} scans {}..{}, one submap of {} scans, l_g = {:g} m, "
                       "s_min = {:g}",
                       summary.dataset, summary.first_scan, summary.last_scan, summary.scans,
                       data.cell_m, summary.min_stability),
           15.0);
  DrawScansPanel(cr, data, FitView(data.extent, kPanelA, kHeader));
  DrawGridPanel(cr, data, FitView(data.extent, kPanelB, kHeader));
  DrawText(cr, 10, kCaptionY,
           fmt::format("(a) {} keypoints in scan i (triangles), {} in scan j (stars), circles = "
                       "scale; cells holding both: green = same history cluster ({}, \"b\"), "
                       "orange = different descriptors ({}, \"a\")",
                       summary.keypoints_first, summary.keypoints_last, data.same_cluster.size(),
                       data.other_cluster.size()),
           12.0);
  DrawText(cr, 10, kCaptionY + 20,
           fmt::format("(b) grey: cells hit by a beam; green: cells with a keypoint history ({}), "
                       "darker = higher s; red outline: s >= s_min ({} stable keypoints)",
                       data.history.size(), summary.stable),
           12.0);
  cairo_destroy(cr);
  WritePng(png, surface.get());
}

// Figure 7 (a): the occupancy grid of G with the stable keypoints circled.
void DrawOccupancyPanel(cairo_t* cr, const FigureData& data, const View& view) {
  ClipToPanel(cr, kPanelA);
  cairo_set_source_rgb(cr, 1, 1, 1);
  for (const Eigen::Vector2d& c : data.hit_cells) Cell(cr, view, c, data.cell_m);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0.95, 0.1, 0.1);
  cairo_set_line_width(cr, 2.0);
  for (const Eigen::Vector2d& k : data.stable_keypoints) {
    const Eigen::Vector2d q = view.Px(k);
    cairo_new_sub_path(cr);
    cairo_arc(cr, q.x(), q.y(), 6.0, 0, 2 * M_PI);
  }
  cairo_stroke(cr);
  cairo_restore(cr);
}

// Figure 7 (b), D: cells with laser points white, with a keypoint too red.
void DrawDistributionPanel(cairo_t* cr, const FigureData& data, const View& view) {
  const double d = data.distribution_cell_m;
  ClipToPanel(cr, kPanelB);
  for (const auto& [ci, cj] : data.laser_cells) {
    if (data.keypoint_cells.count({ci, cj}) > 0) {
      cairo_set_source_rgb(cr, 0.9, 0.1, 0.1);
    } else {
      cairo_set_source_rgb(cr, 1, 1, 1);
    }
    Cell(cr, view, {(ci + 0.5) * d, (cj + 0.5) * d}, d * 0.92);
    cairo_fill(cr);
  }
  cairo_restore(cr);
}

// Figure 7: (a) occupancy grid with the stable keypoints, (b) the binary histograms of D.
void DrawFigure7(const FigureData& data, const std::string& png) {
  Surface surface = NewFigureSurface();
  cairo_t* cr = cairo_create(surface.get());
  DrawText(cr, 10, 26,
           fmt::format("Figure 7 (ours): spatial distribution of the same submap, delta = {:.3f} "
                       "(cells of D: {:g} m)",
                       data.summary.distribution, data.distribution_cell_m),
           15.0);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, kPanelA, kHeader, kPanel, kPanel);
  cairo_rectangle(cr, kPanelB, kHeader, kPanel, kPanel);
  cairo_fill(cr);
  DrawOccupancyPanel(cr, data, FitView(data.extent, kPanelA, kHeader));
  DrawDistributionPanel(cr, data, FitView(data.extent, kPanelB, kHeader));
  DrawText(cr, 10, kCaptionY,
           fmt::format("(a) occupancy grid of G (white: cells hit by a beam) with the {} stable "
                       "keypoints circled in red",
                       data.summary.stable),
           12.0);
  DrawText(cr, 10, kCaptionY + 20,
           fmt::format("(b) binary histograms on D: {} cells with laser points, red = {} cells "
                       "with a stable keypoint too (white = laser points only)",
                       data.laser_cells.size(), data.keypoint_cells.size()),
           12.0);
  cairo_destroy(cr);
  WritePng(png, surface.get());
}

}  // namespace

StabilityFigureSummary DrawStabilityFigures(const std::string& log_path, std::size_t first_scan,
                                            const std::string& fig6_png,
                                            const std::string& fig7_png) {
  const LogInputs inputs = ReadSubmapScans(log_path, first_scan);
  const MappingConfig config;
  LocalMapper mapper(config);
  const std::optional<Submap> submap =
      BuildSubmap({inputs.log.scans, inputs.poses, inputs.keypoints}, 0, mapper);
  if (!submap) {
    throw std::invalid_argument(fmt::format("{}: no submap completes from scan {} within {} scans",
                                            log_path, first_scan, kMaxScans));
  }
  const FigureData data =
      CollectFigureData(log_path, first_scan, inputs, config, mapper.grid(), *submap);
  DrawFigure6(data, fig6_png);
  DrawFigure7(data, fig7_png);
  return data.summary;
}

}  // namespace keyplace::cli
