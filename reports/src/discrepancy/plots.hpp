// reports/src/discrepancy/plots.hpp (internal) — the discrepancy pages' figures as Plots
// (backlash/reports/plot.hpp: the project's one plotting route, gnuplot), drawn as SVG in
// memory so the pages can return their files by name.  The same data give the same bytes.
// Without gnuplot no figure is drawn and the page says why (the rule of the report and
// the map figures: say so instead of failing).
#pragma once

#include "backlash/reports/plot.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace backlash::discrepancy::detail {

/// One curve of a figure: a line through (x, y) (dashed with `dashed`), or with `dots` one
/// translucent dot per point.  At most ~3000 points of a line and ~2500 dots are drawn (an
/// even stride).  `colour`: "#rgb" or "#rrggbb".
struct Curve {
  std::string name, colour;
  const std::vector<double>* x;
  const std::vector<double>* y;
  bool dashed = false;
  bool dots = false;
};

/// A shaded stretch [x0, x1] of the x axis.
struct Band {
  double x0, x1;
  std::string colour;
};

/// "%.6g".
std::string number(double v);

/// Figure `name` (the file NAME.svg): the curves on common axes over the curves' x extent,
/// a legend, the bands shaded behind them and dashed grey horizontal lines at `hlines`'s
/// values (one legend entry, the first one's label).  NaN points are skipped (a line is
/// broken there).
reports::Plot line_plot(const std::string& name, const std::string& title, const std::string& xlabel,
                        const std::string& ylabel, const std::vector<Curve>& curves, const std::vector<Band>& bands = {},
                        const std::vector<std::pair<double, std::string>>& hlines = {});

/// Figure `name`: horizontal bars with their values (the first at the top), and a dashed
/// red vertical reference line at `reference` labelled in the legend.
reports::Plot bar_chart(const std::string& name, const std::string& title, const std::vector<std::pair<std::string, double>>& bars,
                        double reference, const std::string& reference_label);

/// Draws the figures (SVG, in memory) and adds each as {NAME.svg, svg} to `files`.  Returns
/// the page's note when nothing was drawn ("The figures were not drawn: gnuplot is not
/// installed."), else nothing.
std::optional<std::string> add_figures(const std::vector<reports::Plot>& figures,
                                       std::vector<std::pair<std::string, std::string>>& files);

}  // namespace backlash::discrepancy::detail
