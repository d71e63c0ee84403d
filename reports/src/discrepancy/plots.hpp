// reports/src/discrepancy/plots.hpp (internal) — small deterministic SVG plots for the
// discrepancy pages: the same data give the same bytes (numbers printed with %.6g,
// no time stamps, no random ids).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace backlash::discrepancy::detail {

/// One series of a plot: a line through (x, y), or, with `dots`, one dot per point.
/// At most ~3000 points of a line and ~2500 dots are drawn (an even stride).
struct Series {
  std::string name, color;
  const std::vector<double>* x;
  const std::vector<double>* y;
  bool dashed = false;
  bool dots = false;
};

/// A shaded stretch of the x axis.
struct Band {
  double x0, x1;
  std::string color;
};

/// "%.6g".
std::string number(double v);
std::string escape_xml(const std::string& text);

/// Lines (or dots) on common axes with ticks, a legend, optional shaded bands and dashed
/// horizontal lines (one legend entry for all of them).  NaN points are skipped (a line is
/// broken there).
std::string line_plot(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                      const std::vector<Series>& series, const std::vector<Band>& bands = {},
                      const std::vector<std::pair<double, std::string>>& hlines = {});

/// Horizontal bars with their values, and a dashed reference line.
std::string bar_chart(const std::string& title, const std::vector<std::pair<std::string, double>>& bars, double reference,
                      const std::string& reference_label);

}  // namespace backlash::discrepancy::detail
