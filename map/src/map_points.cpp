// map_points.cpp — the points of a design-space map (map/map.hpp): the request checked, grid,
// Sobol and Latin-hypercube points made on demand from their index.
#include "backlash/map/map.hpp"

#include "map_text.hpp"

#include "backlash/numeric/varied_parameter.hpp"
#include "backlash/output/text.hpp"

#include <boost/random/sobol.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

namespace backlash::map {

using api::BadInput;

namespace {

const std::string map_names = numeric::varied_parameter_names(", ");

bool known_name(const std::string& v) { return numeric::varied_parameter(v).has_value(); }

// FROM or TO of --vary (output::read_number); a leading '+' is refused, as it always was.
double parse_number(const std::string& text, const std::string& whole) {
  double value = 0;
  if (output::read_number(text, value) != output::NumberText::ok || text.front() == '+')
    throw BadInput("vary", "'" + whole + "': '" + text + "' is not a finite number (expected NAME=FROM:TO:N)");
  return value;
}

// splitmix64: the round function of the permutations and the jitter of the Latin hypercube.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A keyed permutation of [0, n): a 4-round balanced Feistel network on the smallest even power
// of two >= n, cycle-walking until the value falls inside [0, n).
std::uint64_t permute(std::uint64_t i, std::uint64_t n, std::uint64_t key) {
  int half = 1;
  while ((std::uint64_t{1} << (2 * half)) < n) ++half;
  const std::uint64_t mask = (std::uint64_t{1} << half) - 1;
  std::uint64_t v = i;
  do {
    std::uint64_t left = v >> half, right = v & mask;
    for (std::uint64_t round = 0; round < 4; ++round) {
      const std::uint64_t next = left ^ (mix(right ^ mix(key + round)) & mask);
      left = right;
      right = next;
    }
    v = (left << half) | right;
  } while (v >= n);
  return v;
}

double unit(std::uint64_t bits) { return std::ldexp(static_cast<double>(bits >> 11), -53); }  // [0, 1), exact

}  // namespace

MapAxis parse_vary(const std::string& text) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0)
    throw BadInput("vary", "'" + text + "': expected NAME=FROM:TO:N, e.g. JL_over_Jm=0.25:4:40");
  MapAxis axis;
  axis.name = text.substr(0, equals);
  if (!known_name(axis.name))
    throw BadInput("vary", "'" + text + "': unknown parameter '" + axis.name + "' (" + map_names + ")");
  std::vector<std::string> parts;
  std::size_t start = equals + 1;
  for (std::size_t colon; (colon = text.find(':', start)) != std::string::npos; start = colon + 1)
    parts.push_back(text.substr(start, colon - start));
  parts.push_back(text.substr(start));
  if (parts.size() < 2 || parts.size() > 3)
    throw BadInput("vary", "'" + text + "': expected NAME=FROM:TO:N, e.g. JL_over_Jm=0.25:4:40");
  axis.from = parse_number(parts[0], text);
  axis.to = parse_number(parts[1], text);
  if (parts.size() == 3) {
    const std::string& n = parts[2];
    long count = 0;
    const auto [ptr, error] = std::from_chars(n.data(), n.data() + n.size(), count);
    if (n.empty() || error != std::errc() || ptr != n.data() + n.size() || count < 1 || count > 100000000)
      throw BadInput("vary", "'" + text + "': N must be an integer in 1 … 10^8, got '" + n + "'");
    axis.count = count;
  } else {
    axis.count_given = false;
  }
  return axis;
}

MapPlan::MapPlan(const MapRequest& request) : request_(request), case_(api::Case::load(request.target)) {
  const MapRequest& r = request_;
  if (r.vary.empty() || r.vary.size() > 8) throw BadInput("vary", "give 1 to 8 --vary NAME=FROM:TO:N");
  std::set<std::string> seen;
  for (const MapAxis& a : r.vary) {
    if (!known_name(a.name)) throw BadInput("vary", "unknown parameter '" + a.name + "' (" + map_names + ")");
    if (!seen.insert(a.name).second) throw BadInput("vary", a.name + " is varied twice");
    if (!std::isfinite(a.from) || !std::isfinite(a.to)) throw BadInput("vary", a.name + ": FROM and TO must be finite");
    if (a.count < 1) throw BadInput("vary", a.name + ": N must be >= 1");
  }
  auto both = [&](const char* x, const char* y) { return seen.count(x) && seen.count(y); };
  if (both("JL_over_Jm", "Jm") || both("JL_over_Jm", "JL"))
    throw BadInput("vary", "JL_over_Jm sets Jm and JL (keeping Jm + JL): vary it or them, not both");
  if (both("FL_over_F", "Fm") || both("FL_over_F", "FL"))
    throw BadInput("vary", "FL_over_F sets Fm and FL (keeping Fm + FL): vary it or them, not both");
  if (r.threads < 1 || r.threads > 256) throw BadInput("threads", "expected 1 … 256, got " + std::to_string(r.threads));
  if (r.block < 1 || r.block > 100000) throw BadInput("block", "expected 1 … 100000, got " + std::to_string(r.block));
  if (r.sample == "grid") {
    count_ = 1;
    for (const MapAxis& a : r.vary) {
      if (!a.count_given)
        throw BadInput("vary", a.name + ": a grid needs the number of values, " + a.name +
                                   "=FROM:TO:N (FROM:TO alone is for --sample sobol or lhs)");
      if (count_ > (long{1} << 40) / a.count) throw BadInput("vary", "the grid has more than 2^40 points");
      count_ *= a.count;
    }
  } else if (r.sample == "sobol" || r.sample == "lhs") {
    if (r.points < 1 || r.points > (long{1} << 40))
      throw BadInput("points", "--sample " + r.sample + " needs --points N, 1 … 2^40 (got " + std::to_string(r.points) + ")");
    count_ = r.points;
  } else {
    throw BadInput("sample", "expected grid, sobol or lhs, got '" + r.sample + "'");
  }
  base_ = case_.parameters();
  base_effects_ = case_.effects();
  const auto& experiment = case_.spec().experiment;
  if (experiment && experiment->t_end) t_end_ = experiment->t_end->convert_to<double>();
  if (r.step) step_ = *r.step;
  else if (experiment && experiment->kind == model::ExperimentKind::Step) step_ = experiment->step.convert_to<double>();
  if (!std::isfinite(step_)) throw BadInput("step", "not finite");
  // Each parameter depends on one axis, monotonically: its ends bound every point.
  for (const MapAxis& a : r.vary)
    for (const double x : {a.from, a.to}) {
      numeric::Parameters p = base_;
      numeric::Effects e = base_effects_;
      apply(a.name, x, p, e);
    }
}

void MapPlan::apply(const std::string& v, double x, numeric::Parameters& p, numeric::Effects& e) const {
  // The same assignments as `sweep` (api/src/sweep.cpp), so a one-axis map is that sweep.
  const numeric::VariedParameter varied = *numeric::varied_parameter(v);
  numeric::set_varied(varied, x, p, e, base_);
  const auto text = [&v, x] {  // formed only for a refusal: every point of the map passes here
    std::string out;
    detail::appendf(out, "%s = %.17g", v.c_str(), x);
    return out;
  };
  if (!numeric::physical(p))
    throw BadInput("vary", text() + " gives non-physical parameters (inertias and K > 0, frictions and backlash >= 0)");
  if (!numeric::admissible(e)) throw BadInput("vary", text() + " is outside the effect's range (docs/effects.md)");
  if (numeric::contact_laws_clash(e)) throw BadInput("vary", numeric::contact_law_message(v));
  if (const std::string missing = numeric::missing_effect(varied, e); !missing.empty()) throw BadInput("vary", missing);
}

long MapPlan::stride(int axis) const {
  long s = 1;
  for (std::size_t k = request_.vary.size(); k-- > static_cast<std::size_t>(axis) + 1;) s *= request_.vary[k].count;
  return s;
}

long MapPlan::grid_index(long index, int axis) const {
  return (index / stride(axis)) % request_.vary[static_cast<std::size_t>(axis)].count;
}

std::vector<double> MapPlan::values(long index) const {
  const std::vector<MapAxis>& axes = request_.vary;
  const std::size_t d = axes.size();
  std::vector<double> u(d);
  if (request_.sample == "sobol") {
    thread_local std::unique_ptr<boost::random::sobol> sobol;
    if (!sobol || sobol->dimension() != d) sobol = std::make_unique<boost::random::sobol>(d);
    sobol->seed(static_cast<std::uint64_t>(index));  // the index-th point of the sequence (trivial zero skipped)
    for (double& value : u) value = unit((*sobol)());
  } else if (request_.sample == "lhs") {
    const auto n = static_cast<std::uint64_t>(count_), i = static_cast<std::uint64_t>(index);
    for (std::size_t k = 0; k < d; ++k) {
      const std::uint64_t key = mix(request_.seed ^ mix(k + 1));
      const double jitter = unit(mix(key ^ mix(i)));
      u[k] = (static_cast<double>(permute(i, n, key)) + jitter) / static_cast<double>(n);
    }
  }
  std::vector<double> x(d);
  for (std::size_t k = 0; k < d; ++k) {
    const MapAxis& a = axes[k];
    if (request_.sample == "grid") {
      const long i = grid_index(index, static_cast<int>(k));
      x[k] = a.count == 1 ? a.from : a.from + (a.to - a.from) * i / double(a.count - 1);
    } else {
      x[k] = std::min(std::max(a.from + (a.to - a.from) * u[k], std::min(a.from, a.to)), std::max(a.from, a.to));
    }
  }
  return x;
}

numeric::SweepPoint MapPlan::point(long index) const {
  const std::vector<double> x = values(index);
  numeric::SweepPoint point;
  point.parameters = base_;
  point.effects = base_effects_;
  for (std::size_t k = 0; k < x.size(); ++k) apply(request_.vary[k].name, x[k], point.parameters, point.effects);
  // Warm starts run along a grid line (the last axis); sampled points are not neighbours: each starts cold.
  const long line = request_.sample == "grid" ? index / request_.vary.back().count : index;
  point.series = case_.id() + ":" + std::to_string(line);
  point.x = x.back();
  return point;
}

numeric::SweepPoint MapPlan::point_at(long index, int axis, double value) const {
  numeric::SweepPoint point = this->point(index);
  apply(request_.vary[static_cast<std::size_t>(axis)].name, value, point.parameters, point.effects);
  if (static_cast<std::size_t>(axis) + 1 == request_.vary.size()) point.x = value;
  return point;
}

}  // namespace backlash::map
