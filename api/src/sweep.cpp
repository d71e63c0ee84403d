// sweep.cpp — limit cycles over a parameter (thesis figs. 31, 32, or any case), whole or
// streamed, and the CSV.
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include "backlash/numeric/varied_parameter.hpp"

#include "backlash/symbolic/escape.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <memory>
#include <sstream>
#include <string_view>

namespace backlash::api {

namespace {

/// The largest point count: indices and x values stay exact in a double (2^40 / 3 per series).
constexpr long largest_points = (1L << 40) / 3;
constexpr int largest_threads = 1024;

std::string varied_names() { return numeric::varied_parameter_names(", "); }

/// A case's sweep: its parameters and effects with one of them set to x_i.
struct CaseSweep {
  std::string series;
  numeric::Parameters base;
  numeric::Effects base_effects;
  numeric::VariedParameter varied;
  double from = 0, to = 0;
  long n = 1;

  double x(long i) const {
    return n == 1 ? from : from + (to - from) * static_cast<double>(i) / static_cast<double>(n - 1);
  }
  numeric::SweepPoint point(long i) const {
    numeric::SweepPoint out{series, x(i), base, base_effects};
    numeric::set_varied(varied, out.x, out.parameters, out.effects, base);
    return out;
  }
};

/// Every constraint is an interval in x, so checking both ends checks every point.
void check_ends(const CaseSweep& sweep, const std::string& vary) {
  for (const long i : {0L, sweep.n - 1}) {
    const numeric::SweepPoint pt = sweep.point(i);
    const numeric::Parameters& p = pt.parameters;
    const numeric::Effects& e = pt.effects;
    const std::string end = i == 0 ? "from" : "to", at = vary + " = " + detail::number_text(pt.x);
    if (!numeric::physical(p)) throw BadInput(end, at + " gives non-physical parameters");
    if (!numeric::admissible(e)) throw BadInput(end, at + " is outside the effect's range (docs/effects.md)");
  }
  if (numeric::adds_contact_law(sweep.varied, sweep.base_effects))
    throw BadInput("vary", numeric::contact_law_message(vary));
  if (const std::string missing = numeric::missing_effect(sweep.varied, sweep.base_effects); !missing.empty())
    throw BadInput("vary", missing);
}

CaseSweep case_sweep(const SweepRequest& r) {
  if (r.vary.empty()) throw BadInput("vary", "required for a case (or use fig31 / fig32 as the target)");
  const std::optional<numeric::VariedParameter> found = numeric::varied_parameter(r.vary);
  if (!found) throw BadInput("vary", "unknown parameter '" + r.vary + "' (" + varied_names() + ")");
  for (const auto& [name, value] : {std::pair{"from", &r.from}, std::pair{"to", &r.to}}) {
    if (!*value) throw BadInput(name, "required for a case");
    if (!std::isfinite(**value)) throw BadInput(name, "not finite, got " + detail::number_text(**value));
  }
  const Case c = Case::load(r.target);
  CaseSweep sweep{c.id() + ":" + r.vary, c.parameters(), c.effects(), *found, *r.from, *r.to, r.points};
  check_ends(sweep, r.vary);
  return sweep;
}

/// A request checked: how many points, and each made on demand (from any thread).
struct Plan {
  long count = 0;
  std::function<numeric::SweepPoint(long)> point;
};

void check_counts(const SweepRequest& r) {
  if (r.points < 1) throw BadInput("points", "expected an integer >= 1, got " + std::to_string(r.points));
  if (r.points > largest_points)
    throw BadInput("points", "at most " + std::to_string(largest_points) + ", got " + std::to_string(r.points));
  if (r.threads < 1) throw BadInput("threads", "expected an integer >= 1, got " + std::to_string(r.threads));
  if (r.threads > largest_threads)
    throw BadInput("threads", "at most " + std::to_string(largest_threads) + ", got " + std::to_string(r.threads));
  if (r.target.empty()) throw BadInput("target", "expected fig31, fig32 or a case (I..VIII or a case file)");
}

Plan plan(const SweepRequest& r) {
  check_counts(r);
  const long n = r.points;
  if (r.target == "fig31") return {2 * n, [n](long i) { return numeric::figure31_point(n, i); }};
  if (r.target == "fig32") return {3 * n, [n](long i) { return numeric::figure32_point(n, i); }};
  std::string lowered = r.target;
  for (char& ch : lowered) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  std::error_code ignored;
  if (lowered.rfind("fig", 0) == 0 && !std::filesystem::exists(r.target, ignored))
    throw BadInput("target", "unknown figure '" + r.target +
                                 "': the thesis's sweeps are fig31 and fig32 (or give a case with --vary)");
  auto sweep = std::make_shared<const CaseSweep>(case_sweep(r));
  return {n, [sweep](long i) { return sweep->point(i); }};
}

numeric::SweepOptions options_of(const SweepRequest& r) {
  numeric::SweepOptions options;
  options.threads = r.threads;
  options.progress = r.progress;
  return options;
}

}  // namespace

std::vector<numeric::SweepPoint> sweep_points(const SweepRequest& r) {
  const Plan p = plan(r);
  std::vector<numeric::SweepPoint> points;
  points.reserve(static_cast<std::size_t>(p.count));
  for (long i = 0; i < p.count; ++i) points.push_back(p.point(i));
  return points;
}

Sweep sweep(const SweepRequest& r) {
  const std::vector<numeric::SweepPoint> points = sweep_points(r);
  Sweep out;
  out.threads = r.threads;
  out.rows = numeric::run_sweep(points, options_of(r), &out.summary);
  out.points = static_cast<long>(out.rows.size());
  return out;
}

Sweep sweep(const SweepRequest& r, const TextSink& csv, const std::function<void(const numeric::SweepRow&)>& row) {
  const Plan p = plan(r);
  Sweep out;
  out.threads = r.threads;
  csv(Sweep::csv_header());
  numeric::run_sweep_streamed(
      p.count, p.point, options_of(r),
      [&](const numeric::SweepRow& done) {
        csv(Sweep::csv_row(done));
        ++out.points;
        if (row) row(done);
      },
      &out.summary);
  return out;
}

std::string status_of(const numeric::SweepRow& row) { return detail::status_text(row.status); }

std::string Sweep::csv_header() {
  return "series,x,Jm,Fm,JL,FL,K,backlash,effects,status,branches,peak_to_peak,amplitude,period,separation_velocity,"
         "multiplier\n";
}

std::string Sweep::csv_row(const numeric::SweepRow& r) {
  std::ostringstream csv;
  csv.precision(12);
  const numeric::Parameters& p = r.point.parameters;
  std::string effects = r.point.effects.describe();
  std::replace(effects.begin(), effects.end(), ',', ';');  // one CSV cell
  effects.erase(std::remove(effects.begin(), effects.end(), ' '), effects.end());
  const std::string status = status_of(r);
  csv << symbolic::escape::csv_field(r.point.series) << "," << r.point.x << "," << p.Jm << "," << p.Fm << "," << p.JL
      << "," << p.FL << "," << p.K << "," << p.backlash << "," << effects << "," << status << "," << r.branches;
  if (status == "limit_cycle") {
    csv << "," << r.cycle.peak_to_peak << "," << r.cycle.amplitude << "," << r.cycle.period << ",";
    if (std::isfinite(r.cycle.separation_velocity)) csv << r.cycle.separation_velocity;  // none: a pure bounce cycle
    csv << "," << r.cycle.multiplier << "\n";
  } else {
    csv << ",,,,,\n";
  }
  return csv.str();
}

std::string Sweep::csv() const {
  std::string out = csv_header();
  for (const numeric::SweepRow& r : rows) out += csv_row(r);
  return out;
}

std::string Sweep::summary_line() const {
  std::string out;
  detail::appendf(out, "sweep: %ld points on %d threads; parametric family validated at %ld samples (%ld failed), branches:",
                  points, threads, summary.validated_samples, summary.failed_samples);
  for (const std::string& b : summary.covered_branches) out += " " + b;
  detail::appendf(out, "; %ld limit-cycle searches fell back to the grid survey", summary.survey_fallbacks);
  return out + "\n";
}

}  // namespace backlash::api
