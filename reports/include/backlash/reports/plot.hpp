// backlash/reports/plot.hpp — figures for the reports, drawn by gnuplot.
//
// The one plotting route of the project: the report's figures, the map figures and the
// discrepancy pages' figures are all Plots drawn by gnuplot.
//
// A Plot is a list of series (x, y columns; a NaN breaks a line; lines, dashed lines or
// points by the series' gnuplot style) with labels, axis titles (with units) and a legend,
// optionally over a heat map (filled cells coloured by a value, with a colour bar), over
// shaded stretches of the x axis, with horizontal bars (a bar chart: one named row per
// bar), and on logarithmic axes.  render_figures() writes one gnuplot script with every
// figure as inline data blocks and runs gnuplot once in the output folder: figures/NAME.svg
// (for the web pages) and figures/NAME.pdf (vector, for report.pdf; cairo's time stamp is
// replaced by the epoch, so the bytes are the same from run to run).  render_svgs() draws
// the SVGs only and returns them in memory (gnuplot runs in a temporary folder, removed
// afterwards): for pages that return their files by name (the discrepancy pages).
// figure_csv() gives each figure's data (series,x,y) so a reader, and the tests,
// can check what was drawn.  Without gnuplot nothing is drawn and the reason
// is returned: the page or report says so instead of failing.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace backlash::reports {

struct Series {
  std::string label;
  std::vector<double> x, y;
  /// gnuplot "with" clause: "lines lw 2", "points pt 7 ps 0.6", "lines dt 2" …
  std::string style = "lines lw 2";
  bool in_key = true;  ///< shown in the legend
};

struct Label {
  std::string text;
  double x = 0, y = 0;
};

/// A heat map drawn under the series: one filled cell [x_low, x_high] × [y_low, y_high]
/// per entry, coloured by `value` (a NaN value leaves its cell blank), with a colour bar
/// titled `colour_label` (with units).  The cells need not be uniform (log axes).
///
/// How it is drawn: as an image (gnuplot's `with image`, one pixel per cell: a PNG in the
/// SVG, drawn with sharp pixels, an uninterpolated image in the PDF — a small fraction of
/// the time and bytes of a box per cell) where that is exact: both axes linear, and the
/// cells with a value form a uniform grid of at least 2 × 2 cells from their smallest low
/// to their largest high edge (every edge within 1e-6 of a cell of the grid's), no cell
/// twice, the cells with a value at least a quarter of the grid (a grid position without
/// one is a transparent pixel: blank, as a cell without a box).  Otherwise one filled box
/// per cell with a value (gnuplot's `boxxyerror`): non-uniform cells, log axes (gnuplot
/// places an image's pixels linearly), a single row or column, a sparse grid.
struct HeatMap {
  std::vector<double> x_low, x_high, y_low, y_high, value;
  std::string colour_label;
  std::optional<std::pair<double, double>> value_range;  ///< the colour bar's; default: the values'
};

/// A shaded stretch [x_low, x_high] of the x axis, the full height of the graph, drawn behind
/// everything (e.g. the free-flight intervals of a residual plot).
struct Shade {
  double x_low = 0, x_high = 0;
  std::string colour = "#f0a030";  ///< "#rrggbb"
  double opacity = 0.18;           ///< 0 transparent … 1 opaque
};

/// Horizontal bars from 0 to each value, one row per bar (the first at the top), each row
/// named on the y axis and its value written at the bar's end ("failed" for a NaN, drawn
/// as an empty bar).  The x axis starts at 0; draw reference lines as series.
struct Bars {
  std::vector<std::string> names;  ///< one per row, shown literally
  std::vector<double> values;
  std::string colour = "#4a78b5";
};

struct Plot {
  std::string name;                ///< file stem under figures/, e.g. "fig21_case_V_phase_plane"
  std::string title;               ///< names the thesis figure
  std::string x_label, y_label;    ///< with units
  std::vector<Series> series;
  std::vector<Label> labels;
  std::optional<std::pair<double, double>> x_range, y_range;
  std::string key = "outside right top";
  int width = 1000, height = 650;  ///< SVG size in pixels; the PDF is drawn at 130 px per inch
  std::optional<HeatMap> heat_map;  ///< drawn first, under the series
  bool x_log = false, y_log = false;  ///< logarithmic axes
  std::vector<Shade> shades;          ///< drawn behind everything
  std::optional<Bars> bars;           ///< a bar chart (rows at y = 0, 1, …; y axis reversed, named)
};

/// Draws every plot into `directory`/figures (NAME.svg, NAME.pdf).  Returns the reason
/// when nothing could be drawn (gnuplot missing or failing), else nothing.
std::optional<std::string> render_figures(const std::vector<Plot>& plots, const std::filesystem::path& directory);

/// Draws every plot as SVG only (the same bytes as render_figures' NAME.svg) and returns them
/// in memory: `svgs[i]` is plots[i]'s.  gnuplot works in a fresh temporary folder, removed
/// afterwards.  Returns the reason when nothing could be drawn (gnuplot missing or failing;
/// `svgs` is then empty), else nothing.  The plots' names must differ.
std::optional<std::string> render_svgs(const std::vector<Plot>& plots, std::vector<std::string>& svgs);

/// `text` shown literally in gnuplot's enhanced mode (_ ^ { } @ & ~ \ escaped): for names
/// such as "coulomb_load" in titles, keys and labels.
std::string literal(const std::string& text);

/// The figure's data as CSV: series,x,y (one row per finite point).
std::string figure_csv(const Plot& plot);

/// True when every series has at least one finite point.
bool has_data(const Plot& plot);

}  // namespace backlash::reports
