#include "backlash/numeric/validation.hpp"

#include "backlash/numeric/reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace backlash::numeric {

const char* to_string(ValidationStatus status) { return status == ValidationStatus::Passed ? "passed" : "failed"; }

namespace {

// Slowest decay rate of y'' + 2αy' + w²y (0 if none decays).
double slow_rate(double alpha, double w2) {
  const double D = alpha * alpha - w2;
  if (D > 0) return w2 / (alpha + std::sqrt(D));
  return alpha;
}

double horizon_from_rates(std::initializer_list<double> rates, double natural_time, const ValidationOptions& o) {
  double slowest = std::numeric_limits<double>::infinity();
  for (double r : rates)
    if (r > 0 && r < slowest) slowest = r;
  const double tau = std::isfinite(slowest) ? 1.0 / slowest : natural_time;
  return std::min(o.time_constants * tau, o.max_horizon);
}

std::vector<double> time_grid(double horizon, int points) {
  std::vector<double> grid{0.0};
  for (double early : {1e-8, 1e-6, 1e-4, 1e-3, 1e-2})
    if (early < horizon) grid.push_back(early);
  for (int i = 1; i <= points; ++i) grid.push_back(horizon * i / points);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

// Number of samples up to and including recombination (gap changed by b, or
// back through 0).
std::size_t until_recombination(const std::vector<FreeState>& reference, double backlash) {
  int sign = 0;
  for (std::size_t i = 1; i < reference.size(); ++i) {
    const double gap = reference[i].gap;
    if (backlash > 0 && std::fabs(gap) >= backlash) return i + 1;
    if (sign == 0) {
      if (std::fabs(gap) > 1e-12) sign = gap > 0 ? 1 : -1;
    } else if (gap * sign <= 0) {
      return i + 1;
    }
  }
  return reference.size();
}

struct Tracker {
  StateError e;
  void see(double error, double t, double v0, double x0, double xd0) {
    ++e.samples;
    if (std::isnan(error)) error = std::numeric_limits<double>::infinity();  // NaN is worse than anything
    if (e.samples == 1 || error > e.max_abs_error) {
      e.max_abs_error = error;
      e.at_t = t;
      e.at_dtheta_m0 = v0;
      e.at_theta_o0 = x0;
      e.at_dtheta_o0 = xd0;
    }
  }
};

}  // namespace

double free_horizon(const Parameters& p, const ValidationOptions& o) {
  const double b = p.FL / p.JL;
  if (p.measured_at == model::MeasuredAt::Load)
    return horizon_from_rates({p.Fm / p.Jm, b}, std::sqrt(p.Jm / p.K), o);
  const double alpha = p.Fm / (2 * p.Jm), w2 = p.K / p.Jm;
  return horizon_from_rates({slow_rate(alpha, w2), b}, 1.0 / std::sqrt(w2), o);
}

double contact_horizon(const Parameters& p, const ValidationOptions& o) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const double alpha = F / (2 * J), w2 = p.K / J;
  return horizon_from_rates({slow_rate(alpha, w2)}, 1.0 / std::sqrt(w2), o);
}

std::string ValidationReport::summary() const {
  std::string out;
  char line[320];
  for (const StateError& s : states) {
    if (s.contact)
      std::snprintf(line, sizeof line, "%-9s max |error| %9.3g at t = %-10.6g theta_o0 = %-10.6g dtheta_o0 = %-10.6g %s\n",
                    s.state.c_str(), s.max_abs_error, s.at_t, s.at_theta_o0, s.at_dtheta_o0, s.passed ? "pass" : "FAIL");
    else
      std::snprintf(line, sizeof line, "%-9s max |error| %9.3g at t = %-10.6g dtheta_m0 = %-10.6g %s\n", s.state.c_str(),
                    s.max_abs_error, s.at_t, s.at_dtheta_m0, s.passed ? "pass" : "FAIL");
    out += line;
  }
  return out;
}

const ValidatedEvaluator& ValidationResult::evaluator() const {
  if (validated_) return *validated_;
  std::string failing;
  char buffer[200];
  for (const StateError& s : report_.states)
    if (!s.passed) {
      std::snprintf(buffer, sizeof buffer, "%s%s max |error| %.3g > %.3g", failing.empty() ? "" : "; ", s.state.c_str(),
                    s.max_abs_error, report_.tolerance);
      failing += buffer;
    }
  throw ValidationFailed("evaluator '" + report_.evaluator + "' did not pass validation against odeint: " + failing);
}

ValidationResult validate(EvaluatorPtr evaluator, const ValidationOptions& o) {
  ValidationResult result;
  ValidationReport& r = result.report_;
  if (!evaluator) throw std::invalid_argument("validate: no evaluator");
  const Parameters& p = evaluator->parameters();
  r.evaluator = evaluator->name();
  r.kind = evaluator->kind();
  r.branches = evaluator->branches();
  r.tolerance = o.tolerance;

  const char* free_names[] = {"theta_m", "dtheta_m", "theta_L", "dtheta_L", "gap"};
  std::vector<Tracker> free(5);
  for (int i = 0; i < 5; ++i) free[i].e.state = free_names[i];

  // Free mode over the θ̇m0 grid.
  r.free_horizon = free_horizon(p, o);
  const std::vector<double> free_times = time_grid(r.free_horizon, o.time_points);
  for (double v0 : o.dtheta_m0_grid) {
    std::vector<double> times = free_times;
    std::vector<FreeState> reference = reference_free_trajectory(p, v0, times, o.odeint_tolerance);
    std::size_t n = until_recombination(reference, p.backlash);
    if (n < reference.size()) {
      // Recombination cuts the segment short: resample [0, t_recombination] as finely.
      times = time_grid(times[n - 1], o.time_points);
      reference = reference_free_trajectory(p, v0, times, o.odeint_tolerance);
      n = until_recombination(reference, p.backlash);
    }
    ++r.free_trajectories;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = times[i];
      const FreeState s = evaluator->free_state(t, v0);
      const FreeState& ref = reference[i];
      const double errors[] = {std::fabs(s.theta_m - ref.theta_m), std::fabs(s.dtheta_m - ref.dtheta_m),
                               std::fabs(s.theta_L - ref.theta_L), std::fabs(s.dtheta_L - ref.dtheta_L),
                               std::fabs(s.gap - ref.gap)};
      for (int k = 0; k < 5; ++k) free[k].see(errors[k], t, v0, 0, 0);
    }
  }

  // Contact mode.
  std::vector<std::pair<double, double>> starts = o.contact_starts;
  if (starts.empty()) {
    const double R = p.theta_R, cot = cot_phi(p);
    starts = {{R - 1, 0}, {R + 1, 0}, {R - 1e-3, 0}, {R + 0.5, -0.3}};
    for (double v : {-1.0, 0.1, 1.0}) starts.push_back({R + cot * v, v});
  }
  Tracker contact[2];
  contact[0].e.state = "theta_o";
  contact[1].e.state = "dtheta_o";
  r.contact_horizon = contact_horizon(p, o);
  const std::vector<double> contact_times = time_grid(r.contact_horizon, o.time_points);
  for (const auto& [x0, xd0] : starts) {
    const std::vector<ContactState> reference =
        reference_contact_trajectory(p, x0, xd0, contact_times, o.odeint_tolerance);
    ++r.contact_trajectories;
    for (std::size_t i = 0; i < contact_times.size(); ++i) {
      const ContactState s = evaluator->contact_state(contact_times[i], x0, xd0);
      contact[0].see(std::fabs(s.theta_o - reference[i].theta_o), contact_times[i], 0, x0, xd0);
      contact[1].see(std::fabs(s.dtheta_o - reference[i].dtheta_o), contact_times[i], 0, x0, xd0);
    }
  }

  Tracker cot;
  cot.e.state = "cot_phi";
  cot.see(std::fabs(evaluator->cot_phi() - cot_phi(p)), 0, 0, 0, 0);

  for (Tracker& t : free) r.states.push_back(t.e);
  for (Tracker& t : contact) {
    t.e.contact = true;
    r.states.push_back(t.e);
  }
  r.states.push_back(cot.e);
  bool all = true;
  for (StateError& s : r.states) {
    s.passed = s.max_abs_error <= o.tolerance;
    all = all && s.passed;
  }
  r.status = all ? ValidationStatus::Passed : ValidationStatus::Failed;
  if (all) result.validated_.emplace(ValidatedEvaluator(evaluator, r));
  return result;
}

}  // namespace backlash::numeric
