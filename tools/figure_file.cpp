#include "figure_file.hpp"

#include <cairo-svg.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

bool IsSvg(const std::string& path) {
  return path.size() >= 4 && path.compare(path.size() - 4, 4, ".svg") == 0;
}

}  // namespace

// Creates the surface, draws, writes to a temporary file and commits it onto `path` (synced,
// renamed: io/atomic_file.hpp).
void WriteFigure(const std::string& path, int width_px, int height_px,
                 const std::function<void(cairo_t*)>& draw) {
  const std::string temporary = TemporaryPathFor(path);
  const bool svg = IsSvg(path);
  cairo_surface_t* surface =
      svg ? cairo_svg_surface_create(temporary.c_str(), width_px, height_px)
          : cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width_px, height_px);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  draw(cr);
  cairo_destroy(cr);
  cairo_status_t status = CAIRO_STATUS_SUCCESS;
  if (!svg) status = cairo_surface_write_to_png(surface, temporary.c_str());
  cairo_surface_finish(surface);
  if (status == CAIRO_STATUS_SUCCESS) status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  try {
    if (status != CAIRO_STATUS_SUCCESS) {
      throw std::runtime_error(path + ": cannot write figure: " + cairo_status_to_string(status));
    }
    CommitTemporary(temporary, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

void FigureText(cairo_t* cr, double x, double y, const std::string& text, double size) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, text.c_str());
}

}  // namespace keyplace::cli
