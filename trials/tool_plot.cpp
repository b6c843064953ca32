// Pictures of a polishing trial (cairo): force over time, coverage map.

#include "trials/tool_plot.h"

#include <cairo/cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "trials/cairo_png.h"

namespace costar::trials {

namespace {

std::string formatted(const char* pattern, double value) {
  char line[128];
  std::snprintf(line, sizeof line, pattern, value);
  return line;
}

}  // namespace

void writeForcePlot(const ToolTrace& trace, double force, double band, const std::filesystem::path& png) {
  constexpr int kWidth = 1200;
  constexpr int kHeight = 560;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, kWidth, kHeight);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  const double left = 70;
  const double top = 90;
  const double width = kWidth - left - 40;
  const double height = 330;
  const double t_start = trace.log.empty() ? 0.0 : std::floor(trace.log.front().time);
  const double t_end = trace.log.empty() ? 1.0 : std::max(t_start + 1.0, trace.log.back().time);
  double f_max = force + band + 4.0;
  for (const auto& sample : trace.log) {
    f_max = std::max(f_max, sample.pad_force);
  }
  f_max = std::ceil(f_max / 5.0) * 5.0;
  const auto x = [&](double t) { return left + width * (t - t_start) / (t_end - t_start); };
  const auto y = [&](double f) { return top + height * (1.0 - f / f_max); };

  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  std::string title = trace.title;
  if (const std::size_t at = title.find("SEED"); at != std::string::npos) {
    title.replace(at, 4, std::to_string(trace.seed));
  }
  drawText(cr, left, 34, title, 20, true);
  drawText(cr, left, 58,
           formatted("true contact force, 100 Hz; green band: %.0f", force) + formatted(" +/- %.0f N (", band) +
               trace.band_note + "); " + "orange: the tool on; grey: the tool in the gripper; red: taken away",
           13);
  // Strips under the plot: tool in the gripper, tool on, tool away.
  const double strip = top + height + 30;
  for (std::size_t i = 1; i < trace.log.size(); ++i) {
    const auto& a = trace.log[i - 1];
    const double x0 = x(a.time);
    const double x1 = x(trace.log[i].time);
    if (a.held) {
      cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
      cairo_rectangle(cr, x0, strip, x1 - x0 + 0.5, 12);
      cairo_fill(cr);
    }
    if (a.powered) {
      cairo_set_source_rgb(cr, 0.95, 0.55, 0.15);
      cairo_rectangle(cr, x0, strip + 16, x1 - x0 + 0.5, 12);
      cairo_fill(cr);
    }
    if (a.away) {
      cairo_set_source_rgb(cr, 0.85, 0.2, 0.2);
      cairo_rectangle(cr, x0, strip + 32, x1 - x0 + 0.5, 12);
      cairo_fill(cr);
    }
  }
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  drawText(cr, 8, strip + 11, "held", 11);
  drawText(cr, 8, strip + 27, "on", 11);
  drawText(cr, 8, strip + 43, "away", 11);
  // The band and the axes.
  cairo_set_source_rgba(cr, 0.2, 0.7, 0.3, 0.25);
  cairo_rectangle(cr, left, y(force + band), width, y(force - band) - y(force + band));
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
  cairo_set_line_width(cr, 1);
  cairo_move_to(cr, left, top);
  cairo_line_to(cr, left, top + height);
  cairo_line_to(cr, left + width, top + height);
  cairo_stroke(cr);
  for (double f = 0; f <= f_max + 1e-9; f += 5.0) {
    drawText(cr, left - 30, y(f) + 4, formatted("%.0f", f), 11);
  }
  const double span = t_end - t_start;
  const double t_step = span > 60 ? 10.0 : span > 10 ? 5.0 : span > 5 ? 1.0 : 0.5;
  for (double t = t_start; t <= t_end + 1e-9; t += t_step) {
    drawText(cr, x(t) - 8, top + height + 16, formatted(t_step < 1.0 ? "%.1f" : "%.0f", t), 11);
  }
  drawText(cr, left + width - 150, top + height + 80, "simulated time (s)", 12);
  drawText(cr, 8, top - 10, "force (N)", 12);
  // The force.
  cairo_set_source_rgb(cr, 0.15, 0.3, 0.7);
  cairo_set_line_width(cr, 1.2);
  bool drawing = false;
  for (const auto& sample : trace.log) {
    if (sample.pad_force <= 0.0) {
      drawing = false;
      continue;
    }
    if (drawing) {
      cairo_line_to(cr, x(sample.time), y(sample.pad_force));
    } else {
      cairo_move_to(cr, x(sample.time), y(sample.pad_force));
      drawing = true;
    }
  }
  cairo_stroke(cr);
  double line_y = strip + 70;
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  for (const std::string& event : trace.disturbances) {
    drawText(cr, left, line_y, event, 12);
    line_y += 16;
  }
  writeSurfacePng(surface, cr, png);
}

void writeCoveragePlot(const ToolTrace& trace, const std::filesystem::path& png) {
  if (!trace.coverage) {
    throw std::runtime_error("cannot write plot '" + png.string() + "': the trial had no workpiece");
  }
  const sim::Coverage& coverage = *trace.coverage;
  constexpr int kScale = 6;  // pixels a texel
  const int map_width = coverage.columns * kScale;
  const int map_height = coverage.rows * kScale;
  const int width = 2 * map_width + 170;
  const int height = map_height + 170;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  drawText(cr, 30, 34, "Polishing: the marked area, texel by texel (seed " + std::to_string(trace.seed) + ")", 18,
           true);
  drawText(cr, 30, 56,
           formatted("%.0f", coverage.marked.x() * 100) + formatted(" x %.0f cm, ", coverage.marked.y() * 100) +
               formatted("%.0f mm texels; worked: ", coverage.texel * 1000) +
               formatted("%.1f %% (red: not worked)", 100.0 * coverage.fraction()),
           13);
  float most_time = 0.0F;
  float most_force = 0.0F;
  for (std::size_t i = 0; i < coverage.worked_seconds.size(); ++i) {
    most_time = std::max(most_time, coverage.worked_seconds[i]);
    most_force = std::max(most_force, coverage.max_force[i]);
  }
  const auto draw = [&](int left, const std::vector<float>& values, float most, const std::string& title,
                        const std::string& unit) {
    const int top = 90;
    drawText(cr, left, top - 10, title, 14, true);
    for (int row = 0; row < coverage.rows; ++row) {
      for (int column = 0; column < coverage.columns; ++column) {
        const auto index = static_cast<std::size_t>(row * coverage.columns + column);
        const double value = most > 0 ? values[index] / most : 0.0;
        if (coverage.worked_seconds[index] < 0.05F) {
          cairo_set_source_rgb(cr, 0.9, 0.25, 0.2);
        } else {
          cairo_set_source_rgb(cr, 1.0 - 0.8 * value, 1.0 - 0.6 * value, 1.0 - 0.2 * value);
        }
        // Row 0 is at -y of the workpiece: drawn at the bottom.
        cairo_rectangle(cr, left + column * kScale, top + (coverage.rows - 1 - row) * kScale, kScale, kScale);
        cairo_fill(cr);
      }
    }
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    drawText(cr, left, top + map_height + 20,
             "0" + unit + " (white) to " + formatted("%.1f", most) + unit + " (dark blue)", 12);
    drawText(cr, left, top + map_height + 38, "x along the workpiece to the right, y up", 12);
  };
  draw(30, coverage.worked_seconds, most_time, "time worked", " s");
  draw(60 + map_width, coverage.max_force, most_force, "largest force it was worked with", " N");
  writeSurfacePng(surface, cr, png);
}

}  // namespace costar::trials
