// Issue 21 item 5: Stribeck friction (docs/effects.md, "Stribeck friction") on either body — its
// known answers in the effects engine (numeric/effects/effects_stribeck.cpp), the engine against
// the independent odeint simulator (odeint_effects_simulation.cpp) on random cases, and the case
// file's keys (reader, refusals, writer round trip).
//   break-away    a body at rest leaves only when the torque on it exceeds the STATIC level
//   vs → ∞        the curve is flat at the static level: Coulomb friction at Ts (closed forms)
//   vs → 0        the curve drops to the kinetic level at once: Coulomb at Tk while moving
//   energy        measured at the motor, ½Jm·θ̇m² + ½JL·θ̇L² + ½K(θm − θR)² never grows
#include "backlash/model/case_spec.hpp"
#include "backlash/model/case_writer.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"
#include "backlash/numeric/scales.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace backlash;
using numeric::Body;
using numeric::Effects;
using numeric::EventKind;
using numeric::Parameters;
using numeric::SimulationOptions;
using numeric::SimulationResult;

const numeric::ValidatedEffectModel& model_of(const Parameters& p, const Effects& e) {
  static std::vector<std::unique_ptr<numeric::ValidationResult>> nominal;
  static std::vector<std::unique_ptr<numeric::EffectValidationResult>> keep;
  EXPECT_FALSE(numeric::effect_scale_problem(p, e)) << *numeric::effect_scale_problem(p, e);
  nominal.push_back(std::make_unique<numeric::ValidationResult>(numeric::validate(numeric::parametric_evaluator(p))));
  keep.push_back(std::make_unique<numeric::EffectValidationResult>(numeric::validate_effects(nominal.back()->evaluator(), e)));
  EXPECT_TRUE(keep.back()->passed()) << keep.back()->report().summary();
  return keep.back()->model();
}

SimulationResult run(const Parameters& p, const Effects& e, double step, double t_end, double dt = 0) {
  SimulationOptions o;
  o.t_end = t_end;
  o.sample_interval = dt;
  return numeric::simulate_effects_step(model_of(p, e), step, o, {.general_engine = true});
}

Parameters case_parameters(const std::string& id) { return numeric::parameters_of(model::load_case(id)); }

Effects stribeck(bool motor, double Ts, double Tk, double vs) {
  Effects e;
  (motor ? e.stribeck_motor_static : e.stribeck_load_static) = Ts;
  (motor ? e.stribeck_motor_kinetic : e.stribeck_load_kinetic) = Tk;
  (motor ? e.stribeck_motor_velocity : e.stribeck_load_velocity) = vs;
  return e;
}

std::string describe(const SimulationResult& r) {
  std::string out = std::string(numeric::to_string(r.status)) + ":";
  for (std::size_t i = 0; i < r.events.size() && i < 25; ++i) {
    const auto& e = r.events[i];
    out += " " + std::string(numeric::to_string(e.kind));
    if (e.body != Body::None) out += "(" + std::string(numeric::to_string(e.body)) + ")";
    out += "@" + std::to_string(e.t);
  }
  return out;
}

double state_difference(const numeric::HybridState& a, const numeric::HybridState& b) {
  return std::max({std::fabs(a.theta_m - b.theta_m), std::fabs(a.dtheta_m - b.dtheta_m),
                   std::fabs(a.theta_L - b.theta_L), std::fabs(a.dtheta_L - b.dtheta_L)});
}

// The same events (kind, body, bounce, contact, sticking) at times within `dt`, states within
// `dx`, the same status and final state.  Returns the largest time difference.
double expect_same_events(const SimulationResult& a, const SimulationResult& b, double dt, double dx,
                          const std::string& label) {
  EXPECT_EQ(std::string(numeric::to_string(a.status)), numeric::to_string(b.status)) << label;
  EXPECT_EQ(a.events.size(), b.events.size()) << label << "\n  " << describe(a) << "\n  " << describe(b);
  double worst = 0;
  for (std::size_t i = 0; i < std::min(a.events.size(), b.events.size()); ++i) {
    const auto &x = a.events[i], &y = b.events[i];
    const bool same = x.kind == y.kind && x.body == y.body && x.bounce == y.bounce &&
                      x.after.in_contact == y.after.in_contact && x.after.motor_stuck == y.after.motor_stuck &&
                      x.after.load_stuck == y.after.load_stuck;
    if (!same) {
      ADD_FAILURE() << label << ": event " << i << " differs\n  " << describe(a) << "\n  " << describe(b);
      return worst;
    }
    if (x.kind == EventKind::Rest) continue;  // a threshold time (free flight) or the last stick's
    worst = std::max(worst, std::fabs(x.t - y.t));
    EXPECT_LE(std::fabs(x.t - y.t), dt) << label << ": event " << i << " " << numeric::to_string(x.kind);
    EXPECT_LE(state_difference(x.after, y.after), dx) << label << ": event " << i << " at t = " << x.t;
  }
  EXPECT_LE(state_difference(a.final_state, b.final_state), dx) << label << ": final state";
  return worst;
}

// ------------------------------------------------------------------ break-away at the static level

// Case V's step starts the pair at rest in contact with the drive K·step pushing it: the pair stays
// stuck while K·step is inside the band (its static level, Stribeck Ts on the motor), and moves
// otherwise — at a drive between the kinetic and the static level it does not move, though
// Coulomb friction at the kinetic level would.
TEST(StribeckFriction, item5_breaks_away_at_the_static_level_not_the_kinetic) {
  const Parameters p = case_parameters("V");
  const double Ts = 0.2, Tk = 0.08;
  for (const double factor : {0.999, 1.001}) {
    const double step = factor * Ts / p.K;
    const SimulationResult r = run(p, stribeck(true, Ts, Tk, 0.05), step, 30);
    Effects kinetic;
    kinetic.coulomb_motor = Tk;
    const SimulationResult coulomb = run(p, kinetic, step, 30);
    ASSERT_FALSE(coulomb.events.empty());
    EXPECT_NE(coulomb.events.front().kind, EventKind::Stick) << "Coulomb at the kinetic level moves: " << describe(coulomb);
    if (factor < 1) {
      EXPECT_EQ(r.status, numeric::SimulationStatus::Rest) << describe(r);
      ASSERT_FALSE(r.events.empty());
      EXPECT_EQ(r.events.front().kind, EventKind::Stick);
      EXPECT_EQ(r.events.front().t, 0);
      EXPECT_EQ(r.theta_o_final, p.theta_R - step) << "stuck where it started";
    } else {
      EXPECT_NE(r.theta_o_final, p.theta_R - step) << "it moves: " << describe(r);
      ASSERT_FALSE(r.events.empty());
      EXPECT_NE(r.events.front().kind, EventKind::Stick) << describe(r);
    }
  }
}

// Every stick and slip of a body the engine reports obeys the static rule at its static level
// (case V with Stribeck friction on the motor, Tk = 0.4·Ts: after a separation the motor sticks,
// and breaks away when the load's motion has moved the drive K(θR − θL) out of the band):
// at a stick the torque on the body is within ±Ts, at a break-away of a stuck motor (free
// flight, output at the load, the drive following the moving load) |D| has just reached Ts.
TEST(StribeckFriction, item5_every_stick_and_slip_at_the_static_level) {
  Parameters p = case_parameters("V");
  int slips = 0, sticks = 0;
  for (const auto& [step, Ts] : {std::pair{0.62, 0.1}, {0.3, 0.15}, {-1.2, 0.25}}) {
    const SimulationResult r = run(p, stribeck(true, Ts, 0.4 * Ts, 0.02), step, 60);
    for (const auto& e : r.events) {
      if (e.body != Body::Motor || e.after.in_contact) continue;
      const double D = p.K * (p.theta_R - e.after.theta_L);  // the drive, output at the load
      if (e.kind == EventKind::Stick) {
        ++sticks;
        EXPECT_LE(std::fabs(D), Ts) << "t = " << e.t;
        EXPECT_EQ(e.after.dtheta_m, 0);
      }
      if (e.kind == EventKind::Slip) {
        ++slips;
        // The event time carries the integrator's error (≤ 1e-9 s, the cross-check below): |D|
        // moves by K·|θ̇L|·1e-9 in that time.
        EXPECT_NEAR(std::fabs(D), Ts, 1e-9 * p.K * std::max(1.0, std::fabs(e.after.dtheta_L))) << "t = " << e.t;
      }
    }
  }
  std::printf("motor sticks %d, break-aways %d in free flight\n", sticks, slips);
  EXPECT_GT(sticks, 0);
  EXPECT_GT(slips, 0);
}

// ------------------------------------------------------------------ the limits of the Stribeck velocity

// vs → ∞: the curve Tk + (Ts − Tk)·exp(−(v/vs)²) is Ts − (Ts − Tk)·(v/vs)² + …; with vs = 1e7 and
// |v| < 2 rad/s it is Ts within 0.1·4e-14 = 4e-15 torque — below the integration's own error.  So
// the run must match Coulomb friction at Ts (the closed forms) to the engine's accuracy: 1e-9 s in
// the event times, 1e-8 in the states (the cross-check's tolerances, check_effects_simulators_agree).
TEST(StribeckFriction, item5_velocity_to_infinity_is_coulomb_at_the_static_level) {
  for (const std::string id : {"V", "I"}) {
    const Parameters p = case_parameters(id);
    const double step = id == "V" ? 0.62 : 1.0;
    for (const bool motor : {true, false}) {
      const double Ts = 0.05, Tk = 0.01;
      Effects coulomb;
      (motor ? coulomb.coulomb_motor : coulomb.coulomb_load) = Ts;
      const SimulationResult exact = run(p, coulomb, step, 40);
      const SimulationResult flat = run(p, stribeck(motor, Ts, Tk, 1e7), step, 40);
      const double worst = expect_same_events(flat, exact, 1e-9, 1e-8, "case " + id + (motor ? " motor" : " load"));
      std::printf("case %s, Stribeck on the %s, vs = 1e7 against Coulomb at Ts: %zu events, max |dt| %.2e\n",
                  id.c_str(), motor ? "motor" : "load", exact.events.size(), worst);
    }
  }
}

// vs → 0: the friction of a moving body is Tk except while |v| < a few vs.  Each passage through
// that window (at a start from rest or a velocity zero, acceleration a) lasts about 2·3vs/|a| and
// changes the body's momentum by less than (Ts − Tk)·√π·vs/|a| (∫exp(−(v/vs)²)dt).  With vs = 1e-9,
// Ts − Tk = 0.02 and |a| ≳ 0.05 that is 7e-10 per passage: the run matches Coulomb friction at Tk up
// to the first velocity zero of a body (where the static levels differ: Ts against Tk) within
// 1e-7 — a few passages' error, amplified by at most e^{t/τ} ≤ 20 over the servo's decay.
TEST(StribeckFriction, item5_velocity_to_zero_is_coulomb_at_the_kinetic_level) {
  const Parameters p = case_parameters("V");
  const double Ts = 0.03, Tk = 0.01, step = 0.62;
  for (const bool motor : {true, false}) {
    Effects coulomb;
    (motor ? coulomb.coulomb_motor : coulomb.coulomb_load) = Tk;
    // The first velocity zero of the body with friction, from the Coulomb run's samples.
    const SimulationResult sampled = run(p, coulomb, step, 40, 1e-3);
    double first_zero = 40;
    for (std::size_t i = 1; i < sampled.samples.size(); ++i) {
      const double a = motor ? sampled.samples[i - 1].dtheta_m : sampled.samples[i - 1].dtheta_L;
      const double b = motor ? sampled.samples[i].dtheta_m : sampled.samples[i].dtheta_L;
      if (sampled.samples[i].t > 0.01 && ((a > 0 && b <= 0) || (a < 0 && b >= 0))) {
        first_zero = sampled.samples[i - 1].t;
        break;
      }
    }
    const double t_end = first_zero - 0.01;
    ASSERT_GT(t_end, 1.0);
    const SimulationResult exact = run(p, coulomb, step, t_end);
    const SimulationResult steep = run(p, stribeck(motor, Ts, Tk, 1e-9), step, t_end);
    const double worst = expect_same_events(steep, exact, 1e-7, 1e-7, motor ? "motor" : "load");
    std::printf("Stribeck on the %s, vs = 1e-9 against Coulomb at Tk to t = %.3f: %zu events, max |dt| %.2e, final "
                "state %.2e\n",
                motor ? "motor" : "load", t_end, exact.events.size(), worst,
                state_difference(steep.final_state, exact.final_state));
  }
}

// ------------------------------------------------------------------ energy

// Output at the motor, no offset, no saturation: the drive K(θR − θm) is a spring on the motor, so
// E = ½Jm·θ̇m² + ½JL·θ̇L² + ½K(θm − θR)² changes only by the viscous and friction torques (each
// opposing its body's motion: a Stribeck level ≥ Tk ≥ 0) and the impacts (momentum kept, relative
// velocity scaled by −e): it never grows.  Checked on the samples, within the integration's error
// (1e-9 of E(0)).
TEST(StribeckFriction, item5_energy_never_grows) {
  const Parameters p = case_parameters("I");
  auto energy = [&](double vm, double vL, double theta_m) {
    return 0.5 * p.Jm * vm * vm + 0.5 * p.JL * vL * vL + 0.5 * p.K * (theta_m - p.theta_R) * (theta_m - p.theta_R);
  };
  for (const double restitution : {0.0, 0.6}) {
    Effects e = stribeck(true, 0.04, 0.01, 0.05);
    e.stribeck_load_static = 0.03;
    e.stribeck_load_kinetic = 0.02;
    e.stribeck_load_velocity = 0.2;
    e.restitution = restitution;
    const SimulationResult r = run(p, e, 1.0, 40, 0.005);
    ASSERT_GT(r.samples.size(), 100U);
    const double e0 = energy(0, 0, p.theta_R - 1.0);
    double previous = e0, worst_rise = 0;
    for (const auto& s : r.samples) {
      const double now = energy(s.dtheta_m, s.dtheta_L, s.theta_m);
      worst_rise = std::max(worst_rise, now - previous);
      previous = now;
    }
    EXPECT_LE(worst_rise, 1e-9 * e0) << "restitution " << restitution << ": " << describe(r);
    std::printf("restitution %.1f: %zu samples, largest rise of E %.2e (E(0) = %.3f)\n", restitution, r.samples.size(),
                worst_rise, e0);
  }
}

// ------------------------------------------------------------------ the engine against the reference

// Random structures and effects (Stribeck on either body or both, with Coulomb friction, restitution
// or a compliant mesh, saturation, an offset): the engine and the independent odeint simulator give
// the same events at times within 1e-9 s and states within 1e-8 (check_effects_simulators_agree's
// tolerances: both integrate at 1e-13 per step).
TEST(StribeckFriction, item5_engine_agrees_with_the_reference_simulator) {
  std::mt19937_64 random(20270521);
  std::uniform_real_distribution<double> unit(0, 1);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(random)); };
  double worst = 0;
  for (int trial = 0; trial < 16; ++trial) {
    Parameters p;
    p.measured_at = unit(random) < 0.6 ? model::MeasuredAt::Load : model::MeasuredAt::Motor;
    p.Jm = log_uniform(0.2, 2);
    p.JL = log_uniform(0.2, 2);
    p.Fm = log_uniform(0.02, 0.5);
    p.FL = log_uniform(0.02, 0.5);
    p.K = log_uniform(0.3, 3);
    p.theta_R = 1;
    p.backlash = log_uniform(0.05, 0.5);
    const double torque = 0.6 * p.K, speed = 0.6 * std::sqrt(p.K / (p.Jm + p.JL));
    Effects e;
    for (const bool motor : {true, false}) {
      if (trial % 3 == (motor ? 1 : 2)) continue;  // on the motor, the load or both
      const double Ts = log_uniform(0.01, 0.1) * torque;
      e = [&] {
        Effects f = e;
        (motor ? f.stribeck_motor_static : f.stribeck_load_static) = Ts;
        (motor ? f.stribeck_motor_kinetic : f.stribeck_load_kinetic) = unit(random) * Ts;
        (motor ? f.stribeck_motor_velocity : f.stribeck_load_velocity) = log_uniform(0.01, 1) * speed;
        return f;
      }();
    }
    if (unit(random) < 0.3) e.coulomb_load = log_uniform(0.005, 0.05) * torque;
    if (unit(random) < 0.3) e.saturation = log_uniform(0.3, 1.5) * torque;
    if (unit(random) < 0.3) e.torque_offset = (unit(random) - 0.5) * 0.1 * torque;
    if (unit(random) < 0.25) {
      e.mesh_stiffness = log_uniform(50, 1000) * p.K;
      e.mesh_damping = 2 * log_uniform(0.1, 1) * std::sqrt(e.mesh_stiffness * p.Jm * p.JL / (p.Jm + p.JL));
    } else if (unit(random) < 0.3) {
      e.restitution = log_uniform(0.1, 0.7);
    }
    const double step = (unit(random) < 0.5 ? 1 : -1) * log_uniform(0.3, 1.5);
    SimulationOptions o;
    o.t_end = 25;
    const SimulationResult engine = numeric::simulate_effects_step(model_of(p, e), step, o, {.general_engine = true});
    numeric::OdeintSimulationOptions reference;
    reference.tolerance = 1e-13;
    const SimulationResult odeint = numeric::simulate_effects_step_with_odeint(p, e, step, o, reference);
    const std::string label = "random #" + std::to_string(trial) + " [" + e.describe() + "]";
    const double dt = expect_same_events(engine, odeint, 1e-9, 1e-8, label);
    std::printf("%-12s %3zu events, max |dt| %.2e  %s\n", ("random #" + std::to_string(trial)).c_str(),
                engine.events.size(), dt, e.describe().c_str());
    worst = std::max(worst, dt);
  }
  std::printf("largest event-time difference, engine against the reference: %.2e s\n", worst);
}

// A stiff undamped mesh (check_effects_boundaries' pair: stiffness 1e5, Stribeck on the motor):
// the mesh rings at √(kc·(1/Jm + 1/JL)) ≈ 630 rad/s through some 30 separations and recontacts while the
// motor slips far above its Stribeck velocity, where the drop has saturated in double precision and
// the engine's segments are the closed forms at the kinetic level (effects_stribeck.cpp).  Those
// agree with the reference to its own accuracy, 1e-9 s as above; integrating the ringing
// mesh with dopri5 (the segments before) already missed the first separation by 1.8e-9 s.
TEST(StribeckFriction, item5_saturated_drop_is_the_closed_form_on_a_stiff_mesh) {
  const Parameters p = case_parameters("V");
  Effects e = stribeck(true, 0.186, 0.0034, 0.0031);
  e.mesh_stiffness = 1e5;
  SimulationOptions o;
  o.t_end = 1.33;  // the chattering amplifies any difference: later events differ by more than 1e-9 s
  const SimulationResult engine = numeric::simulate_effects_step(model_of(p, e), 0.62, o, {.general_engine = true});
  numeric::OdeintSimulationOptions reference;
  reference.tolerance = 1e-13;
  const SimulationResult odeint = numeric::simulate_effects_step_with_odeint(p, e, 0.62, o, reference);
  ASSERT_GE(engine.events.size(), 30U) << describe(engine);
  const double dt = expect_same_events(engine, odeint, 1e-9, 1e-8, "stiff mesh");
  std::printf("stiff mesh, Stribeck on the motor: %zu events, max |dt| %.2e against the reference\n",
              engine.events.size(), dt);
}

// ------------------------------------------------------------------ the case file

const std::string case_v = R"(name = "V with Stribeck friction"
measured_at = "load"
K = 1
backlash = 0.3
reference = 1
[motor]
J = 0.5
F = 0.1
[load]
J = 0.5
F = 0.3
[experiment]
step = 0.62
[effects]
)";

TEST(StribeckFriction, item5_case_file_keys_read_written_and_refused) {
  const model::CaseSpec spec = model::parse_case(
      case_v + "stribeck_motor = { static = 0.05, kinetic = 0.02, velocity = 0.1 }\n"
               "stribeck_load = { static = 0.03, kinetic = 0.03, velocity = 1e-2 }\n",
      "stribeck.toml");
  const Effects e = numeric::effects_of(spec);
  EXPECT_EQ(e.stribeck_motor_static, 0.05);
  EXPECT_EQ(e.stribeck_motor_kinetic, 0.02);
  EXPECT_EQ(e.stribeck_motor_velocity, 0.1);
  EXPECT_EQ(e.stribeck_load_velocity, 0.01);
  EXPECT_TRUE(e.stribeck());
  const std::string text = model::write_case_file(spec);
  EXPECT_NE(text.find(R"(stribeck_motor = { static = "1/20", kinetic = "1/50", velocity = "1/10" })"), std::string::npos) << text;
  const model::CaseSpec again = model::parse_case(text, "again.toml");
  EXPECT_EQ(model::write_case_file(again), text) << "written, read and written again: the same bytes";
  for (const model::EffectParameterInfo& parameter : model::effect_parameters)
    EXPECT_EQ(model::field(spec.effects, parameter.id), model::field(again.effects, parameter.id)) << parameter.name;

  auto refusal = [](const std::string& effects) {
    try {
      model::parse_case(case_v + effects, "bad.toml");
    } catch (const model::CaseFileError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("stribeck_load = { static = 0.02, kinetic = 0.03, velocity = 0.1 }\n").find("stribeck_load.kinetic"),
            std::string::npos);
  EXPECT_NE(refusal("stribeck_motor = { static = 0.02, kinetic = 0.01, velocity = 0 }\n").find("stribeck_motor.velocity"),
            std::string::npos);
  EXPECT_NE(refusal("stribeck_motor = { static = 0.02, kinetic = 0.01 }\n").find("velocity"), std::string::npos);
  // What the reader cannot see (models built in code, sweeps, maps): the scale checks.
  const Parameters p = case_parameters("V");
  Effects bad = stribeck(false, 0.02, 0.03, 0.1);
  ASSERT_TRUE(numeric::effect_scale_problem(p, bad));
  EXPECT_NE(numeric::effect_scale_problem(p, bad)->find("stribeck_load.kinetic"), std::string::npos);
  bad = stribeck(true, 0.05, 0.01, 1e-14);  // a curve steeper than any integration spans
  ASSERT_TRUE(numeric::effect_scale_problem(p, bad));
  EXPECT_NE(numeric::effect_scale_problem(p, bad)->find("stribeck_motor.velocity"), std::string::npos);
  bad = stribeck(true, 0.05, 0.01, 0.1);
  bad.delay = 0.05;  // the delayed model has no Stribeck friction: refused by name
  ASSERT_TRUE(numeric::effect_scale_problem(p, bad));
  EXPECT_NE(numeric::effect_scale_problem(p, bad)->find("delay"), std::string::npos);
}

}  // namespace
