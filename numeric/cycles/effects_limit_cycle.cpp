// Limit cycles of the model with effects (effects_limit_cycle.hpp).
#include "backlash/numeric/effects_limit_cycle.hpp"

#include "backlash/numeric/segment_dynamics.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

namespace backlash::numeric {

namespace {

using Vector = Eigen::VectorXd;

// The section Σ: states just after the gap reaches face +1 from the other side (a
// recombination: a rigid impact, or the compliant mesh engaging), in the coordinates
// (θm, θ̇m, θL, θ̇L).  A limit cycle crosses it once per period; restarting a simulation
// from a crossing is exact (the flags — contact, face, sticking, drive regime — come along).
class Section {
 public:
  Section(const ValidatedEffectModel& model, double horizon) : model_(model), horizon_(horizon) {}

  Vector coordinates(const HybridState& s) const {
    Vector x(4);
    x << s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L;
    return x;
  }

  HybridState state(const Vector& x, const HybridState& like) const {
    HybridState s = like;
    s.theta_m = x(0);
    s.dtheta_m = x(1);
    s.theta_L = x(2);
    s.dtheta_L = x(3);
    return s;
  }

  struct Return {
    bool valid = false;
    HybridState state;   ///< on Σ again
    double duration = 0;
    std::string outcome;  ///< why not valid
    double rest_error = 0;
    bool bounced = false;
    Extremes extremes;
    double separation_velocity = NAN, theta_o_separation = NAN;  ///< at the period's separation from face −1
  };

  // P(s): the next crossing of Σ.
  Return next(const HybridState& s, bool track_extremes = false) const {
    SimulationOptions o;
    o.t_end = horizon_;
    o.max_events = 20000;
    o.track_extremes = track_extremes;
    EffectsEngineOptions engine;
    engine.general_engine = true;
    engine.stop_at_face = +1;
    engine.stop_at_kind = EventKind::Recombination;
    const SimulationResult r = simulate_effects(model_, s, o, engine);
    Return out;
    for (const SimulationEvent& e : r.events) out.bounced = out.bounced || e.bounce;
    out.extremes = r.extremes;
    if (r.status == SimulationStatus::Rest) {
      out.outcome = "rest";
      out.rest_error = r.theta_o_final - model_.parameters().theta_R;
      return out;
    }
    const SimulationEvent* crossing = nullptr;
    for (const SimulationEvent& e : r.events)
      if (e.kind == EventKind::Recombination && e.after.face == +1 && e.t > 0) crossing = &e;
    if (r.status != SimulationStatus::Completed || crossing == nullptr || r.t_final >= horizon_) {
      out.outcome = r.status == SimulationStatus::Completed ? "no recombination within the horizon"
                                                            : std::string(to_string(r.status));
      return out;
    }
    out.valid = true;
    out.state = crossing->after;
    out.duration = crossing->t;
    // The period's separation from face −1 (else its first separation): the separation velocity.
    bool any = false, from_minus = false;
    for (const SimulationEvent& e : r.events) {
      if (e.kind != EventKind::Separation || from_minus || (any && e.after.face != -1)) continue;
      out.separation_velocity = std::fabs(e.dtheta_o);
      out.theta_o_separation = e.theta_o;
      any = true;
      from_minus = e.after.face == -1;
    }
    return out;
  }

 private:
  const ValidatedEffectModel& model_;
  double horizon_;
};

double scale_of(const Vector& x) { return std::max(1.0, x.cwiseAbs().maxCoeff()); }

void fill_figures(const Parameters& p, double separation_velocity, double theta_o_separation, const Extremes& x,
                  double period, bool bounced, LimitCycle& cycle) {
  cycle.period = period;
  cycle.bounced = bounced;
  cycle.theta_o_max = x.theta_o_max;
  cycle.theta_o_min = x.theta_o_min;
  cycle.amplitude = std::max(x.theta_o_max - p.theta_R, p.theta_R - x.theta_o_min);
  cycle.peak_to_peak = x.theta_o_max - x.theta_o_min;
  cycle.peak_to_peak_motor = x.theta_m_max - x.theta_m_min;
  cycle.peak_to_peak_load = x.theta_L_max - x.theta_L_min;
  cycle.separation_velocity = separation_velocity;
  cycle.theta_o_separation = theta_o_separation;
}

struct Iteration {
  bool converged = false;
  std::string outcome;
  HybridState state;
  int cycles = 0;
  double residual = 0;
  double rest_error = 0;
};

bool diverges(const Vector& x, double velocity_scale) {
  return !x.allFinite() || x.cwiseAbs().maxCoeff() > 1e8 * velocity_scale;
}

// Iterates P from a seed, accelerated by Steffensen's method (Aitken's Δ² on x, P(x), P(P(x))
// along the section's one contracting direction), until |P(x) − x| is at rounding level, the
// motion rests or grows without bound.
Iteration iterate(const Section& section, HybridState s, const EffectLimitCycleOptions& o, double velocity_scale) {
  Iteration it;
  auto fail = [&it](const Section::Return& r) {
    it.outcome = r.outcome;
    it.rest_error = r.rest_error;
    return it;
  };
  Section::Return r = section.next(s);
  if (!r.valid) return fail(r);
  s = r.state;
  bool accelerate = true;
  double previous_residual = INFINITY;
  for (int k = 0; k < o.max_cycles; ++k) {
    const Section::Return r1 = section.next(s);
    if (!r1.valid) return fail(r1);
    const Vector x0 = section.coordinates(s), x1 = section.coordinates(r1.state);
    if (diverges(x1, velocity_scale)) {
      it.outcome = "divergent: the separation velocity grows without bound";
      return it;
    }
    it.cycles = k + 1;
    it.residual = (x1 - x0).cwiseAbs().maxCoeff();
    // Steffensen only while it helps: a motion decaying toward rest has no fixed point to
    // extrapolate to, and from there on the plain iteration decides.
    if (accelerate && it.residual > 0.9 * previous_residual) accelerate = false;
    previous_residual = it.residual;
    if (it.residual <= o.tolerance * scale_of(x1)) {
      it.converged = true;
      it.state = r1.state;
      return it;
    }
    const Section::Return r2 = section.next(r1.state);
    if (!r2.valid) return fail(r2);
    const Vector x2 = section.coordinates(r2.state);
    // Aitken along the step direction: x* ≈ x2 − λ/(1 − λ)·(x2 − x1), λ = ⟨d1, d0⟩/⟨d0, d0⟩.
    const Vector d0 = x1 - x0, d1 = x2 - x1;
    const double lambda = d1.dot(d0) / d0.dot(d0);
    s = r2.state;
    if (accelerate && std::isfinite(lambda) && lambda > -0.95 && lambda < 0.95) {
      const Vector accelerated = x2 - lambda / (1 - lambda) * d1;
      // Only a modest extrapolation: a motion decaying toward rest (a Coulomb dead band) has no
      // fixed point to extrapolate to, and its velocities must not be pushed through zero.
      const bool modest = (accelerated - x2).cwiseAbs().maxCoeff() <= 4 * d1.cwiseAbs().maxCoeff() &&
                          accelerated(1) * x2(1) > 0 && std::fabs(accelerated(1)) >= 0.25 * std::fabs(x2(1));
      if (accelerated.allFinite() && modest) s = section.state(accelerated, r2.state);
    }
  }
  it.outcome = "the return map did not settle within " + std::to_string(o.max_cycles) + " cycles";
  return it;
}

// The multiplier: P's derivative along Σ at the fixed point.  x1 = P(x* + δe) lies on Σ near
// x*; the ratios q_k = ⟨x_{k+1} − x*, u⟩/⟨x_k − x*, u⟩ of two further returns, extrapolated to
// zero distance (Richardson: q(d) = λ + c·d), give λ.
double multiplier_at(const Section& section, const HybridState& fixed) {
  const Vector star = section.coordinates(fixed);
  Vector perturbed = star;
  perturbed(1) += 1e-4 * scale_of(star);  // a velocity: any direction reaches Σ after one return
  Section::Return r = section.next(section.state(perturbed, fixed));
  if (!r.valid) return NAN;
  std::vector<Vector> x{section.coordinates(r.state)};
  for (int k = 0; k < 2; ++k) {
    r = section.next(r.state);
    if (!r.valid) return NAN;
    x.push_back(section.coordinates(r.state));
  }
  const Vector d0 = x[0] - star;
  if (d0.norm() == 0) return 0;
  const Vector u = d0 / d0.norm();
  const double a0 = d0.dot(u), a1 = (x[1] - star).dot(u), a2 = (x[2] - star).dot(u);
  if (a1 == 0) return 0;
  const double q0 = a1 / a0, q1 = a2 / a1;
  return a1 != a0 ? (q1 * a0 - q0 * a1) / (a0 - a1) : q1;
}

// With a delay the state is a whole history: one continuous simulation whose successive
// separations from face −1 converge to the cycle; the multiplier is the ratio of successive
// steps while they are well above rounding.
struct DelayedCycle {
  Iteration iteration;
  double multiplier = NAN;
  double crossing = 0, period = 0;
  HybridState seed;
};

DelayedCycle iterate_delayed(const ValidatedEffectModel& model, const HybridState& seed,
                             const EffectLimitCycleOptions& o, double horizon_per_cycle) {
  DelayedCycle out;
  out.seed = seed;
  const Parameters& p = model.parameters();
  SimulationOptions so;
  so.t_end = horizon_per_cycle * (o.max_cycles + 2);
  so.max_events = 50 * (o.max_cycles + 2);
  const SimulationResult r = simulate_effects(model, seed, so, {.general_engine = true});
  if (r.status == SimulationStatus::Rest) {
    out.iteration.outcome = "rest";
    out.iteration.rest_error = r.theta_o_final - p.theta_R;
    return out;
  }
  std::vector<const SimulationEvent*> crossings;
  for (const SimulationEvent& e : r.events)
    if (e.kind == EventKind::Recombination && e.after.face == +1) crossings.push_back(&e);
  auto coordinates = [&](const SimulationEvent* e) {
    Vector x(4);
    x << e->after.theta_m, e->after.dtheta_m, e->after.theta_L, e->after.dtheta_L;
    return x;
  };
  std::vector<double> steps, ratios;
  for (std::size_t k = 1; k < crossings.size(); ++k) {
    const double step = (coordinates(crossings[k]) - coordinates(crossings[k - 1])).cwiseAbs().maxCoeff();
    if (!steps.empty() && steps.back() > 1e-7 && step > 1e-7) ratios.push_back(step / steps.back());
    steps.push_back(step);
    if (k >= 2 && step <= o.tolerance * scale_of(coordinates(crossings[k]))) {
      out.iteration.converged = true;
      out.iteration.state = crossings[k]->after;
      out.iteration.cycles = static_cast<int>(k);
      out.iteration.residual = step;
      out.crossing = crossings[k]->t;
      out.period = crossings[k]->t - crossings[k - 1]->t;
      if (!ratios.empty()) {
        std::vector<double> tail(ratios.end() - std::min<std::ptrdiff_t>(ratios.size(), 3), ratios.end());
        std::sort(tail.begin(), tail.end());
        out.multiplier = tail[tail.size() / 2];
      }
      return out;
    }
  }
  out.iteration.outcome = crossings.size() < 3 ? std::string("no sustained oscillation (") + to_string(r.status) + ")"
                                               : "the oscillation did not settle within the simulated cycles";
  return out;
}

// The delayed cycle's figures: the same continuous run, extremes over its last period only.
void describe_delayed_cycle(const ValidatedEffectModel& model, const DelayedCycle& d, LimitCycle& cycle) {
  SimulationOptions so;
  so.t_end = d.crossing + d.period;
  so.max_events = 1000000;
  so.track_extremes = true;
  const SimulationResult r = simulate_effects(model, d.seed, so, {.general_engine = true, .extremes_after = d.crossing});
  bool bounced = false;
  double velocity = NAN, theta = NAN;
  bool from_minus = false;
  for (const SimulationEvent& e : r.events) {
    if (e.t < d.crossing) continue;
    bounced = bounced || e.bounce;
    if (e.kind == EventKind::Separation && !from_minus) {
      velocity = std::fabs(e.dtheta_o);
      theta = e.theta_o;
      from_minus = e.after.face == -1;
    }
  }
  fill_figures(model.parameters(), velocity, theta, r.extremes, d.period, bounced, cycle);
}

// One period from s on Σ with exact extremes: the cycle's figures.
void describe_cycle(const ValidatedEffectModel& model, const Section& section, const HybridState& s, LimitCycle& cycle) {
  const Section::Return r = section.next(s, true);
  fill_figures(model.parameters(), r.separation_velocity, r.theta_o_separation, r.extremes, r.duration, r.bounced, cycle);
}

std::vector<HybridState> seeds(const ValidatedEffectModel& model, const EffectLimitCycleOptions& o) {
  const Parameters& p = model.parameters();
  std::vector<HybridState> out;
  if (o.warm_start) out.push_back(*o.warm_start);
  if (std::isfinite(o.step)) out.push_back(effects_step_start(p, model.effects(), o.step));
  const double scale = std::max(1.0, std::fabs(p.theta_R));
  for (double v : o.seed_velocities) {
    HybridState s = state_on_face(p, -1, p.theta_R + cot_phi(p) * v * scale, v * scale, false);
    s.drive_regime = drive_regime(p, model.effects(), measured(p, s));
    out.push_back(s);
  }
  return out;
}

}  // namespace

LimitCycle find_limit_cycle(const ValidatedEffectModel& model, const EffectLimitCycleOptions& options) {
  const Parameters& p = model.parameters();
  const Effects& e = model.effects();
  if (!e.any() && !options.general) return find_limit_cycle(model.nominal());
  LimitCycle cycle;
  if (p.backlash <= 0) {
    cycle.reason = "no backlash";
    return cycle;
  }
  const double horizon = options.horizon > 0 ? options.horizon : 60 * slowest_time_scale(p);  // as limit_cycle.cpp
  const Section section(model, horizon);
  const double velocity_scale = std::max(1.0, std::fabs(p.theta_R)) * std::sqrt(p.K / (p.Jm + p.JL));
  std::vector<std::string> outcomes;
  double rest_error = 0;
  bool rested = false, found = false;
  for (const HybridState& seed : seeds(model, options)) {
    Iteration it;
    if (e.delayed()) {
      const DelayedCycle d = iterate_delayed(model, seed, options, horizon / 10);
      it = d.iteration;
      if (it.converged) {
        cycle.method = "return map (iteration of one continuous run)";
        cycle.multiplier = d.multiplier;
        describe_delayed_cycle(model, d, cycle);
      }
    } else {
      it = iterate(section, seed, options, velocity_scale);
      if (it.converged) {
        cycle.method = "return map (Steffensen iteration)";
        cycle.multiplier = multiplier_at(section, it.state);
        cycle.section_state = it.state;
        describe_cycle(model, section, it.state, cycle);
      }
    }
    if (it.converged) {
      cycle.iterations = it.cycles;
      cycle.residual = it.residual;
      found = true;
      break;
    }
    if (it.outcome == "rest") {
      rested = true;
      rest_error = it.rest_error;
    }
    if (std::find(outcomes.begin(), outcomes.end(), it.outcome) == outcomes.end()) outcomes.push_back(it.outcome);
  }
  if (!found) {
    std::ostringstream reason;
    if (rested && outcomes.size() == 1) {
      reason << "every seed comes to rest (the Coulomb dead band stops the motion; final error " << rest_error << ")";
      cycle.rest_error = rest_error;
    } else {
      reason << "no stable cycle: ";
      for (std::size_t i = 0; i < outcomes.size(); ++i) reason << (i ? "; " : "") << outcomes[i];
    }
    if (p.measured_at == model::MeasuredAt::Motor)
      reason << "; the backlash is outside the loop, so the system settles with a steady-state error";
    cycle.reason = reason.str();
    return cycle;
  }
  cycle.status = CycleStatus::LimitCycle;
  cycle.stable = cycle.multiplier < 1;
  cycle.half_map_derivative = NAN;
  return cycle;
}

}  // namespace backlash::numeric
