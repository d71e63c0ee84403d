// The discrepancy pages' figures, drawn through the one plotting route (reports/plot.hpp:
// gnuplot), as SVG in memory.
#include "plots.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace backlash::discrepancy::detail {

using reports::literal;
using reports::Plot;

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

namespace {

// "#rgb" as "#rrggbb" (gnuplot reads the long form only); with `alpha` (0 … 1, opaque at 1)
// gnuplot's "#aarrggbb", where aa is the transparency.
std::string gnuplot_colour(const std::string& colour, double alpha = 1) {
  std::string hex = colour.empty() ? std::string() : colour.substr(1);
  if (hex.size() == 3) hex = {hex[0], hex[0], hex[1], hex[1], hex[2], hex[2]};
  std::string out = "#";
  if (alpha < 1) {
    char transparency[3];
    std::snprintf(transparency, sizeof transparency, "%02X", static_cast<unsigned>(std::lround((1 - alpha) * 255)));
    out += transparency;
  }
  out += hex;
  return out;
}

// One curve as a series: at most ~2500 dots or ~3000 points of a line (an even stride).
reports::Series series(const Curve& c) {
  reports::Series s;
  s.label = literal(c.name);
  const std::size_t n = std::min(c.x->size(), c.y->size());
  const std::size_t stride = std::max<std::size_t>(1, n / (c.dots ? 2500 : 3000));
  for (std::size_t i = 0; i < n; i += stride) {
    s.x.push_back((*c.x)[i]);
    s.y.push_back((*c.y)[i]);
  }
  s.style = c.dots ? "points pt 7 ps 0.3 lc rgb '" + gnuplot_colour(c.colour, 0.45) + "'"
                   : "lines lw 1.4" + std::string(c.dashed ? " dt 2" : "") + " lc rgb '" + gnuplot_colour(c.colour) + "'";
  return s;
}

// The finite extent of the points of every curve: {x0, x1, y0, y1}, or nothing.
std::optional<std::array<double, 4>> extent(const std::vector<Curve>& curves) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const Curve& c : curves)
    for (std::size_t i = 0; i < c.x->size() && i < c.y->size(); ++i) {
      if (!std::isfinite((*c.x)[i]) || !std::isfinite((*c.y)[i])) continue;
      x0 = std::min(x0, (*c.x)[i]), x1 = std::max(x1, (*c.x)[i]);
      y0 = std::min(y0, (*c.y)[i]), y1 = std::max(y1, (*c.y)[i]);
    }
  if (!(x0 <= x1)) return std::nullopt;
  return std::array<double, 4>{x0, x1, y0, y1};
}

}  // namespace

Plot line_plot(const std::string& name, const std::string& title, const std::string& xlabel, const std::string& ylabel,
               const std::vector<Curve>& curves, const std::vector<Band>& bands,
               const std::vector<std::pair<double, std::string>>& hlines) {
  Plot plot;
  plot.name = name, plot.title = literal(title), plot.x_label = literal(xlabel), plot.y_label = literal(ylabel);
  plot.width = 1000, plot.height = 480;
  const auto box = extent(curves);
  if (!box) {  // nothing finite: empty axes (gnuplot cannot autoscale on no points)
    plot.x_range = {0.0, 1.0}, plot.y_range = {0.0, 1.0};
    return plot;
  }
  const double x0 = (*box)[0], x1 = (*box)[1] > x0 ? (*box)[1] : x0 + 1;
  plot.x_range = {x0, x1};
  for (const Band& b : bands)
    if (std::min(b.x1, x1) > std::max(b.x0, x0)) plot.shades.push_back({std::max(b.x0, x0), std::min(b.x1, x1), gnuplot_colour(b.colour), 0.18});
  for (const Curve& c : curves) plot.series.push_back(series(c));
  for (std::size_t k = 0; k < hlines.size(); ++k) {  // one legend entry for all of them
    reports::Series line{literal(hlines.front().second), {x0, x1}, {hlines[k].first, hlines[k].first}, "lines lw 1 dt 3 lc rgb '#888888'"};
    line.in_key = k == 0;
    plot.series.push_back(line);
  }
  return plot;
}

Plot bar_chart(const std::string& name, const std::string& title, const std::vector<std::pair<std::string, double>>& bars,
               double reference, const std::string& reference_label) {
  Plot plot;
  plot.name = name, plot.title = literal(title), plot.x_label = "", plot.y_label = "";
  plot.width = 1000, plot.height = std::max(300, 130 + 34 * static_cast<int>(bars.size()));
  reports::Bars b;
  double hi = reference;
  for (const auto& [effect, value] : bars) {
    b.names.push_back(effect);
    b.values.push_back(value);
    if (std::isfinite(value)) hi = std::max(hi, value);
  }
  plot.bars = b;
  plot.x_range = {0.0, std::isfinite(hi) && hi > 0 ? 1.12 * hi : 1.0};
  const double rows = static_cast<double>(bars.size());
  plot.series.push_back({literal(reference_label), {reference, reference}, {-0.6, rows - 0.4}, "lines lw 1.5 dt 2 lc rgb '#cc3333'"});
  return plot;
}

std::optional<std::string> add_figures(const std::vector<Plot>& figures, std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> svgs;
  if (const auto why = reports::render_svgs(figures, svgs)) return "The figures were not drawn: " + *why + ".";
  for (std::size_t f = 0; f < figures.size(); ++f) files.push_back({figures[f].name + ".svg", std::move(svgs[f])});
  return std::nullopt;
}

}  // namespace backlash::discrepancy::detail
