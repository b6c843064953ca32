#include "trials/cairo_png.h"

#include <stdexcept>

#include "core/files.h"

namespace costar::trials {

void drawText(cairo_t* cr, double x, double y, const std::string& s, double size, bool bold) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
}

void writeSurfacePng(cairo_surface_t* surface, cairo_t* cr, const std::filesystem::path& png) {
  std::string encoded;
  const cairo_status_t status = cairo_surface_write_to_png_stream(
      surface,
      [](void* closure, const unsigned char* data, unsigned int length) {
        static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
        return CAIRO_STATUS_SUCCESS;
      },
      &encoded);
  cairo_destroy(cr);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error("cannot write plot '" + png.string() + "': " + cairo_status_to_string(status));
  }
  writeOutputFile(png, encoded);
}

}  // namespace costar::trials
