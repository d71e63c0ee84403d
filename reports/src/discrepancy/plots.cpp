// Small deterministic SVG plots for the discrepancy pages (the same data give the same bytes).
#include "plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace backlash::discrepancy::detail {

// ------------------------------------------------------------------ a small SVG line plot

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

std::string escape_xml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// "Nice" tick values covering [lo, hi].
static std::vector<double> ticks(double lo, double hi) {
  const double span = hi - lo, raw = span / 5, magnitude = std::pow(10, std::floor(std::log10(raw)));
  const double step = raw / magnitude < 1.5 ? magnitude : raw / magnitude < 3 ? 2 * magnitude : raw / magnitude < 7 ? 5 * magnitude : 10 * magnitude;
  std::vector<double> out;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) out.push_back(std::fabs(v) < 1e-12 * span ? 0 : v);
  return out;
}

// One series: dots (at most ~2500) or a line (at most ~3000 points; a NaN breaks it).
template <class MapX, class MapY>
static void draw_series(std::ostringstream& svg, const Series& s, MapX X, MapY Y) {
  const std::size_t n = s.x->size();
  if (s.dots) {  // at most ~2500 dots
    const std::size_t stride = std::max<std::size_t>(1, n / 2500);
    svg << "<g fill=\"" << s.color << "\" fill-opacity=\"0.45\">";
    for (std::size_t i = 0; i < n; i += stride)
      if (std::isfinite((*s.x)[i]) && std::isfinite((*s.y)[i]))
        svg << "<circle cx=\"" << number(X((*s.x)[i])) << "\" cy=\"" << number(Y((*s.y)[i])) << "\" r=\"1.3\"/>";
    svg << "</g>\n";
  } else {  // at most ~3000 points; a NaN breaks the line
    const std::size_t stride = std::max<std::size_t>(1, n / 3000);
    bool open = false;
    for (std::size_t i = 0; i < n; i += stride) {
      const bool finite = std::isfinite((*s.x)[i]) && std::isfinite((*s.y)[i]);
      if (finite && !open) {
        svg << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"1.4\""
            << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"";
        open = true;
      }
      if (finite) svg << number(X((*s.x)[i])) << "," << number(Y((*s.y)[i])) << " ";
      if (!finite && open) svg << "\"/>\n", open = false;
    }
    if (open) svg << "\"/>\n";
  }
}

std::string line_plot(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                      const std::vector<Series>& series, const std::vector<Band>& bands,
                      const std::vector<std::pair<double, std::string>>& hlines) {
  constexpr double W = 900, H = 420, left = 80, right = 190, top = 40, bottom = 55;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const Series& s : series)
    for (std::size_t i = 0; i < s.x->size(); ++i) {
      if (!std::isfinite((*s.x)[i]) || !std::isfinite((*s.y)[i])) continue;
      x0 = std::min(x0, (*s.x)[i]);
      x1 = std::max(x1, (*s.x)[i]);
      y0 = std::min(y0, (*s.y)[i]);
      y1 = std::max(y1, (*s.y)[i]);
    }
  for (const auto& [y, label] : hlines) y0 = std::min(y0, y), y1 = std::max(y1, y);
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad;
  y1 += pad;
  auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * (W - left - right); };
  auto Y = [&](double y) { return H - bottom - (y - y0) / (y1 - y0) * (H - top - bottom); };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H
      << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape_xml(title) << "</text>\n";
  for (const Band& b : bands)
    svg << "<rect x=\"" << number(X(std::max(b.x0, x0))) << "\" y=\"" << top << "\" width=\""
        << number(std::max(0.0, X(std::min(b.x1, x1)) - X(std::max(b.x0, x0)))) << "\" height=\"" << H - top - bottom
        << "\" fill=\"" << b.color << "\" fill-opacity=\"0.18\"/>\n";
  for (double t : ticks(x0, x1))
    svg << "<line x1=\"" << number(X(t)) << "\" y1=\"" << H - bottom << "\" x2=\"" << number(X(t)) << "\" y2=\"" << top
        << "\" stroke=\"#ddd\"/><text x=\"" << number(X(t)) << "\" y=\"" << H - bottom + 18 << "\" text-anchor=\"middle\">"
        << number(t) << "</text>\n";
  for (double t : ticks(y0, y1))
    svg << "<line x1=\"" << left << "\" y1=\"" << number(Y(t)) << "\" x2=\"" << W - right << "\" y2=\"" << number(Y(t))
        << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << number(Y(t) + 4) << "\" text-anchor=\"end\">" << number(t)
        << "</text>\n";
  svg << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << W - left - right << "\" height=\"" << H - top - bottom
      << "\" fill=\"none\" stroke=\"black\"/>\n";
  svg << "<text x=\"" << (left + W - right) / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">" << escape_xml(xlabel)
      << "</text>\n<text transform=\"translate(18," << (top + H - bottom) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
      << escape_xml(ylabel) << "</text>\n";
  for (const auto& [y, label] : hlines)
    svg << "<line x1=\"" << left << "\" y1=\"" << number(Y(y)) << "\" x2=\"" << W - right << "\" y2=\"" << number(Y(y))
        << "\" stroke=\"#888\" stroke-dasharray=\"2,3\"/>\n";
  int row = 0;
  for (const Series& s : series) {
    draw_series(svg, s, X, Y);
    const double ly = top + 14 + 20 * row++;
    svg << "<line x1=\"" << W - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << W - right + 38 << "\" y2=\"" << ly << "\" stroke=\""
        << s.color << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << "/><text x=\"" << W - right + 44
        << "\" y=\"" << ly + 4 << "\">" << escape_xml(s.name) << "</text>\n";
  }
  for (const auto& [y, label] : hlines) {
    const double ly = top + 14 + 20 * row++;
    svg << "<line x1=\"" << W - right + 12 << "\" y1=\"" << ly << "\" x2=\"" << W - right + 38 << "\" y2=\"" << ly
        << "\" stroke=\"#888\" stroke-dasharray=\"2,3\"/><text x=\"" << W - right + 44 << "\" y=\"" << ly + 4 << "\">"
        << escape_xml(label) << "</text>\n";
    break;  // one legend entry for the band's two lines
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string bar_chart(const std::string& title, const std::vector<std::pair<std::string, double>>& bars, double reference,
                      const std::string& reference_label) {
  constexpr double W = 900, row = 28, left = 170, right = 120, top = 40;
  const double H = top + row * (bars.size() + 1) + 30;
  double hi = reference;
  for (const auto& [name, v] : bars)
    if (std::isfinite(v)) hi = std::max(hi, v);
  hi *= 1.05;
  auto X = [&](double v) { return left + v / hi * (W - left - right); };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H
      << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape_xml(title) << "</text>\n";
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const double y = top + row * i;
    const double v = std::isfinite(bars[i].second) ? bars[i].second : 0;
    svg << "<text x=\"" << left - 8 << "\" y=\"" << y + 17 << "\" text-anchor=\"end\">" << escape_xml(bars[i].first)
        << "</text><rect x=\"" << left << "\" y=\"" << y + 4 << "\" width=\"" << number(X(v) - left) << "\" height=\"" << row - 8
        << "\" fill=\"#4a78b5\"/><text x=\"" << number(X(v) + 6) << "\" y=\"" << y + 17 << "\">"
        << (std::isfinite(bars[i].second) ? number(bars[i].second) : std::string("failed")) << "</text>\n";
  }
  const double y_end = top + row * bars.size();
  svg << "<line x1=\"" << number(X(reference)) << "\" y1=\"" << top << "\" x2=\"" << number(X(reference)) << "\" y2=\"" << y_end
      << "\" stroke=\"#c33\" stroke-dasharray=\"5,4\"/><text x=\"" << number(X(reference)) << "\" y=\"" << y_end + 18
      << "\" text-anchor=\"middle\" fill=\"#c33\">" << escape_xml(reference_label) << "</text>\n</svg>\n";
  return svg.str();
}

}  // namespace backlash::discrepancy::detail
