// What the trials' plots share (cairo, private to trials/): text, and writing a finished
// picture checked.

#pragma once

#include <cairo/cairo.h>

#include <filesystem>
#include <string>

namespace costar::trials {

/// Draws `s` with its baseline starting at (x, y).
void drawText(cairo_t* cr, double x, double y, const std::string& s, double size, bool bold = false);

/// Encodes the surface as PNG in memory and writes it checked (core/files.h: a full disk or a
/// pipe nobody reads is named as such, a file is replaced whole); frees `cr` and `surface`.
/// @throws std::runtime_error naming `png` and the problem.
void writeSurfacePng(cairo_surface_t* surface, cairo_t* cr, const std::filesystem::path& png);

}  // namespace costar::trials
