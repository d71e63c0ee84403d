// sweep.cpp — limit cycles over a parameter (thesis figs. 31, 32, or any case), and the CSV.
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace backlash::api {

namespace {

std::string number_text(double value) {
  std::string out;
  detail::appendf(out, "%g", value);
  return out;
}

const char* vary_names =
    "Jm, Fm, JL, FL, K, backlash, reference, JL_over_Jm, FL_over_F, coulomb_motor, coulomb_load, restitution, "
    "saturation, stiffness, damping, delay, torque_offset";

std::vector<numeric::SweepPoint> case_points(const SweepRequest& r) {
  if (r.vary.empty()) throw BadInput("vary", "required for a case (or use fig31 / fig32 as the target)");
  if (!std::isfinite(r.from)) throw BadInput("from", "not finite, got " + number_text(r.from));
  if (!std::isfinite(r.to)) throw BadInput("to", "not finite, got " + number_text(r.to));
  const Case c = Case::load(r.target);
  const numeric::Parameters base = c.parameters();
  const numeric::Effects base_effects = c.effects();
  const std::string& v = r.vary;
  const int n = r.points;
  std::vector<numeric::SweepPoint> points;
  for (int i = 0; i < n; ++i) {
    const double x = n == 1 ? r.from : r.from + (r.to - r.from) * i / double(n - 1);
    numeric::Parameters p = base;
    numeric::Effects e = base_effects;
    if (v == "Jm") p.Jm = x;
    else if (v == "Fm") p.Fm = x;
    else if (v == "JL") p.JL = x;
    else if (v == "FL") p.FL = x;
    else if (v == "K") p.K = x;
    else if (v == "backlash") p.backlash = x;
    else if (v == "reference") p.theta_R = x;
    else if (v == "JL_over_Jm") { const double J = base.Jm + base.JL; p.Jm = J / (1 + x); p.JL = J * x / (1 + x); }
    else if (v == "FL_over_F") { const double F = base.Fm + base.FL; p.FL = x * F; p.Fm = F - p.FL; }
    else if (v == "coulomb_motor") e.coulomb_motor = x;
    else if (v == "coulomb_load") e.coulomb_load = x;
    else if (v == "restitution") e.restitution = x;
    else if (v == "saturation") e.saturation = x;
    else if (v == "stiffness") e.mesh_stiffness = x;
    else if (v == "damping") e.mesh_damping = x;
    else if (v == "delay") e.delay = x;
    else if (v == "torque_offset") e.torque_offset = x;
    else throw BadInput("vary", "unknown parameter '" + v + "' (" + vary_names + ")");
    if (!(p.Jm > 0) || !(p.JL > 0) || p.Fm < 0 || p.FL < 0 || !(p.K > 0) || p.backlash < 0)
      throw BadInput("from/to", v + " = " + std::to_string(x) + " gives non-physical parameters");
    if (e.coulomb_motor < 0 || e.coulomb_load < 0 || e.restitution < 0 || e.restitution >= 1 || !(e.saturation > 0) ||
        !(e.mesh_stiffness > 0) || e.mesh_damping < 0 || e.delay < 0)
      throw BadInput("from/to", v + " = " + std::to_string(x) + " is outside the effect's range (docs/effects.md)");
    if (e.restitution > 0 && e.compliant())
      throw BadInput("vary", v + ": restitution and compliance both model the impact; give one of them");
    if ((v == "stiffness" || v == "damping") && !e.compliant())
      throw BadInput("vary", v + ": the case has no [effects] compliance to vary (give one in the case file)");
    points.push_back({c.id() + ":" + v, x, p, e});
  }
  return points;
}

}  // namespace

std::vector<numeric::SweepPoint> sweep_points(const SweepRequest& r) {
  if (r.points < 1) throw BadInput("points", "expected an integer >= 1, got " + std::to_string(r.points));
  if (r.threads < 1) throw BadInput("threads", "expected an integer >= 1, got " + std::to_string(r.threads));
  if (r.target.empty()) throw BadInput("target", "expected fig31, fig32 or a case (I..VIII or a case file)");
  if (r.target == "fig31") return numeric::figure31_points(r.points);
  if (r.target == "fig32") return numeric::figure32_points(r.points);
  return case_points(r);
}

Sweep sweep(const SweepRequest& r) {
  const std::vector<numeric::SweepPoint> points = sweep_points(r);
  numeric::SweepOptions options;
  options.threads = r.threads;
  options.progress = r.progress;
  Sweep out;
  out.threads = r.threads;
  out.rows = numeric::run_sweep(points, options, &out.summary);
  return out;
}

std::string status_of(const numeric::SweepRow& row) { return detail::status_text(row.status); }

std::string Sweep::csv() const {
  std::ostringstream csv;
  csv.precision(12);
  csv << "series,x,Jm,Fm,JL,FL,K,backlash,effects,status,branches,peak_to_peak,amplitude,period,separation_velocity,multiplier\n";
  for (const numeric::SweepRow& r : rows) {
    const numeric::Parameters& p = r.point.parameters;
    std::string effects = r.point.effects.describe();
    std::replace(effects.begin(), effects.end(), ',', ';');  // one CSV cell
    effects.erase(std::remove(effects.begin(), effects.end(), ' '), effects.end());
    csv << r.point.series << "," << r.point.x << "," << p.Jm << "," << p.Fm << "," << p.JL << "," << p.FL << "," << p.K << ","
        << p.backlash << "," << effects << "," << status_of(r) << "," << r.branches;
    if (r.status == numeric::SweepStatus::LimitCycle) {
      csv << "," << r.cycle.peak_to_peak << "," << r.cycle.amplitude << "," << r.cycle.period << ",";
      if (std::isfinite(r.cycle.separation_velocity)) csv << r.cycle.separation_velocity;  // none: a pure bounce cycle
      csv << "," << r.cycle.multiplier << "\n";
    } else {
      csv << ",,,,,\n";
    }
  }
  return csv.str();
}

std::string Sweep::summary_line() const {
  std::string out;
  detail::appendf(out, "sweep: %zu points on %d threads; parametric family validated at %ld samples (%ld failed), branches:",
                  rows.size(), threads, summary.validated_samples, summary.failed_samples);
  for (const std::string& b : summary.covered_branches) out += " " + b;
  return out + "\n";
}

}  // namespace backlash::api
