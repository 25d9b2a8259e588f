#pragma once
// Line charts with axes, ticks and a legend, several panels to one PNG (cairo). Used by the
// report's sweep figures (paper Figures 8 and 9).

#include <cairo.h>

#include <optional>
#include <string>
#include <vector>

namespace keyplace::cli {

struct ChartSeries {
  std::string label;  // legend text
  std::vector<double> x;
  std::vector<double> y;  // same length as x; NaN = no point
};

struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<ChartSeries> series;
  std::optional<double> y_min;  // fixed range; default: from the data (and 0 when all >= 0)
  std::optional<double> y_max;
};

/// Draws `charts` as panels in rows of `columns` under `title` and writes a PNG to `path`
/// (atomically). Throws std::invalid_argument for a series whose x and y differ in length and
/// std::runtime_error when the file cannot be written.
void DrawCharts(const std::string& path, const std::string& title, const std::vector<Chart>& charts,
                int columns);

/// Black sans-serif text with its baseline at y; `align` 0 = left, 0.5 = centred, 1 = right.
void DrawText(cairo_t* cr, double x, double y, const std::string& text, double size,
              double align = 0.0);

/// Encodes an image surface as PNG and writes it to `path` atomically; throws std::runtime_error
/// naming the path on failure.
void WritePng(const std::string& path, cairo_surface_t* surface);

/// "Nice" tick values covering [low, high]: steps of 1, 2 or 5 times a power of ten, about
/// `target` of them. Exposed for tests.
std::vector<double> NiceTicks(double low, double high, int target);

}  // namespace keyplace::cli
