#include "backlash/numeric/limit_cycle.hpp"

#include "backlash/numeric/describing_function.hpp"
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace backlash::numeric {

namespace {

// The separation state on the line with θ̇o = v, having left face σ = −sign(v).
HybridState separation_state(const ValidatedEvaluator& evaluator, double v) {
  return state_on_face(evaluator.parameters(), v > 0 ? -1 : +1, evaluator.evaluator().separation_theta(v), v, false);
}

// 60 of the system's slowest time scales (which include the contact period 2π√(J/K)): in the
// system's own time, never a floor in seconds — a floor of 100 s was 1e8 contact periods of a
// servo with K = 1e12 (it never bound for the thesis's cases: 60 periods of 2π s exceed it).
double horizon(const Parameters& p) { return 60 * slowest_time_scale(p); }

}  // namespace

const char* to_string(CycleStatus status) {
  switch (status) {
    case CycleStatus::LimitCycle: return "limit_cycle";
    case CycleStatus::None: return "none";
    case CycleStatus::Divergent: return "divergent";
    case CycleStatus::Unresolved: return "unresolved";
  }
  return "none";
}

std::ostream& operator<<(std::ostream& out, CycleStatus status) { return out << to_string(status); }

double limit_cycle_velocity_unit(const Parameters& p) {
  // The model is homogeneous: scaling the backlash scales every cycle, and time scales with
  // √(J/K).  θR plays no part (it only shifts the angles).
  return p.backlash / 0.3 * std::sqrt(p.K / (p.Jm + p.JL));
}

HalfCycle half_cycle(const ValidatedEvaluator& evaluator, double v, bool track_extremes) {
  const Parameters& p = evaluator.parameters();
  HalfCycle h;
  h.v_in = v;
  SimulationOptions options;
  options.t_end = horizon(p);
  options.stop_after_separations = 1;
  options.max_events = 1000;
  options.track_extremes = track_extremes;
  SimulationResult r = simulate(evaluator, separation_state(evaluator, v), options);
  for (const SimulationEvent& e : r.events) h.bounced = h.bounced || e.bounce;
  h.extremes = r.extremes;
  if (r.events.empty() || r.events.back().kind != EventKind::Separation) {
    h.outcome = r.status == SimulationStatus::Rest ? "rest: no recombination"
                                                   : std::string("no separation within the horizon (") + to_string(r.status) + ")";
    return h;
  }
  const SimulationEvent& s = r.events.back();
  if (s.dtheta_o * v >= 0) {
    h.outcome = "the next separation leaves the same face";
    return h;
  }
  h.valid = true;
  h.v_out = -s.dtheta_o;
  h.duration = s.t;
  h.events = std::move(r.events);
  return h;
}

double stability_constant(const Parameters& p, double theta_o, double dtheta_o) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, a = F / (2 * J);
  const double omega2 = p.K / J - a * a;
  if (!(omega2 > 0)) return std::numeric_limits<double>::quiet_NaN();
  const double omega = std::sqrt(omega2), e = p.theta_R - theta_o;
  const double Q = dtheta_o * dtheta_o - F / J * dtheta_o * e + p.K / J * e * e;
  return std::sqrt(Q) / omega * std::exp(a / omega * std::atan((dtheta_o - a * e) / (e * omega)));
}

double stability_constant_jump(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, a = F / (2 * J);
  return std::exp(-M_PI * a / std::sqrt(p.K / J - a * a));
}

namespace {

// h(v) = g(v) − v, NaN where the half cycle does not return to the line.
double excess(const ValidatedEvaluator& evaluator, double v) {
  const HalfCycle hc = half_cycle(evaluator, v);
  return hc.valid ? hc.v_out - v : std::nan("");
}

bool converged(double a, double b) { return std::fabs(b - a) <= 1e-13 * std::max(1.0, std::fabs(b)); }

// g'(v) from the closed forms, for the half cycle of one flight and one contact arc (events:
// a recombination that holds, then the separation).  In error coordinates θ − θR every mode is
// linear and homogeneous: the flight from the separation line is v·(its flight for v = 1), so
// ∂x/∂v = (x − θR)/v, and the contact arc maps (θo − θR, θ̇o) linearly (Φ).  The event times
// move with v (dt = −(∂guard/∂v)/(dguard/dt)), the impact (eq. 24) is linear, and g = −θ̇o at the
// separation Tc = r·y + r0 = 0 (segment_dynamics.hpp).  Nothing for other half cycles (bounces).
std::optional<double> closed_form_derivative(const ValidatedEvaluator& evaluator, const HalfCycle& h) {
  const Parameters& p = evaluator.parameters();
  if (!h.valid || h.events.size() != 2) return std::nullopt;
  const SimulationEvent &impact = h.events[0], &separation = h.events[1];
  if (impact.kind != EventKind::Recombination || impact.bounce || separation.kind != EventKind::Separation)
    return std::nullopt;
  const double v = h.v_in, t1 = impact.t, R = p.theta_R;
  const FreeState f = evaluator.free_state(t1, v);
  const double em = f.theta_m - R, eL = f.theta_L - R;
  const double ddm = -(p.Fm * f.dtheta_m + p.K * (p.measured_at == model::MeasuredAt::Load ? eL : em)) / p.Jm;
  const double ddL = -p.FL * f.dtheta_L / p.JL;
  const double dt1 = -(f.gap / v) / (f.dtheta_L - f.dtheta_m);  // the gap moves by −σb whatever v
  const double dm = em / v + f.dtheta_m * dt1, dL = eL / v + f.dtheta_L * dt1;
  const double dvm = f.dtheta_m / v + ddm * dt1, dvL = f.dtheta_L / v + ddL * dt1;
  const double w0 = p.measured_at == model::MeasuredAt::Load ? dL : dm, w1 = (p.Jm * dvm + p.JL * dvL) / (p.Jm + p.JL);
  // The contact arc: y(τ2) moves by Φ(τ2)·w + ẏ·dτ2, with r·y(τ2) + r0 = 0.
  Parameters centred = p;
  centred.theta_R = 0;
  const ContactState phi_w = contact_state(centred, separation.t - t1, w0, w1);
  const TransmittedTorque tc = transmitted_torque(p);
  const double ddo = contact_acceleration(p, separation.theta_o, separation.dtheta_o);
  const double r_ydot = tc.r(0) * separation.dtheta_o + tc.r(1) * ddo;
  const double dt2 = -(tc.r(0) * phi_w.theta_o + tc.r(1) * phi_w.dtheta_o) / r_ydot;
  const double derivative = -(phi_w.dtheta_o + ddo * dt2);
  return std::isfinite(derivative) ? std::optional<double>(derivative) : std::nullopt;
}

// A fixed point found by Newton's method: v*, g'(v*) and the half cycle there (with extremes).
struct NewtonResult {
  double v, derivative;
  HalfCycle half;
};

// Whether Newton's next step is expected to be its last (below 1e-13 v): quadratic convergence,
// s_{k+1} ≈ C s_k² with C = s_k / s_{k−1}² from the last two steps (1/v after one step).  Only
// then is the half cycle computed with its extremes (the result needs them at the last v alone;
// a wrong guess costs one more half cycle, never a different answer).
bool expect_last(double v, double step, double step_before) {
  const double C = std::isfinite(step_before) ? step / (step_before * step_before) : 1 / v;
  return C * step * step <= 1e-13 * v;
}

// Newton's method on h(v) = g(v) − v from `guess`, g' from the closed forms: v* when the steps
// settle (the last one below 1e-13 v, or at the noise floor of g below 1e-11 v) on a stable
// fixed point (|g'| < 1) within [guess/4, 4·guess]; nothing otherwise (the caller surveys).
std::optional<NewtonResult> newton_fixed_point(const ValidatedEvaluator& evaluator, double guess) {
  double v = guess, previous_step = INFINITY, step_before = INFINITY;
  for (int i = 0; i < 16; ++i) {
    const bool extremes = std::isfinite(previous_step) && expect_last(v, previous_step, step_before);
    HalfCycle h = half_cycle(evaluator, v, extremes);
    const std::optional<double> d = closed_form_derivative(evaluator, h);
    if (!d || !(*d < 1)) return std::nullopt;
    const double step = (h.v_out - v) / (*d - 1);
    const double size = std::fabs(step);
    if (size <= 1e-13 * v || (size <= 1e-11 * v && size >= 0.5 * previous_step)) {
      if (!(std::fabs(*d) < 1) || !(h.duration > 0)) return std::nullopt;
      if (!extremes) h = half_cycle(evaluator, v, true);
      return NewtonResult{v, *d, std::move(h)};
    }
    step_before = previous_step;
    previous_step = size;
    v -= step;
    if (!(v > guess / 4 && v < 4 * guess)) return std::nullopt;
  }
  return std::nullopt;
}

// What the logarithmic grid of the bracketing search saw: the half cycles that returned to the
// separation line, those whose separation velocity grew or decayed, and why the last one did not.
struct GridSurvey {
  int valid = 0, growing = 0, decaying = 0;
  double v_lowest = 0, v_highest = 0;
  std::string last_failure;
};

// h(v) = g(v) − v on a logarithmic grid; every sign change between returning half cycles is
// refined with toms748 to a fixed point.
std::vector<double> bracketed_roots(const ValidatedEvaluator& evaluator, const LimitCycleOptions& options, GridSurvey& s) {
  const double scale = limit_cycle_velocity_unit(evaluator.parameters());
  std::vector<std::pair<double, double>> samples;
  for (int i = 0; i < options.grid; ++i) {
    const double v = scale * options.v_min * std::pow(options.v_max / options.v_min, i / double(options.grid - 1));
    const HalfCycle hc = half_cycle(evaluator, v);
    samples.push_back({v, hc.valid ? hc.v_out - v : std::nan("")});
    if (!hc.valid) s.last_failure = hc.outcome;
    if (hc.valid) {
      if (s.valid++ == 0) s.v_lowest = v;
      s.v_highest = v;
      if (hc.v_out > v) ++s.growing;
      if (hc.v_out < v) ++s.decaying;
    }
  }
  std::vector<double> roots;
  for (size_t i = 1; i < samples.size(); ++i) {
    const auto [v0, h0] = samples[i - 1];
    const auto [v1, h1] = samples[i];
    if (std::isnan(h0) || std::isnan(h1) || (h0 > 0) == (h1 > 0)) continue;
    boost::uintmax_t iterations = 100;
    const auto r = boost::math::tools::toms748_solve([&](double v) { return excess(evaluator, v); }, v0, v1, h0, h1,
                                                     [](double a, double b) { return converged(a, b); }, iterations);
    roots.push_back(0.5 * (r.first + r.second));
  }
  return roots;
}

// No fixed point: the status and the reason, from what the samples showed and nothing more.
LimitCycle without_fixed_point(const Parameters& p, const LimitCycleOptions& options, const GridSurvey& s) {
  LimitCycle cycle;
  char range[160];
  std::snprintf(range, sizeof range, "%d of %d sampled separation velocities in [%.3g, %.3g]", s.valid, options.grid,
                s.v_lowest, s.v_highest);
  if (s.valid == 0) {
    cycle.reason = "no half cycle returns to the separation line (" + s.last_failure + ")";
  } else if (s.growing == s.valid) {
    cycle.status = CycleStatus::Divergent;
    cycle.reason = std::string("divergent: the separation velocity grows every half cycle (g(v) > v at ") + range +
                   "), so the oscillation grows instead of settling on a cycle";
  } else if (s.decaying == s.valid) {
    cycle.reason = std::string("the half-cycle map has no fixed point: the separation velocity decays every half cycle "
                               "(g(v) < v at ") + range + ")";
  } else {
    cycle.reason = std::string("the half-cycle map has no fixed point between returning half cycles (g(v) − v changes "
                               "sign only across velocities whose half cycle does not return: ") + s.last_failure + "; " +
                   range + " return)";
  }
  if (p.measured_at == model::MeasuredAt::Motor && s.decaying == s.valid && s.valid > 0)
    cycle.reason += "; the backlash is outside the loop, so the system settles with a steady-state error";
  return cycle;
}

// The cycle among the fixed points: the first stable one (|g'| < 1), else the first.  g'(v) from
// the closed forms (closed_form_derivative), else by central differences (g is smooth away from
// grazing), always at the root itself: the multiplier must not depend on where the search started.
void choose_fixed_point(const ValidatedEvaluator& evaluator, const std::vector<double>& roots, LimitCycle& cycle) {
  auto derivative = [&](double v) {
    if (const std::optional<double> d = closed_form_derivative(evaluator, half_cycle(evaluator, v))) return *d;
    const double h = 1e-6 * v;
    return (half_cycle(evaluator, v + h).v_out - half_cycle(evaluator, v - h).v_out) / (2 * h);
  };
  double chosen = roots.front();
  double chosen_derivative = derivative(chosen);
  for (double r : roots) {
    if (r == chosen) continue;
    const double d = derivative(r);
    if (std::fabs(d) < 1 && !(std::fabs(chosen_derivative) < 1)) { chosen = r; chosen_derivative = d; }
  }
  for (double r : roots) if (r != chosen) cycle.other_fixed_points.push_back(r);
  cycle.status = CycleStatus::LimitCycle;
  cycle.separation_velocity = chosen;
  cycle.half_map_derivative = chosen_derivative;
  cycle.multiplier = chosen_derivative * chosen_derivative;
  cycle.stable = cycle.multiplier < 1;
}

// The cycle's extremes from the half cycle's: the other half is its mirror image about θR.
void mirror_extremes(const Parameters& p, const Extremes& x, LimitCycle& cycle) {
  const double R2 = 2 * p.theta_R;
  auto full_max = [&](double lo, double hi) { return std::max(hi, R2 - lo); };
  auto full_min = [&](double lo, double hi) { return std::min(lo, R2 - hi); };
  cycle.theta_o_max = full_max(x.theta_o_min, x.theta_o_max);
  cycle.theta_o_min = full_min(x.theta_o_min, x.theta_o_max);
  cycle.amplitude = std::max(cycle.theta_o_max - p.theta_R, p.theta_R - cycle.theta_o_min);
  cycle.peak_to_peak = cycle.theta_o_max - cycle.theta_o_min;
  cycle.peak_to_peak_motor = full_max(x.theta_m_min, x.theta_m_max) - full_min(x.theta_m_min, x.theta_m_max);
  cycle.peak_to_peak_load = full_max(x.theta_L_min, x.theta_L_max) - full_min(x.theta_L_min, x.theta_L_max);
}

// Eq. 38 just after the recombination `e` of the half cycle, and the crossings of θo = θR
// (where the principal branch of C jumps) strictly inside the contact arc that follows, up to
// the separation at `arc_end`.
void contact_arc(const ValidatedEvaluator& evaluator, const SimulationEvent& e, double arc_end, LimitCycle& cycle) {
  const Parameters& p = evaluator.parameters();
  cycle.theta_o_recombination = e.theta_o;
  cycle.dtheta_o_recombination = e.dtheta_o;
  cycle.C_recombination = stability_constant(p, e.theta_o, e.dtheta_o);
  const double arc = arc_end - e.t;
  const LinearSegment contact = contact_mode_segment(p);
  LinearWitness w;
  w.A = contact.A;
  w.c = contact.c;
  w.e = SmallRow::Zero(2);
  w.e(0) = 1;
  w.level = p.theta_R;
  w.time_unit = servo_time_unit(p);
  w.state = [&evaluator, e](double tau) {
    const ContactState c = evaluator.contact_state(tau, e.theta_o, e.dtheta_o);
    SmallVector y(2);
    y << c.theta_o, c.dtheta_o;
    return y;
  };
  double from = 0;
  // Crossings strictly inside the arc (when cot φ = 0 the separation itself is at θo = θR).
  const double end = arc * (1 - 1e-9);
  while (const auto crossing = first_crossing(w, from, end)) {
    if (!crossing->grazing) ++cycle.contact_arc_crossings_of_theta_R;
    from = crossing->t + 1e-12 * std::max(w.time_unit, crossing->t);
    if (from >= arc) break;
  }
}

}  // namespace

void shift_angles(LimitCycle& cycle, double offset) {
  if (offset == 0) return;
  cycle.theta_o_max += offset;
  cycle.theta_o_min += offset;
  cycle.theta_o_separation += offset;
  cycle.theta_o_recombination += offset;
  for (double* angle : {&cycle.section_state.theta_m, &cycle.section_state.theta_L}) *angle += offset;
}

LimitCycle find_limit_cycle(const ValidatedEvaluator& evaluator, const LimitCycleOptions& options) {
  // In error coordinates (θR = 0): nothing depends on θR, and the gap keeps its digits; the
  // cycle's angles are shifted back at the end.
  if (const std::optional<ValidatedEvaluator> centred = in_error_coordinates(evaluator)) {
    LimitCycle cycle = find_limit_cycle(*centred, options);
    shift_angles(cycle, evaluator.parameters().theta_R);
    return cycle;
  }
  const Parameters& p = evaluator.parameters();
  LimitCycle cycle;
  if (p.backlash <= 0) {
    cycle.reason = "no backlash: a rigid drive never separates, so there is no cycle";
    return cycle;
  }
  // Newton's method from the neighbour's cycle (options.guess), else from the describing
  // function's; the logarithmic grid survey only when neither settles on a stable cycle.
  std::optional<NewtonResult> newton;
  auto from = [&](double guess) {
    if (!newton && !options.survey_only && guess > 0 && std::isfinite(guess)) newton = newton_fixed_point(evaluator, guess);
  };
  from(options.guess);
  if (!newton) from(describing_function_separation_velocity(p));
  HalfCycle half;
  if (newton) {
    cycle.status = CycleStatus::LimitCycle;
    cycle.separation_velocity = newton->v;
    cycle.half_map_derivative = newton->derivative;
    cycle.multiplier = newton->derivative * newton->derivative;
    cycle.stable = true;
    half = std::move(newton->half);
    if (options.list_other_fixed_points) {
      GridSurvey survey;
      for (double r : bracketed_roots(evaluator, options, survey))
        if (std::fabs(r - newton->v) > 1e-9 * newton->v) cycle.other_fixed_points.push_back(r);
    }
  } else {
    GridSurvey survey;
    const std::vector<double> roots = bracketed_roots(evaluator, options, survey);
    if (roots.empty()) {
      LimitCycle none = without_fixed_point(p, options, survey);
      none.survey_fallback = true;
      return none;
    }
    choose_fixed_point(evaluator, roots, cycle);
    cycle.survey_fallback = true;
    // The half cycle at v*, with its exact extremes; the other half is its mirror image about θR.
    half = half_cycle(evaluator, cycle.separation_velocity, true);
  }
  const double chosen = cycle.separation_velocity;
  if (!half.valid || !(half.duration > 0)) {
    // The root lies where the half cycle does not return (g jumps there, e.g. across a grazing
    // or a same-face separation): no cycle, never one with period 0.  (Found by the soak test.)
    LimitCycle none;
    none.survey_fallback = cycle.survey_fallback;
    none.reason = "the half-cycle map changes sign at v = " + std::to_string(chosen) +
                  " only across a discontinuity: the half cycle there does not return to the separation line (" +
                  (half.valid ? std::string("it returns at once") : half.outcome) + ")";
    return none;
  }
  cycle.period = 2 * half.duration;
  cycle.bounced = half.bounced;
  mirror_extremes(p, half.extremes, cycle);
  // Eq. 38 at separation and just after the recombination of this half cycle.
  cycle.theta_o_separation = evaluator.evaluator().separation_theta(chosen);
  cycle.C_separation = stability_constant(p, cycle.theta_o_separation, chosen);
  for (const SimulationEvent& e : half.events) {
    if (e.kind != EventKind::Recombination) continue;
    contact_arc(evaluator, e, half.events.back().t, cycle);
    break;
  }
  return cycle;
}

}  // namespace backlash::numeric
