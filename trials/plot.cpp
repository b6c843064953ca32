// The trials' picture: success rate, failures by reason, cycle-time histogram (cairo).

#include <cairo/cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "trials/cairo_png.h"
#include "trials/judge.h"
#include "trials/tool_plot.h"
#include "trials/trials.h"

namespace costar::trials {

namespace {

std::string shorten(const std::string& s, std::size_t width) {
  return s.size() <= width ? s : "..." + s.substr(s.size() - width + 3);
}

}  // namespace

std::vector<std::filesystem::path> writePlot(const Summary& summary, const std::filesystem::path& png) {
  constexpr int kWidth = 1100;
  constexpr int kHeight = 700;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, kWidth, kHeight);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);

  const int n = static_cast<int>(summary.trials.size());
  const int ok = summary.successes();
  char line[256];
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  std::snprintf(line, sizeof line, "%s: %d of %d trials succeeded (%.1f %%)", summary.options.plan.filename().c_str(),
                ok, n, n > 0 ? 100.0 * ok / n : 0.0);
  drawText(cr, 30, 40, line, 22, true);
  std::snprintf(line, sizeof line, "scene %s, judge '%s', seeds %llu..%llu, simulated cell %s with sensor noise",
                summary.options.scene.filename().c_str(), summary.options.judge.c_str(),
                static_cast<unsigned long long>(summary.options.seed),
                static_cast<unsigned long long>(summary.options.seed + std::max(0, n - 1)),
                summary.options.workcell.c_str());
  drawText(cr, 30, 66, line, 14);

  // Left: outcomes, success first, then each failure reason.
  std::vector<std::pair<std::string, int>> bars{{"success", ok}};
  for (const auto& entry : summary.failureHistogram()) {
    bars.push_back(entry);
    if (bars.size() >= 9) {
      break;
    }
  }
  drawText(cr, 30, 110, "Outcomes", 16, true);
  const double bar_left = 30;
  const double bar_width_max = 480;
  const int most = std::max(
      1, std::max_element(bars.begin(), bars.end(), [](auto& a, auto& b) { return a.second < b.second; })->second);
  double y = 130;
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const double w = bar_width_max * bars[i].second / most;
    if (i == 0) {
      cairo_set_source_rgb(cr, 0.2, 0.6, 0.3);
    } else {
      cairo_set_source_rgb(cr, 0.8, 0.3, 0.25);
    }
    cairo_rectangle(cr, bar_left, y, std::max(w, 2.0), 22);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    std::snprintf(line, sizeof line, "%d", bars[i].second);
    drawText(cr, bar_left + std::max(w, 2.0) + 6, y + 16, line, 13, true);
    drawText(cr, bar_left, y + 38, shorten(bars[i].first, 78), 11);
    y += 58;
  }

  // Right: cycle-time histogram of the successful trials.
  std::vector<double> times;
  for (const auto& trial : summary.trials) {
    if (trial.success) {
      times.push_back(trial.cycle_time_s);
    }
  }
  const double left = 620;
  const double top = 130;
  const double width = 440;
  const double height = 380;
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  drawText(cr, left, 110, "Cycle time of successful trials (simulated s)", 16, true);
  cairo_set_line_width(cr, 1);
  cairo_move_to(cr, left, top);
  cairo_line_to(cr, left, top + height);
  cairo_line_to(cr, left + width, top + height);
  cairo_stroke(cr);
  if (!times.empty()) {
    const double lo = std::floor(*std::min_element(times.begin(), times.end()));
    const double hi = std::ceil(*std::max_element(times.begin(), times.end())) + 1e-9;
    constexpr int kBins = 20;
    std::vector<int> bins(kBins, 0);
    for (const double t : times) {
      bins[std::min(kBins - 1, static_cast<int>((t - lo) / (hi - lo) * kBins))]++;
    }
    const int tallest = std::max(1, *std::max_element(bins.begin(), bins.end()));
    for (int b = 0; b < kBins; ++b) {
      const double h = height * bins[b] / tallest;
      cairo_set_source_rgb(cr, 0.25, 0.45, 0.75);
      cairo_rectangle(cr, left + b * width / kBins + 1, top + height - h, width / kBins - 2, h);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    std::snprintf(line, sizeof line, "%.0f", lo);
    drawText(cr, left, top + height + 18, line, 12);
    std::snprintf(line, sizeof line, "%.0f", hi);
    drawText(cr, left + width - 20, top + height + 18, line, 12);
    std::snprintf(line, sizeof line, "%d", tallest);
    drawText(cr, left - 25, top + 10, line, 12);
    const auto stats = summary.cycleTimes();
    std::snprintf(line, sizeof line, "median %.1f s, 95th percentile %.1f s, mean %.1f s", stats.at("median"),
                  stats.at("p95"), stats.at("mean"));
    drawText(cr, left, top + height + 45, line, 14);
  } else {
    drawText(cr, left + 20, top + height / 2, "no successful trial", 14);
  }

  writeSurfacePng(surface, cr, png);
  std::vector<std::filesystem::path> written = {png};
  for (const TrialResult& trial : summary.trials) {
    if (trial.tool) {
      const std::filesystem::path stem = png.parent_path() / png.stem();
      written.push_back(std::filesystem::path(stem.string() + "_force.png"));
      writeForcePlot(*trial.tool, kPolishingForce, kPolishingBand, written.back());
      written.push_back(std::filesystem::path(stem.string() + "_coverage.png"));
      writeCoveragePlot(*trial.tool, written.back());
      break;
    }
  }
  return written;
}

}  // namespace costar::trials
