#include "plot_chart.hpp"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <ostream>
#include <stdexcept>

#include <fmt/core.h>

#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

constexpr double kPanelWidth = 420.0;
constexpr double kPanelHeight = 300.0;
constexpr double kTitleHeight = 36.0;
constexpr double kLeft = 62.0;  // room for the y tick labels
constexpr double kRight = 14.0;
constexpr double kTop = 30.0;     // panel title
constexpr double kBottom = 46.0;  // x tick labels and axis label
constexpr double kLegendHeight = 20.0;

// Colour-blind friendly palette (Okabe-Ito).
constexpr std::array<std::array<double, 3>, 7> kPalette{{{0.0, 0.45, 0.70},
                                                         {0.84, 0.37, 0.0},
                                                         {0.0, 0.62, 0.45},
                                                         {0.80, 0.47, 0.65},
                                                         {0.34, 0.71, 0.91},
                                                         {0.90, 0.62, 0.0},
                                                         {0.0, 0.0, 0.0}}};

std::string TickText(double value, double step) {
  const int digits = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  if (std::abs(value) >= 1e5) return fmt::format("{:.2g}", value);
  return fmt::format("{:.{}f}", std::abs(value) < step * 1e-6 ? 0.0 : value, digits);
}

void DrawPanel(cairo_t* cr, const Chart& chart, double x0, double y0) {
  double min_x = std::numeric_limits<double>::max();
  double max_x = std::numeric_limits<double>::lowest();
  double min_y = min_x;
  double max_y = max_x;
  for (const ChartSeries& s : chart.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i])) continue;
      min_x = std::min(min_x, s.x[i]);  // the x range covers points without a y value too
      max_x = std::max(max_x, s.x[i]);
      if (!std::isfinite(s.y[i])) continue;
      min_y = std::min(min_y, s.y[i]);
      max_y = std::max(max_y, s.y[i]);
    }
  }
  const bool empty = min_x > max_x;
  if (empty) min_x = 0, max_x = 1;
  if (min_y > max_y) min_y = 0, max_y = 1;  // no y value at all
  if (min_y >= 0.0) min_y = 0.0;
  if (chart.y_min) min_y = *chart.y_min;
  if (chart.y_max) max_y = *chart.y_max;
  if (max_x <= min_x) max_x = min_x + 1.0;
  if (max_y <= min_y) max_y = min_y + (min_y == 0.0 ? 1.0 : std::abs(min_y) * 0.1);
  const std::vector<double> y_ticks = NiceTicks(min_y, max_y, 5);
  if (!chart.y_max && y_ticks.size() > 1) max_y = std::max(max_y, y_ticks.back());
  const std::vector<double> x_ticks = NiceTicks(min_x, max_x, 6);

  const double plot_left = x0 + kLeft;
  const double plot_right = x0 + kPanelWidth - kRight;
  const double plot_top = y0 + kTop + kLegendHeight;
  const double plot_bottom = y0 + kPanelHeight - kBottom;
  const auto px = [&](double x) {
    return plot_left + (x - min_x) / (max_x - min_x) * (plot_right - plot_left);
  };
  const auto py = [&](double y) {
    return plot_bottom - (y - min_y) / (max_y - min_y) * (plot_bottom - plot_top);
  };

  DrawText(cr, x0 + kPanelWidth / 2, y0 + 18, chart.title, 13.0, 0.5);
  // Grid and ticks.
  cairo_set_line_width(cr, 1.0);
  const double y_step = y_ticks.size() > 1 ? y_ticks[1] - y_ticks[0] : 1.0;
  for (const double t : y_ticks) {
    if (t < min_y - 1e-12 || t > max_y + 1e-12) continue;
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, plot_left, std::round(py(t)) + 0.5);
    cairo_line_to(cr, plot_right, std::round(py(t)) + 0.5);
    cairo_stroke(cr);
    DrawText(cr, plot_left - 6, py(t) + 4, TickText(t, y_step), 11.0, 1.0);
  }
  const double x_step = x_ticks.size() > 1 ? x_ticks[1] - x_ticks[0] : 1.0;
  for (const double t : x_ticks) {
    if (t < min_x - 1e-12 || t > max_x + 1e-12) continue;
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, std::round(px(t)) + 0.5, plot_top);
    cairo_line_to(cr, std::round(px(t)) + 0.5, plot_bottom);
    cairo_stroke(cr);
    DrawText(cr, px(t), plot_bottom + 15, TickText(t, x_step), 11.0, 0.5);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, plot_left + 0.5, plot_top + 0.5, plot_right - plot_left,
                  plot_bottom - plot_top);
  cairo_stroke(cr);
  DrawText(cr, (plot_left + plot_right) / 2, plot_bottom + 34, chart.x_label, 12.0, 0.5);
  cairo_save(cr);
  cairo_translate(cr, x0 + 14, (plot_top + plot_bottom) / 2);
  cairo_rotate(cr, -M_PI / 2);
  DrawText(cr, 0, 0, chart.y_label, 12.0, 0.5);
  cairo_restore(cr);
  if (empty)
    DrawText(cr, (plot_left + plot_right) / 2, (plot_top + plot_bottom) / 2, "no data", 14.0, 0.5);

  // Series: lines with markers, clipped to the plot.
  cairo_save(cr);
  cairo_rectangle(cr, plot_left, plot_top, plot_right - plot_left, plot_bottom - plot_top);
  cairo_clip(cr);
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const ChartSeries& s = chart.series[k];
    const auto& colour = kPalette[k % kPalette.size()];
    cairo_set_source_rgb(cr, colour[0], colour[1], colour[2]);
    cairo_set_line_width(cr, 2.0);
    bool pen_down = false;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        pen_down = false;
        continue;
      }
      if (pen_down) {
        cairo_line_to(cr, px(s.x[i]), py(s.y[i]));
      } else {
        cairo_move_to(cr, px(s.x[i]), py(s.y[i]));
      }
      pen_down = true;
    }
    cairo_stroke(cr);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      cairo_arc(cr, px(s.x[i]), py(s.y[i]), 3.0, 0, 2 * M_PI);
      cairo_fill(cr);
    }
  }
  cairo_restore(cr);

  // Legend on one line above the plot.
  double lx = plot_left;
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const auto& colour = kPalette[k % kPalette.size()];
    cairo_set_source_rgb(cr, colour[0], colour[1], colour[2]);
    cairo_rectangle(cr, lx, y0 + kTop + 4, 14, 4);
    cairo_fill(cr);
    DrawText(cr, lx + 18, y0 + kTop + 10, chart.series[k].label, 11.0);
    cairo_text_extents_t extents;
    cairo_text_extents(cr, chart.series[k].label.c_str(), &extents);
    lx += 30 + extents.x_advance;
  }
}

}  // namespace

void DrawText(cairo_t* cr, double x, double y, const std::string& text, double size, double align) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_move_to(cr, x - align * extents.x_advance, y);
  cairo_show_text(cr, text.c_str());
}

void WritePng(const std::string& path, cairo_surface_t* surface) {
  cairo_surface_flush(surface);
  WriteFileAtomically(path, [&](std::ostream& out) {
    const cairo_status_t status = cairo_surface_write_to_png_stream(
        surface,
        [](void* closure, const unsigned char* data, unsigned int length) {
          static_cast<std::ostream*>(closure)->write(reinterpret_cast<const char*>(data), length);
          return CAIRO_STATUS_SUCCESS;
        },
        &out);
    if (status != CAIRO_STATUS_SUCCESS) {
      throw std::runtime_error(std::string("cannot encode PNG: ") + cairo_status_to_string(status));
    }
  });
}

std::vector<double> NiceTicks(double low, double high, int target) {
  if (!(high > low) || target < 1) return {low};
  const double raw_step = (high - low) / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw_step)));
  double step = power;
  for (const double factor : {1.0, 2.0, 5.0, 10.0}) {
    step = factor * power;
    if (step >= raw_step) break;
  }
  std::vector<double> ticks;
  const auto first = static_cast<long long>(std::floor(low / step + 1e-9));
  for (long long k = first;
       static_cast<double>(k) * step <= high + step * 1e-9 && ticks.size() < 1000; ++k) {
    ticks.push_back(static_cast<double>(k) * step);  // multiples of step: no accumulated error
  }
  if (ticks.empty() || ticks.back() < high - step * 1e-9) {
    ticks.push_back(static_cast<double>(first + static_cast<long long>(ticks.size())) * step);
  }
  return ticks;
}

void DrawCharts(const std::string& path, const std::string& title, const std::vector<Chart>& charts,
                int columns) {
  for (const Chart& chart : charts) {
    for (const ChartSeries& s : chart.series) {
      if (s.x.size() != s.y.size()) {
        throw std::invalid_argument(fmt::format("{}: chart '{}', series '{}': {} x but {} y values",
                                                path, chart.title, s.label, s.x.size(),
                                                s.y.size()));
      }
    }
  }
  columns = std::max(
      1, std::min<int>(columns, static_cast<int>(std::max<std::size_t>(1, charts.size()))));
  const int rows = static_cast<int>((charts.size() + columns - 1) / columns);
  const int width = static_cast<int>(kPanelWidth * columns);
  const int height = static_cast<int>(kTitleHeight + kPanelHeight * std::max(1, rows));
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> owner(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), &cairo_surface_destroy);
  cairo_surface_t* surface = owner.get();
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  DrawText(cr, 10, 24, title, 15.0);
  for (std::size_t k = 0; k < charts.size(); ++k) {
    const double x0 = kPanelWidth * static_cast<double>(k % static_cast<std::size_t>(columns));
    const std::size_t row = k / static_cast<std::size_t>(columns);
    const double y0 = kTitleHeight + kPanelHeight * static_cast<double>(row);
    DrawPanel(cr, charts[k], x0, y0);
  }
  cairo_destroy(cr);
  WritePng(path, surface);
}

}  // namespace keyplace::cli
