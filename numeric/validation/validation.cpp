#include "backlash/numeric/validation.hpp"

#include "backlash/numeric/reference.hpp"
#include "backlash/numeric/scales.hpp"

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

// The horizon: `time_constants` of the slowest decay (or the natural time when nothing decays),
// at most max_horizon, and at most `max_rate_units` units of the fastest rate 1/fastest: the
// reference needs explicit steps of about 1/fastest (an oscillation or a fast decay), so a
// stiff segment (K = 1e12: 1e6 rad/s for 50 s) is compared over its first max_rate_units/fastest
// seconds — some sixty fast periods (400 rad), where the closed form's rounding shows while odeint's own
// error, which grows with the number of periods, stays below the tolerance —
// instead of running the reference for minutes.
double horizon_from_rates(std::initializer_list<double> rates, double natural_time, double fastest,
                          const ValidationOptions& o) {
  double slowest = std::numeric_limits<double>::infinity();
  for (double r : rates)
    if (r > 0 && r < slowest) slowest = r;
  const double tau = std::isfinite(slowest) ? 1.0 / slowest : natural_time;
  double horizon = std::min(o.time_constants * tau, o.max_horizon);
  if (fastest > 0 && std::isfinite(fastest)) horizon = std::min(horizon, o.max_rate_units / fastest);
  return horizon;
}

// 0, the early times below the horizon and horizon·i/points (i = 1…points), ascending, without
// repeats.  Both parts are ascending already (horizon·i/points rounds monotonically in i for a
// horizon > 0), so they are merged instead of sorted: the same grid.
std::vector<double> time_grid(double horizon, int points) {
  std::vector<double> grid;
  grid.reserve(6 + static_cast<std::size_t>(std::max(0, points)));
  grid.push_back(0.0);
  for (double t : {1e-8, 1e-6, 1e-4, 1e-3, 1e-2})
    if (t < horizon) grid.push_back(t);
  const auto early_end = static_cast<std::ptrdiff_t>(grid.size());
  for (int i = 1; i <= points; ++i) grid.push_back(horizon * i / points);
  if (horizon > 0) std::inplace_merge(grid.begin(), grid.begin() + early_end, grid.end());
  else std::sort(grid.begin(), grid.end());  // not ascending (or NaN): sorted as given
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

// Recombination along a free trajectory, sample by sample from the first (t = 0): the gap has
// changed by b, or come back through 0.
class Recombination {
 public:
  explicit Recombination(double backlash) : backlash_(backlash) {}
  /// The next sample's gap; true at the first sample of recombination (and after it).
  bool reached(double gap) {
    if (seen_++ == 0 || found_) return found_;
    if (backlash_ > 0 && std::fabs(gap) >= backlash_) return found_ = true;
    if (sign_ == 0) {
      if (std::fabs(gap) > 1e-12) sign_ = gap > 0 ? 1 : -1;
    } else if (gap * sign_ <= 0) {
      found_ = true;
    }
    return found_;
  }

 private:
  double backlash_;
  long seen_ = 0;
  int sign_ = 0;
  bool found_ = false;
};

// The reference at `times` up to and including the first sample of recombination (all of them
// when there is none): odeint stops there (the samples before are the same bits as a run to the
// end), so fewer states than times means it recombined before the last.
std::vector<FreeState> reference_until_recombination(const Parameters& centred, double v0, const std::vector<double>& times,
                                                     double tolerance) {
  Recombination r(centred.backlash);
  return reference_free_trajectory(centred, v0, times, tolerance, [&r](const FreeState& s) { return r.reached(s.gap); });
}

// The largest absolute error and, separately, the largest error relative to the trajectory's
// own size, max(1, scale): the gate passes on the latter.  Scales are taken from the reference
// in error coordinates (θ − θR), so neither θR nor the stiffness of a segment (velocities of
// 1e3 rad/s when K = 1e6) makes a correct evaluator fail — while a trajectory of unit size or
// smaller keeps the absolute tolerance.
struct Tracker {
  StateError e;
  void see(double error, double scale, double t, double v0, double x0, double xd0) {
    ++e.samples;
    if (std::isnan(error)) error = std::numeric_limits<double>::infinity();  // NaN is worse than anything
    const double unit = std::max(1.0, std::isfinite(scale) ? scale : std::numeric_limits<double>::infinity());
    const double scaled = error / unit;
    if (e.samples == 1 || error > e.max_abs_error) {
      e.max_abs_error = error;
      e.at_t = t;
      e.at_dtheta_m0 = v0;
      e.at_theta_o0 = x0;
      e.at_dtheta_o0 = xd0;
    }
    if (e.samples == 1 || scaled > e.max_scaled_error) {
      e.max_scaled_error = scaled;
      e.scale = unit;
    }
  }
};

}  // namespace

double free_horizon(const Parameters& p, const ValidationOptions& o) {
  const double b = p.FL / p.JL, fastest = fastest_mode_rate(p);
  if (p.measured_at == model::MeasuredAt::Load)
    return horizon_from_rates({p.Fm / p.Jm, b}, std::sqrt(p.Jm / p.K), fastest, o);
  const double alpha = p.Fm / (2 * p.Jm), w2 = p.K / p.Jm;
  return horizon_from_rates({slow_rate(alpha, w2), b}, 1.0 / std::sqrt(w2), fastest, o);
}

double contact_horizon(const Parameters& p, const ValidationOptions& o) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const double alpha = F / (2 * J), w2 = p.K / J;
  return horizon_from_rates({slow_rate(alpha, w2)}, 1.0 / std::sqrt(w2), fastest_mode_rate(p), o);
}

std::string ValidationReport::summary() const {
  std::string out;
  char line[320];
  for (const StateError& s : states) {
    if (s.contact)
      std::snprintf(line, sizeof line, "%-9s max |error| %9.3g at t = %-10.6g theta_o0 = %-10.6g dtheta_o0 = %-10.6g",
                    s.state.c_str(), s.max_abs_error, s.at_t, s.at_theta_o0, s.at_dtheta_o0);
    else
      std::snprintf(line, sizeof line, "%-9s max |error| %9.3g at t = %-10.6g dtheta_m0 = %-10.6g", s.state.c_str(),
                    s.max_abs_error, s.at_t, s.at_dtheta_m0);
    out += line;
    if (s.scale > 1) {  // the trajectory is larger than unit size: the gate compares relative to it
      std::snprintf(line, sizeof line, " (%.3g of scale %.3g)", s.max_scaled_error, s.scale);
      out += line;
    }
    out += s.passed ? " pass\n" : " FAIL\n";
  }
  return out;
}

std::string ValidationReport::failures() const {
  std::string failing;
  char buffer[200];
  for (const StateError& s : states)
    if (!s.passed) {
      std::snprintf(buffer, sizeof buffer, "%s%s max |error| %.3g > %.3g", failing.empty() ? "" : "; ", s.state.c_str(),
                    s.max_scaled_error * s.scale, tolerance * s.scale);
      failing += buffer;
    }
  return failing;
}

const ValidatedEvaluator& ValidationResult::evaluator() const {
  if (validated_) return *validated_;
  throw ValidationFailed("evaluator '" + report_.evaluator + "' did not pass validation against odeint: " +
                         report_.failures());
}

namespace {

// The same evaluator with θR = 0, or nullptr (θR = 0 already, or a generated case).
EvaluatorPtr centred_copy(const SegmentEvaluator& evaluator) {
  const Parameters& p = evaluator.parameters();
  const std::string kind = evaluator.kind();
  if (p.theta_R == 0 || (kind != "parametric" && kind != "direct")) return nullptr;
  Parameters centred = p;
  centred.theta_R = 0;
  return kind == "parametric" ? parametric_evaluator(centred) : direct_branch_evaluator(centred);
}

}  // namespace

std::optional<ValidatedEvaluator> in_error_coordinates(const ValidatedEvaluator& evaluator) {
  EvaluatorPtr shifted = centred_copy(evaluator.evaluator());
  if (!shifted) return std::nullopt;
  return ValidatedEvaluator(std::move(shifted), evaluator.report());
}

namespace {

// The free mode against odeint over the θ̇m0 grid, in error coordinates θ − θR: the reference
// integrates the segment with θR = 0 (the dynamics do not depend on θR), the evaluator's angles
// are shifted by θR.  A reference integrated at θR = 1e4 would carry odeint's relative
// tolerance times 1e4.
void compare_free_mode(const SegmentEvaluator& evaluator, const ValidationOptions& o, ValidationReport& r,
                       std::vector<Tracker>& free) {
  const Parameters& p = evaluator.parameters();
  const double R = p.theta_R;
  Parameters centred = p;
  centred.theta_R = 0;
  r.free_horizon = free_horizon(p, o);
  const std::vector<double> free_times = time_grid(r.free_horizon, o.time_points);
  for (double v0 : o.dtheta_m0_grid) {
    std::vector<double> times = free_times;
    std::vector<FreeState> reference = reference_until_recombination(centred, v0, times, o.odeint_tolerance);
    if (reference.size() < times.size()) {
      // Recombination cuts the segment short: resample [0, t_recombination] as finely.
      times = time_grid(times[reference.size() - 1], o.time_points);
      reference = reference_until_recombination(centred, v0, times, o.odeint_tolerance);
    }
    const std::size_t n = reference.size();
    ++r.free_trajectories;
    double position_scale = 0, motor_speed = 0, load_speed = 0;
    for (std::size_t i = 0; i < n; ++i) {
      position_scale = std::max({position_scale, std::fabs(reference[i].theta_m), std::fabs(reference[i].theta_L)});
      motor_speed = std::max(motor_speed, std::fabs(reference[i].dtheta_m));
      load_speed = std::max(load_speed, std::fabs(reference[i].dtheta_L));
    }
    const double scales[] = {position_scale, motor_speed, position_scale, load_speed, position_scale};
    for (std::size_t i = 0; i < n; ++i) {
      const double t = times[i];
      const FreeState s = evaluator.free_state(t, v0);
      const FreeState& ref = reference[i];
      const double errors[] = {std::fabs((s.theta_m - R) - ref.theta_m), std::fabs(s.dtheta_m - ref.dtheta_m),
                               std::fabs((s.theta_L - R) - ref.theta_L), std::fabs(s.dtheta_L - ref.dtheta_L),
                               std::fabs(s.gap - ref.gap)};
      for (int k = 0; k < 5; ++k) free[k].see(errors[k], scales[k], t, v0, 0, 0);
    }
  }
}

// The contact mode against odeint from the options' starts (by default: at rest on either side
// of θR, near it, moving, and on the separation line), in error coordinates as the free mode.
void compare_contact_mode(const SegmentEvaluator& evaluator, const ValidationOptions& o, ValidationReport& r,
                          Tracker (&contact)[2]) {
  const Parameters& p = evaluator.parameters();
  const double R = p.theta_R;
  Parameters centred = p;
  centred.theta_R = 0;
  std::vector<std::pair<double, double>> starts = o.contact_starts;
  if (starts.empty()) {
    const double cot = cot_phi(p);
    starts = {{R - 1, 0}, {R + 1, 0}, {R - 1e-3, 0}, {R + 0.5, -0.3}};
    for (double v : {-1.0, 0.1, 1.0}) starts.push_back({R + cot * v, v});
  }
  r.contact_horizon = contact_horizon(p, o);
  const std::vector<double> contact_times = time_grid(r.contact_horizon, o.time_points);
  for (const auto& [x0, xd0] : starts) {
    const std::vector<ContactState> reference =
        reference_contact_trajectory(centred, x0 - R, xd0, contact_times, o.odeint_tolerance);
    ++r.contact_trajectories;
    double position_scale = 0, speed = 0;
    for (const ContactState& c : reference) {
      position_scale = std::max(position_scale, std::fabs(c.theta_o));
      speed = std::max(speed, std::fabs(c.dtheta_o));
    }
    for (std::size_t i = 0; i < contact_times.size(); ++i) {
      const ContactState s = evaluator.contact_state(contact_times[i], x0, xd0);
      contact[0].see(std::fabs((s.theta_o - R) - reference[i].theta_o), position_scale, contact_times[i], 0, x0, xd0);
      contact[1].see(std::fabs(s.dtheta_o - reference[i].dtheta_o), speed, contact_times[i], 0, x0, xd0);
    }
  }
}

}  // namespace

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
  const EvaluatorPtr centred = o.error_coordinates ? centred_copy(*evaluator) : nullptr;
  const SegmentEvaluator& compared = centred ? *centred : *evaluator;
  compare_free_mode(compared, o, r, free);
  Tracker contact[2];
  contact[0].e.state = "theta_o";
  contact[1].e.state = "dtheta_o";
  compare_contact_mode(compared, o, r, contact);
  Tracker cot;
  cot.e.state = "cot_phi";
  cot.see(std::fabs(evaluator->cot_phi() - cot_phi(p)), std::fabs(cot_phi(p)), 0, 0, 0, 0);

  for (Tracker& t : free) r.states.push_back(t.e);
  for (Tracker& t : contact) {
    t.e.contact = true;
    r.states.push_back(t.e);
  }
  r.states.push_back(cot.e);
  bool all = true;
  for (StateError& s : r.states) {
    s.passed = s.max_scaled_error <= o.tolerance;
    all = all && s.passed;
  }
  r.status = all ? ValidationStatus::Passed : ValidationStatus::Failed;
  if (all) result.validated_.emplace(ValidatedEvaluator(evaluator, r));
  return result;
}

}  // namespace backlash::numeric
