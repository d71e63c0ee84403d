// Figures and summary of a design-space map (map/figures.hpp): bins per pair and
// per axis filled as the points stream past, heat maps with the 1/2-contour of the cycle
// fraction (marching squares) drawn by gnuplot through plot.hpp, and summary.md
// (docs/map-figures.md).
#include "backlash/map/figures.hpp"

#include "backlash/model/effect_table.hpp"
#include "backlash/reports/plot.hpp"

#include <algorithm>
#include <cctype>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace backlash::map::figures {

// The figures are drawn with gnuplot through the plotting target (backlash/reports/plot.hpp).
using reports::HeatMap;
using reports::Label;
using reports::Plot;
using reports::render_figures;
using reports::Series;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

const std::vector<std::string>& known_statuses() {
  static const std::vector<std::string> names = {"limit_cycle", "none", "divergent", "unvalidated", "refused", "error"};
  return names;
}

std::string number(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// The coordinate the bins are equal in: the value, or its log10 on a log axis.
double to_u(const MapAxis& a, double x) { return a.log_scale ? std::log10(x) : x; }
double from_u(const MapAxis& a, double u) { return a.log_scale ? std::pow(10.0, u) : u; }

std::pair<double, double> box(const MapAxis& a) { return {std::min(a.from, a.to), std::max(a.from, a.to)}; }

void check_axis(const MapAxis& a, bool grid) {
  const std::string where = "map figures: axis '" + a.name + "': ";
  if (!std::isfinite(a.from) || !std::isfinite(a.to)) throw std::invalid_argument(where + "from/to not finite");
  if (a.bins < 1) throw std::invalid_argument(where + "bins = " + std::to_string(a.bins) + ", needs at least 1");
  if (a.from == a.to && !(grid && a.bins == 1)) throw std::invalid_argument(where + "from = to = " + number(a.from));
  if (a.log_scale && std::min(a.from, a.to) <= 0)
    throw std::invalid_argument(where + "log scale needs from, to > 0, got " + number(std::min(a.from, a.to)));
}

using reports::literal;  // text shown literally in gnuplot's enhanced mode

// The texts below never put a space right after a sub/superscript: librsvg drops a space
// at the edge of gnuplot's <tspan> pieces, even a no-break one ("J_{m} + J_{L}" reads "Jm+ JL").
struct ParameterText {
  std::string name;
  std::string symbol;       // gnuplot enhanced text
  std::string description;  // with the unit: docs/physics.md (rad, s, torques in N·m), docs/effects.md
};

/// The structure's texts here; an effect parameter's from the table of effects (SYMBOL,
/// DESCRIPTION (UNIT)).
std::optional<ParameterText> parameter_text(const std::string& name) {
  static const ParameterText table[] = {
      {"Jm", "J_{m}", "motor inertia (kg·m^{2})"},
      {"JL", "J_{L}", "load inertia (kg·m^{2})"},
      {"Fm", "F_{m}", "motor viscous friction (N·m·s/rad)"},
      {"FL", "F_{L}", "load viscous friction (N·m·s/rad)"},
      {"K", "K", "loop gain (N·m/rad)"},
      {"backlash", "b", "backlash (rad)"},
      {"reference", "θ_{R}", "reference step (rad)"},
      {"JL_over_Jm", "J_{L}/J_{m}", "inertia ratio, (J_{m}+J_{L}) kept (dimensionless)"},
      {"FL_over_F", "F_{L}/F", "load share of F, (F_{m}+F_{L}) kept (dimensionless)"}};
  for (const ParameterText& t : table)
    if (name == t.name) return t;
  if (const model::EffectParameterInfo* e = model::effect_parameter_named(name))
    return ParameterText{std::string(e->name), std::string(e->symbol),
                         std::string(e->description) + " (" + std::string(e->unit) + ")"};
  return std::nullopt;
}

// The parameter's symbol (titles) and its axis label: symbol, what it is, unit.
std::string symbol(const std::string& name) {
  const std::optional<ParameterText> t = parameter_text(name);
  return t ? t->symbol : literal(name);
}
std::string axis_label(const std::string& name) {
  const std::optional<ParameterText> t = parameter_text(name);
  return t ? t->symbol + ", " + t->description : literal(name);
}

std::string file_part(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return out;
}

}  // namespace

void MapFigures::Bin::add(double magnitude, bool cycle) {
  ++n;
  if (cycle) ++cycles;
  const double delta = magnitude - mean;
  mean += delta / static_cast<double>(n);
  m2 += delta * (magnitude - mean);
}

MapFigures::MapFigures(std::string case_id, std::vector<MapAxis> axes, std::string sampling)
    : case_id_(std::move(case_id)), axes_(std::move(axes)), sampling_(std::move(sampling)) {
  const bool grid = sampling_ == "grid";
  if (!grid && sampling_ != "sobol" && sampling_ != "lhs")
    throw std::invalid_argument("map figures: sampling '" + sampling_ + "' is none of grid, sobol, lhs");
  for (const MapAxis& a : axes_) {
    check_axis(a, grid);
    const int group = grid ? (a.bins + max_bins_per_axis - 1) / max_bins_per_axis : 1;
    group_.push_back(group);
    bins_.push_back(grid ? (a.bins + group - 1) / group : std::min(a.bins, max_bins_per_axis));
    axis_bins_.emplace_back(static_cast<std::size_t>(bins_.back()));
  }
  for (std::size_t p = 0; p < axes_.size(); ++p)
    for (std::size_t q = p + 1; q < axes_.size(); ++q) {
      pair_bins_.emplace_back(static_cast<std::size_t>(bins_[p]) * static_cast<std::size_t>(bins_[q]));
      markers_.emplace_back();
    }
  status_names_ = known_statuses();
  status_counts_.assign(status_names_.size(), 0);
}

// The bin of value x on an axis; on a grid, the grid value's index (divided by the group).
int MapFigures::bin_of(std::size_t axis, double x, std::int64_t index) const {
  const MapAxis& a = axes_[axis];
  const auto [lo, hi] = box(a);
  const double u0 = to_u(a, lo), u1 = to_u(a, hi);
  const auto outside = [&](const std::string& why) {
    return std::invalid_argument("map figures: point " + std::to_string(index) + ": " + a.name + " = " + number(x) + " " + why);
  };
  if (!std::isfinite(x) || (a.log_scale && x <= 0)) throw outside("is not a value of the axis");
  if (u1 == u0) {
    if (x != lo) throw outside("is not the grid's one value " + number(lo));
    return 0;
  }
  const double t = (to_u(a, x) - u0) / (u1 - u0);  // 0 … 1 across the box
  if (t < -1e-9 || t > 1 + 1e-9) throw outside("is outside [" + number(lo) + ", " + number(hi) + "]");
  if (sampling_ != "grid") return std::clamp(static_cast<int>(std::floor(t * bins_[axis])), 0, bins_[axis] - 1);
  const double k = t * (a.bins - 1);
  const double k_near = std::round(k);
  if (std::abs(k - k_near) > 1e-6) throw outside("is not one of the axis's " + std::to_string(a.bins) + " grid values");
  return static_cast<int>(k_near) / group_[axis];
}

std::size_t MapFigures::pair_slot(int p, int q) const {
  const int d = static_cast<int>(axes_.size());
  if (p < 0 || q <= p || q >= d) throw std::out_of_range("map figures: no pair (" + std::to_string(p) + ", " + std::to_string(q) + ")");
  return static_cast<std::size_t>(p * d - p * (p + 1) / 2 + (q - p - 1));
}

void MapFigures::add(const MapPoint& point) {
  const std::string where = "map figures: point " + std::to_string(point.index) + ": ";
  if (point.index <= last_index_)
    throw std::invalid_argument(where + "comes after point " + std::to_string(last_index_) + " (points must come in index order)");
  if (point.x.size() != axes_.size())
    throw std::invalid_argument(where + std::to_string(point.x.size()) + " values instead of " + std::to_string(axes_.size()));
  std::vector<int> bin(axes_.size());
  for (std::size_t i = 0; i < axes_.size(); ++i) bin[i] = bin_of(i, point.x[i], point.index);
  last_index_ = point.index;
  ++points_;
  const auto known = std::find(status_names_.begin(), status_names_.end(), point.status);
  const std::size_t s = static_cast<std::size_t>(known - status_names_.begin());
  if (known == status_names_.end()) { status_names_.push_back(point.status); status_counts_.push_back(0); }
  ++status_counts_[s];
  const bool cycle = point.status == "limit_cycle" && std::isfinite(point.peak_to_peak);
  if (!cycle && point.status != "none") return;  // unknown answer: counted, not binned
  const double magnitude = cycle ? point.peak_to_peak : 0.0;
  if (cycle) {
    const bool first = all_.cycles == 0;
    magnitude_min_ = first ? magnitude : std::min(magnitude_min_, magnitude);
    magnitude_max_ = first ? magnitude : std::max(magnitude_max_, magnitude);
    if (std::isfinite(point.period)) {
      period_min_ = periods_ == 0 ? point.period : std::min(period_min_, point.period);
      period_max_ = periods_ == 0 ? point.period : std::max(period_max_, point.period);
      ++periods_;
    }
  }
  all_.add(magnitude, cycle);
  for (std::size_t i = 0; i < axes_.size(); ++i) axis_bins_[i][static_cast<std::size_t>(bin[i])].add(magnitude, cycle);
  std::size_t slot = 0;
  for (std::size_t p = 0; p < axes_.size(); ++p)
    for (std::size_t q = p + 1; q < axes_.size(); ++q, ++slot)
      pair_bins_[slot][static_cast<std::size_t>(bin[p] + bins_[p] * bin[q])].add(magnitude, cycle);
}

void MapFigures::add_boundary(const MapBoundaryPoint& point) {
  if (point.x.size() != axes_.size())
    throw std::invalid_argument("map figures: boundary point with " + std::to_string(point.x.size()) + " values instead of " +
                                std::to_string(axes_.size()));
  if (point.along < 0 || point.along >= static_cast<int>(axes_.size()))
    throw std::invalid_argument("map figures: boundary point along axis " + std::to_string(point.along) + " of " +
                                std::to_string(axes_.size()));
  ++boundary_points_;
  for (int other = 0; other < static_cast<int>(axes_.size()); ++other) {
    if (other == point.along) continue;
    const int p = std::min(other, point.along), q = std::max(other, point.along);
    Markers& m = markers_[pair_slot(p, q)];
    if (m.seen++ % m.stride != 0) continue;
    m.kept.emplace_back(point.x[static_cast<std::size_t>(p)], point.x[static_cast<std::size_t>(q)]);
    if (m.kept.size() < static_cast<std::size_t>(max_boundary_markers)) continue;
    std::vector<std::pair<double, double>> every_other;  // full: keep every other one, double the stride
    for (std::size_t k = 0; k < m.kept.size(); k += 2) every_other.push_back(m.kept[k]);
    m.kept = std::move(every_other);
    m.stride *= 2;
  }
}

// The bin edges of an axis, in values (equal steps in u; a grid's bins centred on its values).
std::vector<double> MapFigures::edges(std::size_t axis) const {
  const MapAxis& a = axes_[axis];
  const auto [lo, hi] = box(a);
  const double u0 = to_u(a, lo), u1 = to_u(a, hi);
  std::vector<double> out;
  if (sampling_ != "grid") {
    for (int b = 0; b <= bins_[axis]; ++b) out.push_back(from_u(a, u0 + (u1 - u0) * b / bins_[axis]));
    return out;
  }
  // grid: value k at u0 + k·du; bin b holds values b·g … b·g + g − 1
  const double du = a.bins > 1 ? (u1 - u0) / (a.bins - 1) : (a.log_scale ? 0.1 : std::max(std::abs(lo), 1.0) * 0.1);
  for (int b = 0; b <= bins_[axis]; ++b) {
    const int k = std::min(b * group_[axis], a.bins);
    out.push_back(from_u(a, u0 + (k - 0.5) * du));
  }
  return out;
}

namespace {

// Marching squares: the level-0 line of v (nx × ny values at the cell corners (cx, cy), index
// ix + nx·iy; NaN corners skip their cells) as segments, NaN between them.  A saddle cell is
// resolved by the mean of its corners.  Crossings are interpolated linearly in (cx, cy).
void level_zero_segments(const std::vector<double>& v, const std::vector<double>& cx, const std::vector<double>& cy,
                         std::vector<double>& out_x, std::vector<double>& out_y) {
  const std::size_t nx = cx.size(), ny = cy.size();
  for (std::size_t iy = 0; iy + 1 < ny; ++iy)
    for (std::size_t ix = 0; ix + 1 < nx; ++ix) {
      // corners in order around the cell: (ix,iy) (ix+1,iy) (ix+1,iy+1) (ix,iy+1)
      const std::array<double, 4> x = {cx[ix], cx[ix + 1], cx[ix + 1], cx[ix]};
      const std::array<double, 4> y = {cy[iy], cy[iy], cy[iy + 1], cy[iy + 1]};
      const std::array<double, 4> f = {v[ix + nx * iy], v[ix + 1 + nx * iy], v[ix + 1 + nx * (iy + 1)], v[ix + nx * (iy + 1)]};
      if (std::any_of(f.begin(), f.end(), [](double z) { return std::isnan(z); })) continue;
      std::vector<std::array<double, 2>> crossing;  // on edges 0..3 (edge e joins corner e and e+1)
      std::vector<int> edge;
      for (int e = 0; e < 4; ++e) {
        const int a = e, b = (e + 1) % 4;
        if ((f[a] >= 0) == (f[b] >= 0)) continue;
        const double t = f[a] / (f[a] - f[b]);
        crossing.push_back({x[a] + t * (x[b] - x[a]), y[a] + t * (y[b] - y[a])});
        edge.push_back(e);
      }
      std::vector<std::pair<int, int>> pairs;
      if (crossing.size() == 2) pairs = {{0, 1}};
      else if (crossing.size() == 4) {
        // saddle: corner e is cut off by the crossings on edges e−1 and e.  Cut off the corners
        // whose sign differs from the cell's mean (the mean's side joins across the centre).
        const bool centre_inside = (f[0] + f[1] + f[2] + f[3]) / 4 >= 0;
        const bool corner0_inside = f[0] >= 0;
        if (corner0_inside != centre_inside) pairs = {{3, 0}, {1, 2}};  // corners 0 and 2 cut off
        else pairs = {{0, 1}, {2, 3}};                                  // corners 1 and 3 cut off
      }
      for (const auto& [i, j] : pairs) {
        out_x.insert(out_x.end(), {crossing[i][0], crossing[j][0], nan});
        out_y.insert(out_y.end(), {crossing[i][1], crossing[j][1], nan});
      }
    }
}

std::vector<double> centres_u(const MapAxis& a, const std::vector<double>& edges) {
  std::vector<double> out;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) out.push_back((to_u(a, edges[b]) + to_u(a, edges[b + 1])) / 2);
  return out;
}

}  // namespace

MapField MapFigures::field(int p, int q) const {
  const std::vector<Bin>& bins = pair_bins_[pair_slot(p, q)];
  const auto up = static_cast<std::size_t>(p), uq = static_cast<std::size_t>(q);
  MapField out;
  out.p = p;
  out.q = q;
  out.x_edges = edges(up);
  out.y_edges = edges(uq);
  std::vector<double> level;  // cycle fraction − 1/2
  for (const Bin& b : bins) {
    out.count.push_back(b.n);
    out.mean_peak_to_peak.push_back(b.n ? b.mean : nan);
    out.cycle_fraction.push_back(b.n ? static_cast<double>(b.cycles) / static_cast<double>(b.n) : nan);
    level.push_back(out.cycle_fraction.back() - 0.5);
  }
  level_zero_segments(level, centres_u(axes_[up], out.x_edges), centres_u(axes_[uq], out.y_edges), out.contour_x, out.contour_y);
  for (double& x : out.contour_x) x = std::isnan(x) ? x : from_u(axes_[up], x);
  for (double& y : out.contour_y) y = std::isnan(y) ? y : from_u(axes_[uq], y);
  for (const auto& [x, y] : markers_[pair_slot(p, q)].kept) {
    out.boundary_x.push_back(x);
    out.boundary_y.push_back(y);
  }
  return out;
}

std::string MapFigures::figure_stem(int p, int q) const {
  pair_slot(p, q);  // checks the pair
  return "figures/map_" + file_part(axes_[static_cast<std::size_t>(p)].name) + "_" + file_part(axes_[static_cast<std::size_t>(q)].name);
}

// First-order index of each axis from its bins (the correlation ratio η²): SS_between / SS_total
// with SS_between = Σ n_b (m_b − m)², SS_total = SS_between + Σ (within-bin sums of squares).
std::vector<MapSensitivity> MapFigures::sensitivities() const {
  std::vector<MapSensitivity> out;
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    double between = 0, within = 0;
    std::int64_t filled = 0;
    for (const Bin& b : axis_bins_[i]) {
      if (b.n == 0) continue;
      ++filled;
      between += static_cast<double>(b.n) * (b.mean - all_.mean) * (b.mean - all_.mean);
      within += b.m2;
    }
    const double total = between + within;
    MapSensitivity s{axes_[i].name, total > 0 ? between / total : 0.0, 0.0};
    if (sampling_ != "grid" && total > 0 && all_.n > filled)
      s.bias = static_cast<double>(filled - 1) * within / static_cast<double>(all_.n - filled) / total;
    out.push_back(s);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const MapSensitivity& a, const MapSensitivity& b) { return a.first_order_index > b.first_order_index; });
  return out;
}

namespace {

std::string axis_text(const MapAxis& a, int bins, bool grid) {
  std::string text = "`" + a.name + "` from " + number(a.from) + " to " + number(a.to);
  text += grid ? " (" + std::to_string(a.bins) + " values" : " (" + std::to_string(bins) + " bins";
  if (grid && bins != a.bins) text += " in " + std::to_string(bins) + " bins";
  return text + (a.log_scale ? ", log scale)" : ")");
}

std::string estimator_text(bool grid) {
  std::string text =
      "The first-order index of a parameter is Var(E[magnitude | parameter]) / Var(magnitude), the magnitude being "
      "the peak-to-peak swing of θo (0 where there is no cycle).  It is estimated from the parameter's bins as the "
      "correlation ratio η² = Σ_b n_b (m_b − m)² / Σ_points (y − m)², with n_b points of mean m_b in bin b and m the "
      "mean of all N binned points (the bins' variance of the bin means, weighted by their counts, over the total "
      "variance).  Binning replaces E[magnitude | parameter] by its bin averages, which lowers the index by the "
      "variation of E[magnitude | parameter] inside a bin (of order the bin width squared for a smooth map).  ";
  if (grid)
    text += "On a full grid the bin means are exact averages over the other parameters' grid values, so the index is "
            "that of the grid's own (discrete, uniform) distribution, without sampling noise.";
  else
    text += "With sampled points each bin mean carries sampling noise, which raises the index on average by about "
            "(B − 1)·MS_within / SS_total ≈ (B − 1)/N · (1 − η²) for B non-empty bins — the column *bias* (a parameter "
            "without influence reads about (B − 1)/N, not 0).  Few points per bin (N/B below about 10) make this bias "
            "and the noise large: compare an index with its bias before ranking on it; η² − bias (the ε² estimate) "
            "corrects the bias on average.";
  return text;
}

}  // namespace

std::string MapFigures::summary_markdown() const {
  const bool grid = sampling_ == "grid";
  std::ostringstream md;
  md << "# Design-space map of case " << case_id_ << "\n\n"
     << points_ << " points, " << (grid ? "a grid" : sampling_ == "sobol" ? "Sobol sampling" : "Latin-hypercube sampling")
     << ", over:\n\n";
  for (std::size_t i = 0; i < axes_.size(); ++i) md << "- " << axis_text(axes_[i], bins_[i], grid) << "\n";
  md << "\n## Points by status\n\n| status | points |\n|---|---:|\n";
  for (std::size_t s = 0; s < status_names_.size(); ++s)
    if (status_counts_[s] > 0 || s < 2) md << "| " << status_names_[s] << " | " << status_counts_[s] << " |\n";
  const std::int64_t undecided = points_ - all_.n;
  md << "\nBinned (a cycle or none): " << all_.n << "; left out of the bins and figures (answer unknown): " << undecided << ".\n";
  md << "\n## Magnitude\n\n";
  if (all_.cycles == 0) md << "No point has a limit cycle.\n";
  else {
    md << "Peak-to-peak swing of θo over the " << all_.cycles << " limit cycles: " << number(magnitude_min_) << " to "
       << number(magnitude_max_) << " rad";
    if (periods_ > 0) md << "; period " << number(period_min_) << " to " << number(period_max_) << " s";
    md << ".\n";
  }
  md << "\n## Which parameter moves the magnitude most\n\n| rank | parameter | first-order index |" << (grid ? "" : " bias |")
     << "\n|---:|---|---:|" << (grid ? "" : "---:|") << "\n";
  const std::vector<MapSensitivity> ranked = sensitivities();
  for (std::size_t r = 0; r < ranked.size(); ++r) {
    md << "| " << r + 1 << " | `" << ranked[r].name << "` | " << number(ranked[r].first_order_index) << " |";
    if (!grid) md << " " << number(ranked[r].bias) << " |";
    md << "\n";
  }
  if (all_.n < 2 || all_.m2 <= 0) md << "\nThe magnitude does not vary over the binned points: no ranking.\n";
  md << "\n" << estimator_text(grid) << "\n\n## Figures\n\n";
  if (axes_.size() < 2) md << "One varied parameter: no pair figures.\n";
  for (int p = 0; p < static_cast<int>(axes_.size()); ++p)
    for (int q = p + 1; q < static_cast<int>(axes_.size()); ++q) {
      const std::string stem = figure_stem(p, q);
      md << "- `" << axes_[static_cast<std::size_t>(p)].name << "` × `" << axes_[static_cast<std::size_t>(q)].name << "`: ![map]("
         << stem << ".svg) ([PDF](" << stem << ".pdf))\n";
    }
  md << "\nEach figure: the mean peak-to-peak swing over the bins (colour), the cycle/no-cycle boundary as the line "
        "where half of a bin's points have a cycle, and the boundary crossings found exactly along the grid lines "
        "(markers; a map of more than two parameters shows them from every slice of the others).\n";
  return md.str();
}

namespace {

Plot pair_plot(const MapField& f, const MapAxis& x, const MapAxis& y, const std::string& title, const std::string& stem) {
  Plot plot;
  plot.name = stem.substr(std::string("figures/").size());
  plot.title = title;
  plot.x_label = axis_label(x.name);
  plot.y_label = axis_label(y.name);
  plot.x_log = x.log_scale;
  plot.y_log = y.log_scale;
  plot.x_range = std::pair{f.x_edges.front(), f.x_edges.back()};
  plot.y_range = std::pair{f.y_edges.front(), f.y_edges.back()};
  plot.key = "below horizontal";
  plot.width = 900;
  plot.height = 760;
  HeatMap h;
  h.colour_label = "mean peak-to-peak swing (rad) of θ_{o}, 0 without a cycle";
  const std::size_t nx = f.x_edges.size() - 1;
  for (std::size_t k = 0; k < f.mean_peak_to_peak.size(); ++k) {
    h.x_low.push_back(f.x_edges[k % nx]);
    h.x_high.push_back(f.x_edges[k % nx + 1]);
    h.y_low.push_back(f.y_edges[k / nx]);
    h.y_high.push_back(f.y_edges[k / nx + 1]);
    h.value.push_back(f.mean_peak_to_peak[k]);
  }
  // the colour bar starts at 0 (no cycle); without any cycle it spans [0, 1] rad
  double top = 0;
  for (double v : h.value) top = std::isfinite(v) ? std::max(top, v) : top;
  h.value_range = std::pair{0.0, top > 0 ? top : 1.0};
  plot.heat_map = std::move(h);
  const bool decided = std::any_of(f.count.begin(), f.count.end(), [](std::int64_t n) { return n > 0; });
  if (!decided) plot.title += " — no point with a known answer";
  else if (f.contour_x.empty()) plot.title += " — no cycle/no-cycle boundary inside";
  if (!f.contour_x.empty())
    plot.series.push_back({"cycle/no-cycle boundary: half of the bin's points have a cycle", f.contour_x, f.contour_y,
                           "lines lw 3 lc rgb '#ff2d2d'"});
  if (!f.boundary_x.empty()) {  // white dots ringed in black: seen on the palette's dark and light ends
    plot.series.push_back({"boundary found exactly along grid lines", f.boundary_x, f.boundary_y,
                           "points pt 7 ps 0.75 lc rgb '#000000'"});
    plot.series.push_back({"", f.boundary_x, f.boundary_y, "points pt 7 ps 0.45 lc rgb '#ffffff'", false});
  }
  return plot;
}

}  // namespace

std::string MapFigures::write(const std::filesystem::path& directory) const {
  std::vector<Plot> plots;
  for (int p = 0; p < static_cast<int>(axes_.size()); ++p)
    for (int q = p + 1; q < static_cast<int>(axes_.size()); ++q) {
      const MapAxis& x = axes_[static_cast<std::size_t>(p)];
      const MapAxis& y = axes_[static_cast<std::size_t>(q)];
      const std::string title = "Case " + literal(case_id_) + ": limit cycles over (" + symbol(x.name) + ", " + symbol(y.name) +
                                "), " + std::to_string(points_) + " points, " + sampling_;
      plots.push_back(pair_plot(field(p, q), x, y, title, figure_stem(p, q)));
    }
  std::string failure;
  if (!plots.empty())
    if (const auto why = render_figures(plots, directory)) failure = *why;
  std::string summary = summary_markdown();
  if (!failure.empty()) summary += "\nThe figures were not drawn: " + failure + ".\n";
  const std::filesystem::path staged = directory / ".summary.md.partial";
  {
    std::ofstream out(staged, std::ios::binary);
    out << summary;
    if (!out) throw std::runtime_error("map figures: cannot write " + staged.string());
  }
  std::filesystem::rename(staged, directory / "summary.md");
  return failure;
}

}  // namespace backlash::map::figures
