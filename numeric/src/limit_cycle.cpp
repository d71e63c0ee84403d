#include "backlash/numeric/limit_cycle.hpp"

#include "backlash/numeric/segment_dynamics.hpp"

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <cmath>

namespace backlash::numeric {

namespace {

// The separation state on the line with θ̇o = v, having left face σ = −sign(v).
HybridState separation_state(const ValidatedEvaluator& evaluator, double v) {
  const Parameters& p = evaluator.parameters();
  const int face = v > 0 ? -1 : +1;
  HybridState s;
  s.in_contact = false;
  s.face = face;
  s.dtheta_m = s.dtheta_L = v;
  const double theta_o = evaluator.evaluator().separation_theta(v);
  const double x = face * p.backlash / 2;
  if (p.measured_at == model::MeasuredAt::Motor) {
    s.theta_m = theta_o;
    s.theta_L = theta_o + x;
  } else {
    s.theta_L = theta_o;
    s.theta_m = theta_o - x;
  }
  return s;
}

double horizon(const Parameters& p) { return std::max(100.0, 60 * slowest_time_scale(p)); }

}  // namespace

HalfCycle half_cycle(const ValidatedEvaluator& evaluator, double v) {
  const Parameters& p = evaluator.parameters();
  HalfCycle h;
  h.v_in = v;
  SimulationOptions options;
  options.t_end = horizon(p);
  options.stop_after_separations = 1;
  options.max_events = 1000;
  const SimulationResult r = simulate(evaluator, separation_state(evaluator, v), options);
  for (const SimulationEvent& e : r.events) h.bounced = h.bounced || e.bounce;
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

LimitCycle find_limit_cycle(const ValidatedEvaluator& evaluator, const LimitCycleOptions& options) {
  const Parameters& p = evaluator.parameters();
  LimitCycle cycle;
  if (p.backlash <= 0) {
    cycle.reason = "no backlash";
    return cycle;
  }
  const double scale = std::max(1.0, std::fabs(p.theta_R));
  // h(v) = g(v) − v on a logarithmic grid; brackets where it changes sign between valid points.
  std::vector<std::pair<double, double>> samples;
  std::string last_failure;
  for (int i = 0; i < options.grid; ++i) {
    const double v = scale * options.v_min * std::pow(options.v_max / options.v_min, i / double(options.grid - 1));
    const HalfCycle hc = half_cycle(evaluator, v);
    if (hc.valid) samples.push_back({v, hc.v_out - v}); else { samples.push_back({v, std::nan("")}); last_failure = hc.outcome; }
  }
  auto g_minus_v = [&](double v) {
    const HalfCycle hc = half_cycle(evaluator, v);
    return hc.valid ? hc.v_out - v : std::nan("");
  };
  std::vector<double> roots;
  for (size_t i = 1; i < samples.size(); ++i) {
    const auto [v0, h0] = samples[i - 1];
    const auto [v1, h1] = samples[i];
    if (std::isnan(h0) || std::isnan(h1) || (h0 > 0) == (h1 > 0)) continue;
    boost::uintmax_t iterations = 100;
    const auto r = boost::math::tools::toms748_solve(
        g_minus_v, v0, v1, h0, h1, [](double a, double b) { return std::fabs(b - a) <= 1e-13 * std::max(1.0, b); },
        iterations);
    roots.push_back(0.5 * (r.first + r.second));
  }
  if (roots.empty()) {
    bool any_valid = false;
    for (const auto& s : samples) any_valid = any_valid || !std::isnan(s.second);
    cycle.reason = any_valid ? "the half-cycle map has no fixed point: every separation velocity decays (g(v) < v)"
                             : "no half cycle returns to the separation line (" + last_failure + ")";
    if (p.measured_at == model::MeasuredAt::Motor)
      cycle.reason += "; the backlash is outside the loop, so the system settles with a steady-state error";
    return cycle;
  }
  // The stable cycle (|g'| < 1), else the first.
  auto derivative = [&](double v) {
    const double h = 1e-6 * v;
    const HalfCycle a = half_cycle(evaluator, v - h), b = half_cycle(evaluator, v + h);
    return (b.v_out - a.v_out) / (2 * h);
  };
  double chosen = roots.front(), chosen_derivative = derivative(chosen);
  for (double r : roots) {
    const double d = derivative(r);
    if (std::fabs(d) < 1 && !(std::fabs(chosen_derivative) < 1)) { chosen = r; chosen_derivative = d; }
  }
  for (double r : roots) if (r != chosen) cycle.other_fixed_points.push_back(r);
  cycle.status = "limit_cycle";
  cycle.separation_velocity = chosen;
  cycle.half_map_derivative = chosen_derivative;
  cycle.multiplier = chosen_derivative * chosen_derivative;
  cycle.stable = cycle.multiplier < 1;

  // One full period (two mirrored halves), sampled densely for the swings; extrema refined by Brent.
  SimulationOptions options_cycle;
  options_cycle.t_end = horizon(p);
  options_cycle.stop_after_separations = 2;
  const HybridState start = separation_state(evaluator, chosen);
  const SimulationResult full = simulate(evaluator, start, options_cycle);
  cycle.period = full.t_final;
  for (const SimulationEvent& e : full.events) cycle.bounced = cycle.bounced || e.bounce;
  SimulationOptions sampled = options_cycle;
  sampled.sample_interval = cycle.period / 20000;
  const SimulationResult trajectory = simulate(evaluator, start, sampled);
  double o_max = -INFINITY, o_min = INFINITY, m_max = -INFINITY, m_min = INFINITY, l_max = -INFINITY, l_min = INFINITY;
  for (const TrajectorySample& s : trajectory.samples) {
    o_max = std::max(o_max, s.theta_o); o_min = std::min(o_min, s.theta_o);
    m_max = std::max(m_max, s.theta_m); m_min = std::min(m_min, s.theta_m);
    l_max = std::max(l_max, s.theta_L); l_min = std::min(l_min, s.theta_L);
  }
  // Refine the measured shaft's extremes: by symmetry the cycle is odd about θR.
  auto theta_o_at = [&](double t) {
    SimulationOptions o = options_cycle;
    o.t_end = t;
    o.stop_after_separations = 0;
    return simulate(evaluator, start, o).theta_o_final;
  };
  const double dt = sampled.sample_interval;
  auto refine = [&](double sign, double best) {
    double t_best = 0;
    for (const TrajectorySample& s : trajectory.samples) if (s.theta_o * sign >= best * sign) t_best = s.t;
    const auto r = boost::math::tools::brent_find_minima([&](double t) { return -sign * theta_o_at(t); },
                                                         std::max(1e-12, t_best - dt), t_best + dt, 50);
    return std::max(best * sign, -r.second) * sign;
  };
  o_max = refine(+1, o_max);
  o_min = refine(-1, o_min);
  // Extremes at a kink (an impact reverses θ̇o) are event states, exact.
  for (const SimulationEvent& e : full.events) {
    o_max = std::max(o_max, e.theta_o);
    o_min = std::min(o_min, e.theta_o);
  }
  cycle.theta_o_max = o_max;
  cycle.theta_o_min = o_min;
  cycle.amplitude = std::max(std::fabs(o_max - p.theta_R), std::fabs(o_min - p.theta_R));
  cycle.peak_to_peak = o_max - o_min;
  cycle.peak_to_peak_motor = m_max - m_min;
  cycle.peak_to_peak_load = l_max - l_min;

  // Eq. 38 at separation and just after the (first) recombination of the cycle.
  cycle.theta_o_separation = evaluator.evaluator().separation_theta(chosen);
  cycle.C_separation = stability_constant(p, cycle.theta_o_separation, chosen);
  for (const SimulationEvent& e : full.events) {
    if (e.kind != EventKind::Recombination) continue;
    cycle.theta_o_recombination = e.theta_o;
    cycle.dtheta_o_recombination = e.dtheta_o;
    cycle.C_recombination = stability_constant(p, e.theta_o, e.dtheta_o);
    // The contact arc from here to the next separation: does it cross θo = θR?
    const SimulationEvent* next = nullptr;
    for (const SimulationEvent& f : full.events) if (f.t > e.t && f.kind == EventKind::Separation) { next = &f; break; }
    if (next) {
      int crossings = 0;
      double previous = e.theta_o - p.theta_R;
      for (const TrajectorySample& s : trajectory.samples) {
        if (s.t <= e.t || s.t >= next->t) continue;
        const double now = s.theta_o - p.theta_R;
        if ((now > 0) != (previous > 0)) ++crossings;
        previous = now;
      }
      cycle.contact_arc_crossings_of_theta_R = crossings;
    }
    break;
  }
  return cycle;
}

}  // namespace backlash::numeric
