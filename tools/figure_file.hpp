#pragma once
// Writing a cairo figure: PNG or SVG by the file's extension, to a temporary file renamed onto
// the target, so a figure is either complete or absent.

#include <cairo.h>

#include <functional>
#include <string>

namespace keyplace::cli {

/// Draws on a white width_px x height_px surface and writes it to `path`. Throws
/// std::runtime_error naming the path when it cannot be written.
void WriteFigure(const std::string& path, int width_px, int height_px,
                 const std::function<void(cairo_t*)>& draw);

/// Black sans-serif text with its baseline at (x, y).
void FigureText(cairo_t* cr, double x, double y, const std::string& text, double size = 14.0);

}  // namespace keyplace::cli
