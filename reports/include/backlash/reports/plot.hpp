// backlash/reports/plot.hpp — figures for the reports, drawn by gnuplot.
//
// A Plot is a list of series (x, y columns) with labels; `render_svg` writes
// the data and a gnuplot script to a scratch folder, runs gnuplot, and returns
// the SVG text (or nothing, with the reason, when gnuplot is missing or fails:
// the report then says so instead of failing).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace backlash::reports {

struct Series {
  std::string label;
  std::vector<double> x, y;
  std::string style = "lines";  ///< gnuplot style: "lines", "points pt 7 ps 0.5", "linespoints"
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  int width = 900, height = 600;
};

/// SVG text, or nothing (and `why`) when gnuplot is unavailable or fails.
std::optional<std::string> render_svg(const Plot& plot, std::string* why = nullptr);

/// The errata ledgers (reports/errata/*.toml) as one Markdown document.
std::string errata_markdown(const std::string& errata_directory);

}  // namespace backlash::reports
