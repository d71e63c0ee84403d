// The closed-form simulator with effects (effects_simulation.hpp) against the
// independent one on Boost.Odeint (odeint_effects_simulation.hpp): the same events
// (kinds, bodies, bounce and accumulation flags, faces, contact, sticking, status)
// at times within 1e-9 s, states within 1e-8 — every effect alone and in pairs on
// the thesis's cases (their step and its negative), with θR ≠ 1, and on random
// parameter sets with random effects.  Each comparison prints its max |Δt|.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using numeric::Effects;
using numeric::Parameters;
using numeric::SimulationOptions;
using numeric::SimulationResult;

constexpr double time_tolerance = 1e-9;
constexpr double state_tolerance = 1e-8;

const numeric::ValidatedEvaluator& evaluator_of(const Parameters& p) {
  static std::vector<std::unique_ptr<numeric::ValidationResult>> keep;
  keep.push_back(std::make_unique<numeric::ValidationResult>(numeric::validate(numeric::parametric_evaluator(p))));
  return keep.back()->evaluator();
}

const numeric::ValidatedEffectModel& model_of(const Parameters& p, const Effects& e) {
  static std::vector<std::unique_ptr<numeric::EffectValidationResult>> keep;
  keep.push_back(std::make_unique<numeric::EffectValidationResult>(numeric::validate_effects(evaluator_of(p), e)));
  EXPECT_TRUE(keep.back()->passed()) << keep.back()->report().summary();
  return keep.back()->model();
}

std::string describe(const SimulationResult& r) {
  std::ostringstream out;
  out << numeric::to_string(r.status) << ", " << r.events.size() << " events:";
  for (std::size_t i = 0; i < r.events.size() && i < 30; ++i) {
    const auto& e = r.events[i];
    out << " " << numeric::to_string(e.kind);
    if (e.body != numeric::Body::None) out << "(" << numeric::to_string(e.body) << ")";
    out << (e.bounce ? "!" : "") << (e.accumulation ? "*" : "") << "@" << e.t;
  }
  return out.str();
}

double worst_state(const numeric::HybridState& a, const numeric::HybridState& b) {
  return std::max({std::fabs(a.theta_m - b.theta_m), std::fabs(a.dtheta_m - b.dtheta_m), std::fabs(a.theta_L - b.theta_L),
                   std::fabs(a.dtheta_L - b.dtheta_L)});
}

// A stick–bounce cascade (a body sticks between ever slower bounces, accumulating at a point,
// until an impact is slower than the slowest bounce) is compared up to its first impact slower
// than 1e-5: beyond it an event's time is the gap's rounding divided by that velocity, which no
// simulator resolves, and the number of events differs; the outcome — status and final
// state — is still compared.
std::size_t resolvable_events(const SimulationResult& closed, const SimulationResult& odeint) {
  for (std::size_t i = 1; i < closed.events.size(); ++i) {
    const auto& e = closed.events[i];
    const bool impact = e.kind == numeric::EventKind::Recombination || e.kind == numeric::EventKind::Recontact;
    if (impact && closed.events[i - 1].kind == numeric::EventKind::Stick &&
        std::fabs(e.before.dtheta_L - e.before.dtheta_m) < 1e-5)
      return i;
  }
  return std::max(closed.events.size(), odeint.events.size());
}

// Event by event; gtest failures name the first disagreement.  Returns max |Δt|.
double compare(const SimulationResult& closed, const SimulationResult& odeint, const std::string& label) {
  EXPECT_EQ(numeric::to_string(closed.status), std::string(numeric::to_string(odeint.status))) << label;
  const std::size_t resolvable = resolvable_events(closed, odeint);
  if (resolvable >= std::max(closed.events.size(), odeint.events.size()))
    EXPECT_EQ(closed.events.size(), odeint.events.size())
        << label << "\n  closed form: " << describe(closed) << "\n  odeint:      " << describe(odeint);
  else
    std::printf("%s: a stick-bounce cascade; the %zu events before its unresolvable tail are compared\n", label.c_str(),
                resolvable);
  double worst_t = 0;
  const std::size_t n = std::min({closed.events.size(), odeint.events.size(), resolvable});
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = closed.events[i];
    const auto& o = odeint.events[i];
    const bool same = c.kind == o.kind && c.body == o.body && c.bounce == o.bounce && c.accumulation == o.accumulation &&
                      c.after.in_contact == o.after.in_contact && c.after.face == o.after.face &&
                      c.after.motor_stuck == o.after.motor_stuck && c.after.load_stuck == o.after.load_stuck &&
                      c.after.drive_regime == o.after.drive_regime;
    if (!same) {
      ADD_FAILURE() << label << ": event " << i << " differs: closed form " << describe(closed) << "\n  odeint " << describe(odeint);
      return worst_t;
    }
    if (c.kind == numeric::EventKind::Rest) continue;  // the rest time is where the velocities fall below a threshold
    const double dt = std::fabs(c.t - o.t);
    worst_t = std::max(worst_t, dt);
    EXPECT_LE(dt, time_tolerance) << label << ": event " << i << " (" << numeric::to_string(c.kind) << ") at t = " << c.t
                                  << " vs " << o.t;
    EXPECT_LE(worst_state(c.after, o.after), state_tolerance) << label << ": event " << i << " at t = " << c.t;
  }
  EXPECT_LE(worst_state(closed.final_state, odeint.final_state),
            resolvable >= std::max(closed.events.size(), odeint.events.size()) ? state_tolerance : 1e-6)
      << label << ": final state";
  return worst_t;
}

double run_both(const Parameters& p, const Effects& e, double step, double t_end, const std::string& label) {
  SimulationOptions o;
  o.t_end = t_end;
  const SimulationResult closed = numeric::simulate_effects_step(model_of(p, e), step, o, {.general_engine = true});
  numeric::OdeintSimulationOptions reference;
  reference.tolerance = 1e-13;  // the reference must be well inside the 1e-9 s compared: at 1e-12 a
                                // long coast (8 s of free flight) drifts 1.7e-9 s, at 1e-14 8e-12 s
  const SimulationResult odeint = numeric::simulate_effects_step_with_odeint(p, e, step, o, reference);
  const double worst = compare(closed, odeint, label + " [" + e.describe() + "]");
  std::printf("%-40s %-52s %4zu events, max |dt| %.2e\n", label.c_str(), e.describe().c_str(), closed.events.size(), worst);
  return worst;
}

std::vector<Effects> each_effect() {
  std::vector<Effects> out(9);
  out[0].coulomb_motor = 0.03;
  out[1].coulomb_load = 0.02;
  out[2].restitution = 0.4;
  out[3].saturation = 0.25;
  out[4].mesh_stiffness = 400;
  out[4].mesh_damping = 4;
  out[5].delay = 0.05;
  out[6].torque_offset = 0.02;
  out[7].coulomb_motor = 0.01;
  out[7].coulomb_load = 0.01;
  out[7].saturation = 0.2;
  out[8].delay = 0.1;
  out[8].coulomb_load = 0.01;
  return out;
}

TEST(EffectsSimulatorsAgree, EveryEffectOnEveryThesisCase) {
  for (const std::string& id : model::thesis_case_ids()) {
    const model::CaseSpec spec = model::load_case(id);
    const Parameters p = numeric::parameters_of(spec);
    const double step = model::to_double(spec.experiment->step);
    for (const Effects& e : each_effect())
      for (double s : {step, -step}) run_both(p, e, s, 30, "case " + id + " step " + std::to_string(s));
  }
}

TEST(EffectsSimulatorsAgree, EveryPairOfEffectsOnCaseV) {
  const Parameters p = numeric::parameters_of(model::load_case("V"));
  const std::vector<Effects> single = each_effect();
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = i + 1; j < 7; ++j) {
      Effects e = single[i];
      const Effects& f = single[j];
      if ((e.restitution > 0 && f.compliant()) || (f.restitution > 0 && e.compliant())) continue;
      e.coulomb_motor = std::max(e.coulomb_motor, f.coulomb_motor);
      e.coulomb_load = std::max(e.coulomb_load, f.coulomb_load);
      e.restitution = std::max(e.restitution, f.restitution);
      e.saturation = std::min(e.saturation, f.saturation);
      e.mesh_stiffness = std::min(e.mesh_stiffness, f.mesh_stiffness);
      e.mesh_damping = std::max(e.mesh_damping, f.mesh_damping);
      e.delay = std::max(e.delay, f.delay);
      e.torque_offset += f.torque_offset;
      run_both(p, e, 0.62, 40, "case V pair");
    }
}

TEST(EffectsSimulatorsAgree, AReferenceFarFromOne) {
  Parameters p = numeric::parameters_of(model::load_case("VI"));
  for (double reference : {-3.5, 40.0}) {
    p.theta_R = reference;
    for (const Effects& e : each_effect()) run_both(p, e, 0.55, 30, "case VI thetaR " + std::to_string(reference));
  }
}

TEST(EffectsSimulatorsAgree, RandomParametersAndEffects) {
  std::mt19937_64 random(20261123);
  std::uniform_real_distribution<double> unit(0, 1);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(random)); };
  for (int trial = 0; trial < 40; ++trial) {
    Parameters p;
    p.measured_at = unit(random) < 0.7 ? model::MeasuredAt::Load : model::MeasuredAt::Motor;
    p.Jm = log_uniform(0.1, 2);
    p.JL = log_uniform(0.1, 2);
    p.Fm = unit(random) < 0.2 ? 0 : log_uniform(0.02, 0.5);
    p.FL = unit(random) < 0.2 ? 0 : log_uniform(0.02, 0.5);
    p.K = log_uniform(0.3, 3);
    p.theta_R = unit(random) < 0.5 ? 1 : 4 * unit(random) - 2;
    p.backlash = log_uniform(0.05, 0.5);
    Effects e;
    const double torque = p.K * 0.6;
    if (unit(random) < 0.4) e.coulomb_motor = log_uniform(0.005, 0.1) * torque;
    if (unit(random) < 0.4) e.coulomb_load = log_uniform(0.005, 0.1) * torque;
    if (unit(random) < 0.3) e.saturation = log_uniform(0.2, 1.5) * torque;
    if (unit(random) < 0.3) e.torque_offset = (unit(random) - 0.5) * 0.1 * torque;
    if (unit(random) < 0.25) {
      e.mesh_stiffness = log_uniform(50, 2000) * p.K;
      e.mesh_damping = 2 * log_uniform(0.05, 1) * std::sqrt(e.mesh_stiffness * p.Jm * p.JL / (p.Jm + p.JL));
    } else if (unit(random) < 0.3) {
      e.restitution = log_uniform(0.1, 0.8);
    }
    if (unit(random) < 0.2) e.delay = log_uniform(0.01, 0.1) * std::sqrt((p.Jm + p.JL) / p.K);
    const double step = (unit(random) < 0.5 ? 1 : -1) * log_uniform(0.2, 1.5);
    run_both(p, e, step, 25, "random #" + std::to_string(trial));
  }
}

}  // namespace
