// The closed-form simulator with effects (effects_simulation.hpp, docs/effects.md):
// each effect's own physics, the neutral limits, the delayed loop against its
// characteristic equation, and limit cycles with effects.  The agreement with the
// independent odeint simulator is check_effects_simulators_agree.cpp.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using numeric::Effects;
using numeric::EventKind;
using numeric::HybridState;
using numeric::Parameters;
using numeric::SimulationOptions;
using numeric::SimulationResult;

const numeric::ValidatedEvaluator& nominal(const std::string& id) {
  static std::map<std::string, numeric::ValidationResult> cache;
  auto found = cache.find(id);
  if (found == cache.end()) found = cache.emplace(id, numeric::validate(numeric::case_evaluator(model::load_case(id)))).first;
  return found->second.evaluator();
}

const numeric::ValidatedEvaluator& nominal(const Parameters& p) {
  static std::vector<std::unique_ptr<numeric::ValidationResult>> keep;
  keep.push_back(std::make_unique<numeric::ValidationResult>(numeric::validate(numeric::parametric_evaluator(p))));
  return keep.back()->evaluator();
}

const numeric::ValidatedEffectModel& with_effects(const numeric::ValidatedEvaluator& n, const Effects& e) {
  static std::vector<std::unique_ptr<numeric::EffectValidationResult>> keep;
  keep.push_back(std::make_unique<numeric::EffectValidationResult>(numeric::validate_effects(n, e)));
  EXPECT_TRUE(keep.back()->passed()) << keep.back()->report().summary();
  return keep.back()->model();
}

double step_of(const std::string& id) { return model::to_double(model::load_case(id).experiment->step); }

Effects coulomb(double motor, double load) {
  Effects e;
  e.coulomb_motor = motor;
  e.coulomb_load = load;
  return e;
}

SimulationOptions sampled(double t_end, double dt) {
  SimulationOptions o;
  o.t_end = t_end;
  o.sample_interval = dt;
  return o;
}

// The effects engine even where every effect is neutral (never the nominal shortcut).
const numeric::EffectsEngineOptions general{.general_engine = true};

// ------------------------------------------------------------------ neutral limits

TEST(EffectsNeutral, GeneralEngineReproducesTheNominalSimulatorOnEveryCase) {
  for (const std::string& id : model::thesis_case_ids()) {
    const auto& model = with_effects(nominal(id), Effects{});
    for (double step : {step_of(id), 0.6 * step_of(id), -step_of(id)}) {
      SimulationOptions o;
      o.t_end = 40;
      const SimulationResult n = numeric::simulate_step(nominal(id), step, o);
      const SimulationResult g = numeric::simulate_effects_step(model, step, o, general);
      EXPECT_EQ(numeric::to_string(g.status), std::string(numeric::to_string(n.status))) << id << " step " << step;
      ASSERT_EQ(g.events.size(), n.events.size()) << id << " step " << step;
      double worst = 0;
      for (std::size_t i = 0; i < n.events.size(); ++i) {
        EXPECT_EQ(g.events[i].kind, n.events[i].kind) << id << " event " << i;
        EXPECT_EQ(g.events[i].bounce, n.events[i].bounce) << id << " event " << i;
        worst = std::max(worst, std::fabs(g.events[i].t - n.events[i].t));
      }
      EXPECT_LE(worst, 1e-11) << id << " step " << step << ": event times differ by " << worst;
      EXPECT_NEAR(g.theta_o_final, n.theta_o_final, 1e-10) << id;
    }
  }
}

TEST(EffectsNeutral, TinyEffectsApproachTheNominalModel) {
  // Each effect at a value 1e-9 of its scale moves the first events by about as much.
  const auto& n = nominal("V");
  SimulationOptions o;
  o.t_end = 20;
  const SimulationResult reference = numeric::simulate_step(n, step_of("V"), o);
  std::vector<Effects> tiny(4);
  tiny[0].coulomb_load = 1e-9;
  tiny[1].restitution = 1e-9;
  tiny[2].saturation = 1e9;
  tiny[3].torque_offset = 1e-9;
  for (const Effects& e : tiny) {
    const SimulationResult r = numeric::simulate_effects_step(with_effects(n, e), step_of("V"), o, general);
    std::size_t compared = 0;
    for (std::size_t i = 0, j = 0; i < reference.events.size() && j < r.events.size(); ++j) {
      if (r.events[j].kind != reference.events[i].kind) continue;  // e.g. a vanishing bounce series
      EXPECT_NEAR(r.events[j].t, reference.events[i].t, 1e-6) << e.describe() << " event " << i;
      ++i;
      ++compared;
    }
    EXPECT_GE(compared, reference.events.size() - 1) << e.describe();
  }
}

TEST(EffectsGate, EveryModeOfEveryEffectPassesOnTheThesisCases) {
  std::vector<Effects> each(6);
  each[0] = coulomb(0.05, 0.03);
  each[1].restitution = 0.4;
  each[2].saturation = 0.3;
  each[3].mesh_stiffness = 400;
  each[3].mesh_damping = 4;
  each[4].torque_offset = -0.02;
  each[5] = coulomb(0.02, 0);
  each[5].saturation = 0.2;
  for (const char* id : {"I", "II", "V", "VIII"})
    for (const Effects& e : each) {
      const numeric::EffectValidationResult r = numeric::validate_effects(nominal(id), e);
      EXPECT_TRUE(r.passed()) << id << " " << e.describe() << "\n" << r.report().summary();
      for (const numeric::ModeValidation& m : r.report().modes)
        EXPECT_LE(m.max_abs_error, 1e-9) << id << " " << m.mode.describe();
    }
}

// ------------------------------------------------------------------ Coulomb friction

TEST(EffectsCoulomb, AFreeLoadStopsInFiniteTimeAtTheClosedFormInstant) {
  Parameters p = nominal("V").parameters();
  p.backlash = 100;  // no impact in the time considered
  const double TL = 0.03, v0 = 0.5;
  const auto& model = with_effects(nominal(p), coulomb(0, TL));
  HybridState s = numeric::state_on_face(p, -1, p.theta_R, 0, false);
  s.dtheta_L = v0;
  const SimulationResult r = numeric::simulate_effects(model, s, sampled(6, 0.01), general);
  // JL θ̈ + FL θ̇ = −TL from v0: stops at (JL/FL)·ln(1 + FL v0/TL).
  const double expected = p.JL / p.FL * std::log(1 + p.FL * v0 / TL);
  const auto stick = std::find_if(r.events.begin(), r.events.end(), [](const numeric::SimulationEvent& e) {
    return e.kind == EventKind::Stick && e.body == numeric::Body::Load;
  });
  ASSERT_NE(stick, r.events.end()) << "the load never stuck";
  EXPECT_NEAR(stick->t, expected, 1e-10) << "stopped at " << stick->t << " instead of " << expected;
  for (const numeric::TrajectorySample& x : r.samples)
    if (x.t > stick->t + 1e-9) {
      EXPECT_EQ(x.dtheta_L, 0.0) << "t = " << x.t;
      EXPECT_EQ(x.theta_L, stick->after.theta_L) << "t = " << x.t;
    }
}

TEST(EffectsCoulomb, AStuckMotorStaysPutInsideTheBandAndBreaksAwayAtItsEdge) {
  const Effects e = coulomb(0.05, 0);
  const auto& model = with_effects(nominal("V"), e);
  const Parameters& p = model.parameters();
  const SimulationResult r = numeric::simulate_effects_step(model, step_of("V"), sampled(60, 0.005), general);
  int breakaways = 0, sticks = 0;
  double stuck_since = -1, stuck_theta = 0;
  for (const numeric::SimulationEvent& ev : r.events) {
    if (ev.body != numeric::Body::Motor) continue;
    const double drive = p.K * (p.theta_R - ev.after.theta_L);  // output at the load
    if (ev.kind == EventKind::Stick) {
      ++sticks;
      EXPECT_LE(std::fabs(drive), e.coulomb_motor + 1e-12) << "stuck at t = " << ev.t << " with drive " << drive;
    }
    if (ev.kind == EventKind::Slip) {
      ++breakaways;
      EXPECT_NEAR(std::fabs(drive), e.coulomb_motor, 1e-9) << "broke away at t = " << ev.t;
    }
  }
  EXPECT_GT(sticks, 0);
  EXPECT_GT(breakaways, 0);
  // Between a stick and the next break-away, the motor does not move at all.
  std::size_t next = 0;
  for (const numeric::TrajectorySample& x : r.samples) {
    while (next < r.events.size() && r.events[next].t <= x.t) {
      const auto& ev = r.events[next++];
      if (ev.body == numeric::Body::Motor && ev.kind == EventKind::Stick) stuck_since = ev.t, stuck_theta = ev.after.theta_m;
      if (ev.body == numeric::Body::Motor && ev.kind == EventKind::Slip) stuck_since = -1;
      if (ev.kind == EventKind::Recombination || ev.kind == EventKind::Recontact) stuck_since = -1;
    }
    if (stuck_since >= 0) {
      EXPECT_EQ(x.dtheta_m, 0.0) << "t = " << x.t;
      EXPECT_EQ(x.theta_m, stuck_theta) << "t = " << x.t;
    }
  }
}

TEST(EffectsCoulomb, LargeFrictionStopsTheServoInADeadBandAwayFromTheReference) {
  for (const char* id : {"V", "III", "I"}) {
    const Effects e = coulomb(0.08, 0.06);
    const auto& model = with_effects(nominal(id), e);
    const Parameters& p = model.parameters();
    const SimulationResult r = numeric::simulate_effects_step(model, step_of(id), sampled(80, 0), general);
    ASSERT_EQ(r.status, numeric::SimulationStatus::Rest) << id << " returned " << numeric::to_string(r.status);
    const double error = r.theta_o_final - p.theta_R;
    EXPECT_NE(error, 0.0) << id;
    EXPECT_EQ(r.final_state.dtheta_m, 0.0);
    EXPECT_EQ(r.final_state.dtheta_L, 0.0);
    // The drive that holds it is inside the static band: |K·error| ≤ Tm + TL (contact) or ≤ Tm (free motor).
    const double drive = p.K * (p.theta_R - (p.measured_at == model::MeasuredAt::Motor ? r.final_state.theta_m
                                                                                          : r.final_state.theta_L));
    EXPECT_LE(std::fabs(drive), e.coulomb_motor + e.coulomb_load + 1e-12) << id << ": rests with error " << error;
  }
}

// ------------------------------------------------------------------ energy (output at the motor)

double potential(const Parameters& p, const Effects& e, double theta_m) {
  const double x = theta_m - p.theta_R, L = e.saturation;
  const double loop = e.saturating() && std::fabs(p.K * x) > L ? L * std::fabs(x) - L * L / (2 * p.K) : p.K * x * x / 2;
  return loop - e.torque_offset * x;
}

double energy(const Parameters& p, const Effects& e, const numeric::TrajectorySample& s) {
  double E = 0.5 * p.Jm * s.dtheta_m * s.dtheta_m + 0.5 * p.JL * s.dtheta_L * s.dtheta_L + potential(p, e, s.theta_m);
  if (e.compliant())
    for (int face : {-1, 1}) {
      const double delta = face * (s.theta_L - s.theta_m) - p.backlash / 2;
      if (delta > 0) E += 0.5 * e.mesh_stiffness * delta * delta;
    }
  return E;
}

TEST(EffectsEnergy, WithTheOutputAtTheMotorTheEnergyNeverGrows) {
  std::vector<Effects> each(5);
  each[0] = coulomb(0.03, 0.02);
  each[1].restitution = 0.5;
  each[2].saturation = 0.2;
  each[3].mesh_stiffness = 400;
  each[3].mesh_damping = 4;
  each[4].torque_offset = 0.05;
  each[4].coulomb_load = 0.01;
  for (const char* id : {"I", "II"})
    for (const Effects& e : each) {
      const auto& model = with_effects(nominal(id), e);
      const Parameters& p = model.parameters();
      const SimulationResult r = numeric::simulate_effects_step(model, step_of(id), sampled(30, 0.002), general);
      ASSERT_GT(r.samples.size(), 100u);
      double previous = energy(p, e, r.samples.front()), worst = 0;
      const double scale = std::max(1.0, previous);
      for (const numeric::TrajectorySample& s : r.samples) {
        const double E = energy(p, e, s);
        worst = std::max(worst, E - previous);
        previous = E;
      }
      EXPECT_LE(worst, 1e-9 * scale) << id << " " << e.describe() << ": the energy grew by " << worst;
    }
}

// ------------------------------------------------------------------ impacts

TEST(EffectsImpact, MomentumIsConservedAndNewtonsLawHoldsAtEveryImpact) {
  for (const auto& [id, e_value] : {std::pair<std::string, double>{"V", 0.4}, {"III", 0.7}, {"VIII", 0.2}}) {
    Effects e;
    e.restitution = e_value;
    const auto& model = with_effects(nominal(id), e);
    const Parameters& p = model.parameters();
    const SimulationResult r = numeric::simulate_effects_step(model, step_of(id), sampled(40, 0), general);
    int impacts = 0;
    for (const numeric::SimulationEvent& ev : r.events) {
      if ((ev.kind != EventKind::Recombination && ev.kind != EventKind::Recontact) || ev.accumulation) continue;
      ++impacts;
      const HybridState& a = ev.before;
      const HybridState& b = ev.after;
      const double momentum_before = p.Jm * a.dtheta_m + p.JL * a.dtheta_L;
      const double momentum_after = p.Jm * b.dtheta_m + p.JL * b.dtheta_L;
      EXPECT_NEAR(momentum_after, momentum_before, 1e-13 * std::max(1.0, std::fabs(momentum_before))) << id << " t = " << ev.t;
      EXPECT_NEAR(b.dtheta_L - b.dtheta_m, -e_value * (a.dtheta_L - a.dtheta_m), 1e-13) << id << " t = " << ev.t;
      const double kinetic_before = p.Jm * a.dtheta_m * a.dtheta_m + p.JL * a.dtheta_L * a.dtheta_L;
      const double kinetic_after = p.Jm * b.dtheta_m * b.dtheta_m + p.JL * b.dtheta_L * b.dtheta_L;
      EXPECT_LE(kinetic_after, kinetic_before * (1 + 1e-13)) << id << " t = " << ev.t;
    }
    EXPECT_GT(impacts, 5) << id;
  }
}

TEST(EffectsImpact, ABounceSeriesEndsInContactAtItsAccumulationTime) {
  Effects e;
  e.restitution = 0.4;
  const auto& model = with_effects(nominal("III"), e);
  const SimulationResult r = numeric::simulate_effects_step(model, step_of("III"), sampled(60, 0), general);
  EXPECT_NE(r.status, numeric::SimulationStatus::Chattering);
  EXPECT_NE(r.status, numeric::SimulationStatus::EventLimit);
  int series = 0;
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    if (!r.events[i].accumulation) continue;
    ++series;
    EXPECT_TRUE(r.events[i].after.in_contact) << "t = " << r.events[i].t;
    // The bounces before it shrink geometrically with the ratio e (a bouncing ball under a
    // nearly constant pressing acceleration): the last intervals' ratios tend to e.
    ASSERT_GE(i, 4u);
    const double d1 = r.events[i - 1].t - r.events[i - 2].t, d2 = r.events[i - 2].t - r.events[i - 3].t;
    EXPECT_NEAR(d1 / d2, e.restitution, 1e-3) << "t = " << r.events[i].t;
    // The summed tail: 2w/(α(1 − e)) is below the threshold, so at most that far from the last bounce.
    EXPECT_LE(r.events[i].t - r.events[i - 1].t,
              numeric::accumulation_fraction * numeric::servo_period(model.parameters()) * (1 + 1e-12));
  }
  EXPECT_GT(series, 2) << "no bounce series was summed";
}

// ------------------------------------------------------------------ saturation and compliance

TEST(EffectsSaturation, TheDriveReachesAndLeavesItsLimitExactlyAtThePositionsKThetaErrorIsL) {
  Effects e;
  e.saturation = 0.3;
  const auto& model = with_effects(nominal("V"), e);
  const Parameters& p = model.parameters();
  const SimulationResult r = numeric::simulate_effects_step(model, step_of("V"), sampled(60, 0), general);
  int switches = 0;
  for (const numeric::SimulationEvent& ev : r.events) {
    if (ev.kind != EventKind::Saturation && ev.kind != EventKind::Desaturation) continue;
    ++switches;
    EXPECT_NEAR(std::fabs(p.K * (p.theta_R - ev.theta_o)), e.saturation, 1e-12) << "t = " << ev.t;
    if (ev.kind == EventKind::Saturation)
      EXPECT_EQ(ev.after.drive_regime, p.K * (p.theta_R - ev.theta_o) > 0 ? 1 : -1) << "t = " << ev.t;
    else
      EXPECT_EQ(ev.after.drive_regime, 0);
  }
  EXPECT_GE(switches, 2);
}

TEST(EffectsCompliance, TheMeshPushesAndNeverPulls) {
  Effects e;
  e.mesh_stiffness = 400;
  e.mesh_damping = 4;
  for (const char* id : {"V", "I", "VIII"}) {
    const auto& model = with_effects(nominal(id), e);
    const Parameters& p = model.parameters();
    const SimulationResult r = numeric::simulate_effects_step(model, step_of(id), sampled(40, 0.001), general);
    int engaged = 0;
    for (const numeric::TrajectorySample& s : r.samples) {
      for (int face : {-1, 1}) {
        const double delta = face * (s.theta_L - s.theta_m) - p.backlash / 2;
        const double force = e.mesh_stiffness * delta + e.mesh_damping * face * (s.dtheta_L - s.dtheta_m);
        if (s.in_contact && delta > -1e-12) {
          ++engaged;
          EXPECT_GE(force, -1e-9) << id << ": a tensile mesh force " << force << " at t = " << s.t;
        }
      }
    }
    EXPECT_GT(engaged, 100) << id;
  }
}

TEST(EffectsCompliance, AStiffWellDampedMeshApproachesTheRigidInelasticGear) {
  const auto& n = nominal("V");
  SimulationOptions o;
  o.t_end = 6;
  const SimulationResult rigid = numeric::simulate_step(n, step_of("V"), o);
  ASSERT_GE(rigid.events.size(), 2u);
  double previous = INFINITY;
  for (double stiffness : {1e3, 1e4, 1e5, 1e6}) {
    Effects e;
    e.mesh_stiffness = stiffness;
    const double reduced_inertia = n.parameters().Jm * n.parameters().JL / (n.parameters().Jm + n.parameters().JL);
    e.mesh_damping = 2 * 20 * std::sqrt(stiffness * reduced_inertia);  // damping ratio 20
    const SimulationResult r = numeric::simulate_effects_step(with_effects(n, e), step_of("V"), o, general);
    ASSERT_GE(r.events.size(), 2u);
    const double gap = std::max(std::fabs(r.events[0].t - rigid.events[0].t), std::fabs(r.events[1].t - rigid.events[1].t));
    std::printf("stiffness %.0e: first separation and recombination within %.3e s of the rigid gear\n", stiffness, gap);
    EXPECT_LT(gap, previous) << "stiffness " << stiffness;
    previous = gap;
  }
  EXPECT_LT(previous, 2e-3);
}

// ------------------------------------------------------------------ delay

// The dominant root of J s² + F s + K e^{−sτ} = 0, by Newton's method from the undelayed root.
std::complex<double> dominant_root(double J, double F, double K, double tau) {
  std::complex<double> s(-F / (2 * J), std::sqrt(K / J - F * F / (4 * J * J)));
  for (int k = 0; k < 100; ++k) {
    const std::complex<double> g = J * s * s + F * s + K * std::exp(-s * tau);
    const std::complex<double> dg = 2.0 * J * s + F - K * tau * std::exp(-s * tau);
    s -= g / dg;
  }
  return s;
}

TEST(EffectsDelay, ARigidDelayedLoopOscillatesAtTheRootOfItsCharacteristicEquation) {
  Parameters p = nominal("V").parameters();
  p.backlash = 0;  // a rigid drive: the contact mode alone, J θ̈ + F θ̇ + K θ(t − τ) = K θR
  for (double tau : {0.1, 0.3}) {
    Effects e;
    e.delay = tau;
    const auto& model = with_effects(nominal(p), e);
    const SimulationResult r = numeric::simulate_effects_step(model, 1.0, sampled(40, 0.002), general);
    // Zero crossings of θo − θR (cubic Hermite on the samples) and the extremes between them.
    std::vector<double> crossings, peaks;
    for (std::size_t i = 1; i < r.samples.size(); ++i) {
      const auto& a = r.samples[i - 1];
      const auto& b = r.samples[i];
      const double ya = a.theta_o - p.theta_R, yb = b.theta_o - p.theta_R;
      if (a.t > 15 && ya * yb < 0) crossings.push_back(a.t + (b.t - a.t) * ya / (ya - yb));
      if (a.t > 15 && a.dtheta_o * b.dtheta_o < 0) peaks.push_back(std::fabs(ya));
    }
    ASSERT_GE(crossings.size(), 4u);
    ASSERT_GE(peaks.size(), 3u);
    const std::complex<double> root = dominant_root(p.Jm + p.JL, p.Fm + p.FL, p.K, tau);
    const double half_period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
    const double decay = std::log(peaks.back() / peaks.front()) / ((peaks.size() - 1) * half_period);
    std::printf("tau %.2f: root %.8f%+.8fi, simulated %.8f%+.8fi\n", tau, root.real(), root.imag(), decay,
                M_PI / half_period);
    EXPECT_NEAR(M_PI / half_period, root.imag(), 2e-4 * root.imag()) << "tau = " << tau;
    EXPECT_NEAR(decay, root.real(), 2e-3 * std::fabs(root.real())) << "tau = " << tau;
  }
}

TEST(EffectsDelay, AVanishingDelayApproachesTheUndelayedModel) {
  const auto& n = nominal("V");
  SimulationOptions o;
  o.t_end = 10;
  const SimulationResult reference = numeric::simulate_step(n, step_of("V"), o);
  double previous = INFINITY;
  for (double tau : {1e-2, 1e-3}) {
    Effects e;
    e.delay = tau;
    const SimulationResult r = numeric::simulate_effects_step(with_effects(n, e), step_of("V"), o, general);
    ASSERT_GE(r.events.size(), 3u);
    double gap = 0;
    for (int i = 0; i < 3; ++i) gap = std::max(gap, std::fabs(r.events[i].t - reference.events[i].t));
    EXPECT_LT(gap, previous) << "tau = " << tau;
    EXPECT_LT(gap, 2 * tau) << "tau = " << tau;  // first order in τ
    previous = gap;
  }
}

// ------------------------------------------------------------------ every pair of effects

TEST(EffectsPairs, EveryPairRunsToAStatusOnCaseV) {
  std::vector<std::pair<std::string, Effects>> single;
  Effects e;
  e = Effects{}; e.coulomb_motor = 0.02; single.push_back({"coulomb_motor", e});
  e = Effects{}; e.coulomb_load = 0.01; single.push_back({"coulomb_load", e});
  e = Effects{}; e.restitution = 0.3; single.push_back({"restitution", e});
  e = Effects{}; e.saturation = 0.25; single.push_back({"saturation", e});
  e = Effects{}; e.mesh_stiffness = 400; e.mesh_damping = 8; single.push_back({"compliance", e});
  e = Effects{}; e.delay = 0.05; single.push_back({"delay", e});
  e = Effects{}; e.torque_offset = 0.01; single.push_back({"torque_offset", e});
  int pairs = 0;
  for (std::size_t i = 0; i < single.size(); ++i)
    for (std::size_t j = i + 1; j < single.size(); ++j) {
      if (single[i].first == "restitution" && single[j].first == "compliance") continue;  // refused by the loader
      Effects both = single[i].second;
      const Effects& other = single[j].second;
      both.coulomb_motor = std::max(both.coulomb_motor, other.coulomb_motor);
      both.coulomb_load = std::max(both.coulomb_load, other.coulomb_load);
      both.restitution = std::max(both.restitution, other.restitution);
      both.saturation = std::min(both.saturation, other.saturation);
      both.mesh_stiffness = std::min(both.mesh_stiffness, other.mesh_stiffness);
      both.mesh_damping = std::max(both.mesh_damping, other.mesh_damping);
      both.delay = std::max(both.delay, other.delay);
      both.torque_offset = both.torque_offset + other.torque_offset;
      const auto& model = with_effects(nominal("V"), both);
      const SimulationResult r = numeric::simulate_effects_step(model, step_of("V"), sampled(60, 0.05), general);
      const std::string label = single[i].first + " + " + single[j].first;
      EXPECT_TRUE(r.status == numeric::SimulationStatus::Completed || r.status == numeric::SimulationStatus::Rest)
          << label << " returned " << numeric::to_string(r.status);
      EXPECT_TRUE(std::isfinite(r.theta_o_final)) << label;
      for (const auto& s : r.samples) ASSERT_TRUE(std::isfinite(s.theta_o) && std::isfinite(s.dtheta_o)) << label;
      for (std::size_t k = 1; k < r.events.size(); ++k) EXPECT_GE(r.events[k].t, r.events[k - 1].t) << label;
      ++pairs;
    }
  EXPECT_EQ(pairs, 20);
}

// ------------------------------------------------------------------ limit cycles with effects

TEST(EffectsLimitCycle, TheGeneralReturnMapReproducesEveryNominalCycle) {
  for (const char* id : {"III", "IV", "V", "VI", "VII", "VIII"}) {
    const numeric::LimitCycle n = numeric::find_limit_cycle(nominal(id));
    numeric::EffectLimitCycleOptions o;
    o.general = true;
    o.step = step_of(id);
    const numeric::LimitCycle g = numeric::find_limit_cycle(with_effects(nominal(id), Effects{}), o);
    ASSERT_EQ(g.status, numeric::CycleStatus::LimitCycle) << id << ": " << g.reason;
    EXPECT_NEAR(g.peak_to_peak, n.peak_to_peak, 1e-9) << id;
    EXPECT_NEAR(g.amplitude, n.amplitude, 1e-9) << id;
    EXPECT_NEAR(g.period, n.period, 1e-9) << id;
    EXPECT_NEAR(g.separation_velocity, n.separation_velocity, 1e-9) << id;
    EXPECT_NEAR(g.multiplier, n.multiplier, 1e-5 * n.multiplier) << id << ": returned " << g.multiplier << " instead of "
                                                                  << n.multiplier;
  }
}

TEST(EffectsLimitCycle, CoulombFrictionShrinksThenKillsTheCycle) {
  numeric::EffectLimitCycleOptions o;
  o.step = step_of("V");
  const double nominal_size = numeric::find_limit_cycle(nominal("V")).peak_to_peak;
  double previous = nominal_size;
  for (double TL : {0.005, 0.01, 0.015}) {
    const numeric::LimitCycle c = numeric::find_limit_cycle(with_effects(nominal("V"), coulomb(0, TL)), o);
    ASSERT_EQ(c.status, numeric::CycleStatus::LimitCycle) << "TL = " << TL << ": " << c.reason;
    EXPECT_LT(c.peak_to_peak, previous) << "TL = " << TL;
    previous = c.peak_to_peak;
  }
  const numeric::LimitCycle dead = numeric::find_limit_cycle(with_effects(nominal("V"), coulomb(0, 0.04)), o);
  EXPECT_EQ(dead.status, numeric::CycleStatus::None);
  EXPECT_NE(dead.reason.find("rest"), std::string::npos) << dead.reason;
}

TEST(EffectsLimitCycle, EachCycleIsWhereTheStepResponseEndsUp) {
  std::vector<Effects> each(5);
  each[0] = coulomb(0.01, 0.005);
  each[1].restitution = 0.4;
  each[2].saturation = 0.1;
  each[3].torque_offset = 0.02;
  each[4].delay = 0.05;
  for (const Effects& e : each) {
    const auto& model = with_effects(nominal("V"), e);
    numeric::EffectLimitCycleOptions o;
    o.step = step_of("V");
    const numeric::LimitCycle c = numeric::find_limit_cycle(model, o);
    ASSERT_EQ(c.status, numeric::CycleStatus::LimitCycle) << e.describe() << ": " << c.reason;
    SimulationOptions so;
    so.t_end = 400;
    so.track_extremes = true;
    const SimulationResult r =
        numeric::simulate_effects_step(model, step_of("V"), so, {.general_engine = true, .extremes_after = 400 - 3 * c.period});
    EXPECT_NEAR(r.extremes.theta_o_max - r.extremes.theta_o_min, c.peak_to_peak, 1e-7) << e.describe();
    std::printf("case V, %s: peak-to-peak %.9f, period %.6f, multiplier %.6f (%s)\n", e.describe().c_str(), c.peak_to_peak,
                c.period, c.multiplier, c.method.c_str());
  }
}

}  // namespace
