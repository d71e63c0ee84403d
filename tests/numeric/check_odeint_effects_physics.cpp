// The physics of the independent odeint simulator with effects
// (odeint_effects_simulation.hpp, semantics docs/effects.md), checked against
// closed forms, conservation laws and the nominal odeint simulator — never against
// the closed-form effects simulator (the point of this one is to be independent
// of it).  Every comparison prints what it measured.
//
//   neutral effects       = simulate_with_odeint: event kinds, bounce flags, faces,
//                           status, times within 1e-9 s (thesis cases, their step and
//                           a negative one; random parameter sets)
//   Coulomb               closed-form stop time of a coasting load; a stuck body stays
//                           put inside its band and breaks away exactly at its edge;
//                           large friction rests in the dead band |D| ≤ Tm + TL
//   energy, momentum      kinetic energy never rises at an impact, momentum is
//                           conserved and v_rel⁺ = −e·v_rel⁻; with the output at the
//                           motor the total energy never rises along the trajectory
//   restitution           a bounce series ends with an `accumulation` recontact
//   saturation            the applied drive is sat(K(θR − θo)) + T0 at every sample,
//                           events exactly at K(θR − θo) = ±L
//   compliance            the mesh never pulls; stiff and heavily damped → the rigid
//                           inelastic model
//   delay                 the dominant root of J s² + F s + K e^{−sτ} (rigid drive);
//                           breakaways and regime switches where the delayed drive
//                           K(θR − θo(t − τ)) meets its limit; first-order convergence
//                           to the undelayed model as τ → 0; accuracy of 60 s records
//                           against a much tighter tolerance, and their time
//   statuses              every status reachable, never a hang or a NaN
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"
#include "backlash/numeric/odeint_simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using numeric::Body;
using numeric::Effects;
using numeric::EventKind;
using numeric::HybridState;
using numeric::Parameters;
using numeric::SimulationOptions;
using numeric::SimulationResult;
using numeric::SimulationStatus;

constexpr double time_tolerance = 1e-9;

Parameters case_parameters(const std::string& id) { return numeric::parameters_of(model::load_case(id)); }
double case_step(const std::string& id) { return model::to_double(model::load_case(id).experiment->step); }

Parameters parameters(double Jm, double Fm, double JL, double FL, double K, double b, double theta_R,
                      model::MeasuredAt at) {
  Parameters p;
  p.Jm = Jm;
  p.Fm = Fm;
  p.JL = JL;
  p.FL = FL;
  p.K = K;
  p.backlash = b;
  p.theta_R = theta_R;
  p.measured_at = at;
  return p;
}

std::string describe(const SimulationResult& r, std::size_t limit = 30) {
  std::ostringstream out;
  out.precision(10);
  out << numeric::to_string(r.status) << ", " << r.events.size() << " events:";
  for (std::size_t i = 0; i < r.events.size() && i < limit; ++i) {
    const auto& e = r.events[i];
    out << " " << numeric::to_string(e.kind) << (e.bounce ? "!" : "") << (e.accumulation ? "*" : "");
    if (e.body != Body::None) out << "(" << numeric::to_string(e.body) << ")";
    out << "@" << e.t;
  }
  return out.str();
}

SimulationResult run(const Parameters& p, const Effects& e, double step, double t_end, double sample_interval = 0,
                     const numeric::OdeintSimulationOptions& oo = {}) {
  SimulationOptions o;
  o.t_end = t_end;
  o.sample_interval = sample_interval;
  return numeric::simulate_effects_step_with_odeint(p, e, step, o, oo);
}

bool all_finite(const SimulationResult& r) {
  auto ok = [](const HybridState& h) {
    return std::isfinite(h.theta_m) && std::isfinite(h.dtheta_m) && std::isfinite(h.theta_L) && std::isfinite(h.dtheta_L);
  };
  if (!ok(r.final_state) || !std::isfinite(r.t_final) || !std::isfinite(r.theta_o_final)) return false;
  for (const auto& e : r.events)
    if (!ok(e.after) || !std::isfinite(e.t) || !std::isfinite(e.theta_o) || !std::isfinite(e.dtheta_o)) return false;
  for (const auto& s : r.samples)
    if (!std::isfinite(s.theta_m) || !std::isfinite(s.dtheta_m) || !std::isfinite(s.theta_L) || !std::isfinite(s.dtheta_L))
      return false;
  return true;
}

// The state just before time t (the simulation stopped there): the pre-impact state of an
// event at t.
HybridState state_before(const Parameters& p, const Effects& e, double step, double t) {
  SimulationOptions o;
  o.t_end = t - 1e-14 * std::max(1.0, t);
  return numeric::simulate_effects_step_with_odeint(p, e, step, o).final_state;
}

// A few random parameter sets (fixed seed), thesis-like magnitudes.
struct RandomSet {
  Parameters p;
  double step;
};
std::vector<RandomSet> random_sets(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<RandomSet> sets;
  for (int i = 0; i < n; ++i) {
    double x[10];
    for (double& v : x) v = u(rng);  // drawn in sequence (argument evaluation order is unspecified)
    RandomSet s;
    s.p = parameters(0.05 + 0.95 * x[0], 0.5 * x[1], 0.05 + 0.95 * x[2], 0.5 * x[3], 0.5 + 2.5 * x[4], 0.02 + 0.5 * x[5],
                     -2 + 4 * x[6], x[7] < 0.5 ? model::MeasuredAt::Motor : model::MeasuredAt::Load);
    s.step = (x[8] < 0.5 ? -1 : 1) * (0.1 + 1.2 * x[9]);
    sets.push_back(s);
  }
  return sets;
}

double measured_of(const Parameters& p, const HybridState& h) { return numeric::measured(p, h); }

// ---------------------------------------------------------------- neutral effects

struct NeutralAgreement {
  double max_dt = 0;
  std::size_t events = 0;
  int bounces = 0;
};

NeutralAgreement compare_with_nominal(const Parameters& p, double step, const std::string& label) {
  SimulationOptions o;
  o.t_end = 60;
  o.track_extremes = true;
  o.sample_interval = 0.25;
  const SimulationResult nominal = numeric::simulate_step_with_odeint(p, step, o);
  const SimulationResult effects = numeric::simulate_effects_step_with_odeint(p, Effects{}, step, o);
  NeutralAgreement a;
  EXPECT_EQ(std::string(numeric::to_string(effects.status)), numeric::to_string(nominal.status))
      << label << ": simulate_effects_step_with_odeint returned status " << numeric::to_string(effects.status)
      << " instead of " << numeric::to_string(nominal.status);
  EXPECT_EQ(effects.events.size(), nominal.events.size())
      << label << ": returned " << effects.events.size() << " events instead of " << nominal.events.size()
      << "\n  nominal: " << describe(nominal) << "\n  effects: " << describe(effects);
  const std::size_t n = std::min(effects.events.size(), nominal.events.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& x = effects.events[i];
    const auto& y = nominal.events[i];
    if (x.kind != y.kind || x.bounce != y.bounce || x.after.face != y.after.face || x.after.in_contact != y.after.in_contact) {
      ADD_FAILURE() << label << ": event " << i << " returned " << numeric::to_string(x.kind) << (x.bounce ? " (bounce)" : "")
                    << " at t = " << x.t << " instead of " << numeric::to_string(y.kind) << (y.bounce ? " (bounce)" : "")
                    << " at t = " << y.t;
      return a;
    }
    a.max_dt = std::max(a.max_dt, std::fabs(x.t - y.t));
    a.bounces += x.bounce;
    EXPECT_LE(std::fabs(x.t - y.t), time_tolerance)
        << label << ": event " << i << " returned t = " << x.t << " instead of " << y.t;
  }
  a.events = n;
  EXPECT_EQ(effects.samples.size(), nominal.samples.size()) << label << ": samples";
  EXPECT_NEAR(effects.extremes.theta_o_max, nominal.extremes.theta_o_max, 1e-9) << label;
  EXPECT_NEAR(effects.extremes.theta_o_min, nominal.extremes.theta_o_min, 1e-9) << label;
  return a;
}

TEST(OdeintEffects, NeutralEffectsReproduceTheNominalSimulatorOnTheThesisCases) {
  for (const std::string& id : model::thesis_case_ids()) {
    const Parameters p = case_parameters(id);
    const double step = case_step(id);
    for (double a : {step, -step}) {
      const std::string label = "case " + id + " step " + std::to_string(a);
      const NeutralAgreement r = compare_with_nominal(p, a, label);
      std::printf("neutral  %-22s %3zu events %2d bounces  max |dt| %.2e\n", label.c_str(), r.events, r.bounces, r.max_dt);
      EXPECT_GT(r.events, 0u) << label;
    }
  }
}

TEST(OdeintEffects, NeutralEffectsReproduceTheNominalSimulatorOnRandomParameters) {
  double worst = 0;
  std::size_t events = 0;
  int bounces = 0;
  for (const RandomSet& s : random_sets(12, 20240611)) {
    const NeutralAgreement r = compare_with_nominal(s.p, s.step, "random set");
    worst = std::max(worst, r.max_dt);
    events += r.events;
    bounces += r.bounces;
  }
  // Parameter sets whose impacts bounce (light loads, output at the motor).
  for (const Parameters& p : {parameters(0.5, 0.1, 0.05, 0, 1, 0.3, 1, model::MeasuredAt::Motor),
                              parameters(0.5, 0.1, 0.02, 0, 1, 0.3, 1, model::MeasuredAt::Motor)}) {
    const NeutralAgreement r = compare_with_nominal(p, 0.3, "bouncing set");
    worst = std::max(worst, r.max_dt);
    events += r.events;
    bounces += r.bounces;
  }
  std::printf("neutral  random + bouncing sets: %zu events, %d bounces, max |dt| %.2e\n", events, bounces, worst);
  EXPECT_GT(bounces, 0);
}

// ---------------------------------------------------------------- Coulomb friction

// A free load coasting (a wide backlash, no impact) against Coulomb and viscous friction:
// JL θ̈ + FL θ̇ = −TL stops at t = (JL/FL)·ln(1 + FL·v0/TL) (JL·v0/TL without FL).
TEST(OdeintEffects, CoastingLoadStopsAtTheClosedFormTime) {
  struct Trial {
    double JL, FL, TL, v0;
  };
  const Trial trials[] = {{0.5, 0.3, 0.05, 0.4}, {0.8, 0, 0.1, -0.3}, {0.2, 0.5, 0.01, 1.2}, {1.0, 0.05, 0.3, 0.2}};
  for (const Trial& tr : trials) {
    const Parameters p = parameters(0.5, 0.1, tr.JL, tr.FL, 1, 10, 1, model::MeasuredAt::Motor);
    Effects e;
    e.coulomb_load = tr.TL;
    HybridState s;
    s.in_contact = false;
    s.face = -1;
    s.theta_m = 1;  // the motor at rest at θR: it stays there (output at the motor)
    s.theta_L = 1;
    s.dtheta_L = tr.v0;
    SimulationOptions o;
    o.t_end = 20;
    const SimulationResult r = numeric::simulate_effects_with_odeint(p, e, s, o);
    const double v = std::fabs(tr.v0);
    const double expected = tr.FL > 0 ? tr.JL / tr.FL * std::log1p(tr.FL * v / tr.TL) : tr.JL * v / tr.TL;
    ASSERT_FALSE(r.events.empty()) << describe(r);
    const auto& stick = r.events.front();
    EXPECT_EQ(stick.kind, EventKind::Stick) << "returned " << numeric::to_string(stick.kind) << " instead of stick";
    EXPECT_EQ(stick.body, Body::Load) << "returned " << numeric::to_string(stick.body) << " instead of load";
    EXPECT_NEAR(stick.t, expected, 1e-9) << "the stop time returned " << stick.t << " instead of " << expected;
    EXPECT_EQ(stick.after.dtheta_L, 0.0);
    EXPECT_TRUE(stick.after.load_stuck);
    const double distance = tr.FL > 0 ? tr.JL / tr.FL * (v - tr.TL / tr.FL * std::log1p(tr.FL * v / tr.TL))
                                      : 0.5 * tr.JL * v * v / tr.TL;
    EXPECT_NEAR(std::fabs(stick.after.theta_L - 1), distance, 1e-9);
    std::printf("coulomb  coasting load JL=%.2f FL=%.2f TL=%.2f v0=%+.2f: stops at %.12f (closed form %.12f)\n", tr.JL,
                tr.FL, tr.TL, tr.v0, stick.t, expected);
  }
}

// A stuck motor with the output at the load: the drive K(θR − θL) follows the coasting
// load; the motor stays exactly put while |D| ≤ Tm and breaks away where |D| = Tm:
// θL(t) = θR + v0·(JL/FL)(1 − e^{−FL t/JL}) ⇒ t = −(JL/FL)·ln(1 − Tm·FL/(K·v0·JL)).
TEST(OdeintEffects, StuckMotorStaysPutInsideTheBandAndBreaksAwayAtItsEdge) {
  const Parameters p = parameters(0.5, 0.1, 0.5, 0.3, 1, 2, 1, model::MeasuredAt::Load);
  for (double offset : {0.0, 0.03}) {
    Effects e;
    e.coulomb_motor = 0.1;
    e.torque_offset = offset;
    HybridState s;
    s.in_contact = false;
    s.face = -1;
    s.theta_m = 1;
    s.theta_L = 1;
    s.dtheta_L = 0.2;
    s.motor_stuck = true;
    SimulationOptions o;
    o.t_end = 3;
    o.sample_interval = 0.01;
    const SimulationResult r = numeric::simulate_effects_with_odeint(p, e, s, o);
    ASSERT_FALSE(r.events.empty()) << describe(r);
    const auto& slip = r.events.front();
    EXPECT_EQ(slip.kind, EventKind::Slip) << "returned " << numeric::to_string(slip.kind) << " instead of slip";
    EXPECT_EQ(slip.body, Body::Motor);
    // D = K(θR − θL) + T0 reaches −Tm (the load moves forward).
    const double reach = (e.coulomb_motor + offset) / p.K;
    const double expected = -p.JL / p.FL * std::log(1 - reach * p.FL / (0.2 * p.JL));
    EXPECT_NEAR(slip.t, expected, 1e-9) << "the breakaway returned t = " << slip.t << " instead of " << expected;
    EXPECT_LT(slip.after.dtheta_m, 1e-300);
    for (const auto& sample : r.samples) {
      if (sample.t >= slip.t) break;
      EXPECT_EQ(sample.theta_m, 1.0) << "the stuck motor moved at t = " << sample.t;
      EXPECT_EQ(sample.dtheta_m, 0.0) << "the stuck motor moved at t = " << sample.t;
    }
    // After the breakaway the motor moves in the drive's direction (−1).
    bool moved = false;
    for (const auto& sample : r.samples)
      if (sample.t > slip.t + 0.05) {
        EXPECT_LT(sample.dtheta_m, 0.0) << "t = " << sample.t;
        moved = true;
        break;
      }
    EXPECT_TRUE(moved);
    std::printf("coulomb  stuck motor, T0 = %.2f: breaks away at %.12f (closed form %.12f)\n", offset, slip.t, expected);
  }
}

// With the drive constant a stuck pair (or stuck bodies) is at rest: the status is `rest`
// away from θR, inside the static band; every stick and slip obeys the band.
TEST(OdeintEffects, LargeCoulombRestsInTheDeadBand) {
  struct Trial {
    const char* id;
    double Tm, TL, T0;
  };
  const Trial trials[] = {{"V", 0.1, 0.1, 0}, {"V", 0.25, 0.05, 0.05}, {"I", 0.1, 0.05, 0}, {"III", 0.02, 0.2, -0.03},
                          {"II", 0.05, 0.05, 0.02}, {"VIII", 0.3, 0.3, 0}};
  for (const Trial& tr : trials) {
    const Parameters p = case_parameters(tr.id);
    Effects e;
    e.coulomb_motor = tr.Tm;
    e.coulomb_load = tr.TL;
    e.torque_offset = tr.T0;
    const SimulationResult r = run(p, e, case_step(tr.id), 200);
    const std::string label = std::string("case ") + tr.id + " " + e.describe();
    ASSERT_EQ(r.status, SimulationStatus::Rest) << label << ": returned " << describe(r) << " instead of rest";
    ASSERT_FALSE(r.events.empty());
    EXPECT_EQ(r.events.back().kind, EventKind::Rest);
    EXPECT_TRUE(r.final_state.motor_stuck && r.final_state.load_stuck) << label;
    EXPECT_EQ(r.final_state.dtheta_m, 0.0);
    EXPECT_EQ(r.final_state.dtheta_L, 0.0);
    const double error = r.theta_o_final - p.theta_R;
    const double drive = -p.K * error + tr.T0;
    EXPECT_LE(std::fabs(drive), tr.Tm + tr.TL + 1e-12)
        << label << ": the final drive returned " << drive << " instead of one within ±" << tr.Tm + tr.TL;
    EXPECT_GT(std::fabs(error), 1e-6) << label << ": rest exactly at θR (no dead band?)";
    // The rest is at the last stick.
    const auto& rest = r.events.back();
    ASSERT_GE(r.events.size(), 2u);
    EXPECT_EQ(rest.t, r.events[r.events.size() - 2].t);
    // Sticks within the band, breakaways at its edge.
    for (const auto& ev : r.events) {
      if (ev.kind != EventKind::Stick && ev.kind != EventKind::Slip) continue;
      const double d = p.K * (p.theta_R - measured_of(p, ev.after)) + tr.T0;
      if (ev.body == Body::Both && ev.after.in_contact) {
        const double v = -ev.after.face * d;  // pushing component
        if (ev.kind == EventKind::Stick) {
          EXPECT_TRUE(v <= tr.Tm + tr.TL + 1e-12 && v >= -tr.Tm - 1e-12) << label << ": pair stuck with v = " << v;
        }
      } else if (ev.body == Body::Motor && !ev.after.in_contact) {
        if (ev.kind == EventKind::Stick) {
          EXPECT_LE(std::fabs(d), tr.Tm + 1e-12) << label;
        }
        if (ev.kind == EventKind::Slip) {
          EXPECT_NEAR(std::fabs(d), tr.Tm, 1e-9) << label;
        }
      }
    }
    std::printf("coulomb  %-4s %-40s rest at t = %8.4f, error %+.6f, drive %+.6f (band %.3f), %zu events\n", tr.id,
                e.describe().c_str(), rest.t, error, drive, tr.Tm + tr.TL, r.events.size());
  }
}

// ---------------------------------------------------------------- energy and momentum

struct ImpactCheck {
  int impacts = 0;
  double max_momentum = 0, max_restitution = 0, max_energy_rise = -INFINITY;
};

// At every impact event: momentum conserved, v_rel⁺ = −e·v_rel⁻, kinetic energy not higher.
ImpactCheck check_impacts(const Parameters& p, const Effects& e, double step, double t_end, const std::string& label,
                          int limit = 12) {
  ImpactCheck c;
  const SimulationResult r = run(p, e, step, t_end);
  EXPECT_TRUE(all_finite(r)) << label;
  for (std::size_t i = 0; i < r.events.size() && c.impacts < limit; ++i) {
    const auto& ev = r.events[i];
    if (ev.kind != EventKind::Recombination && ev.kind != EventKind::Recontact) continue;
    if (ev.accumulation) continue;  // the end of a summed series (an inelastic impact τ∞ earlier)
    if (i > 0 && r.events[i - 1].t == ev.t) continue;  // a second event at the same instant
    const HybridState b = state_before(p, e, step, ev.t);
    const HybridState& a = ev.after;
    const double momentum_before = p.Jm * b.dtheta_m + p.JL * b.dtheta_L;
    const double momentum_after = p.Jm * a.dtheta_m + p.JL * a.dtheta_L;
    const double ke_before = 0.5 * (p.Jm * b.dtheta_m * b.dtheta_m + p.JL * b.dtheta_L * b.dtheta_L);
    const double ke_after = 0.5 * (p.Jm * a.dtheta_m * a.dtheta_m + p.JL * a.dtheta_L * a.dtheta_L);
    const double v_before = b.dtheta_L - b.dtheta_m, v_after = a.dtheta_L - a.dtheta_m;
    const double scale = std::max(1e-3, std::fabs(v_before));
    c.max_momentum = std::max(c.max_momentum, std::fabs(momentum_after - momentum_before));
    c.max_energy_rise = std::max(c.max_energy_rise, ke_after - ke_before);
    EXPECT_NEAR(momentum_after, momentum_before, 1e-8)
        << label << ": momentum at the impact at t = " << ev.t << " returned " << momentum_after << " instead of "
        << momentum_before;
    EXPECT_LE(ke_after, ke_before + 1e-9) << label << ": kinetic energy rose at the impact at t = " << ev.t;
    if (e.restitution > 0 && !e.compliant()) {
      const double expected = -e.restitution * v_before;
      c.max_restitution = std::max(c.max_restitution, std::fabs(v_after - expected) / scale);
      EXPECT_NEAR(v_after, expected, 1e-8 * scale)
          << label << ": v_rel after the impact at t = " << ev.t << " returned " << v_after << " instead of " << expected;
    } else if (!e.compliant()) {
      EXPECT_NEAR(v_after, 0.0, 1e-12) << label << ": inelastic impact at t = " << ev.t;
    }
    ++c.impacts;
  }
  return c;
}

TEST(OdeintEffects, ImpactsConserveMomentumAndObeyNewtonsLaw) {
  struct Trial {
    const char* id;
    Effects e;
  };
  auto with = [](std::function<void(Effects&)> f) {
    Effects e;
    f(e);
    return e;
  };
  const Trial trials[] = {
      {"V", with([](Effects& e) { e.restitution = 0.5; })},
      {"I", with([](Effects& e) { e.restitution = 0.8; })},
      {"III", with([](Effects& e) { e.restitution = 0.3; e.coulomb_load = 0.02; })},
      {"IV", with([](Effects& e) { e.restitution = 0.6; e.saturation = 0.4; })},
      {"VI", with([](Effects& e) { e.restitution = 0.4; e.delay = 0.1; })},
      {"VII", with([](Effects& e) { e.coulomb_motor = 0.03; e.torque_offset = 0.05; })},
      {"II", with([](Effects& e) { e.restitution = 0.9; })},
  };
  for (const Trial& tr : trials) {
    const std::string label = std::string("case ") + tr.id + " " + tr.e.describe();
    const ImpactCheck c = check_impacts(case_parameters(tr.id), tr.e, case_step(tr.id), 30, label);
    EXPECT_GT(c.impacts, 0) << label;
    std::printf("impacts  %-4s %-38s %2d impacts: max |Δmomentum| %.1e, max |v_rel⁺ + e v_rel⁻|/|v_rel⁻| %.1e, max ΔKE %+.1e\n",
                tr.id, tr.e.describe().c_str(), c.impacts, c.max_momentum, c.max_restitution, c.max_energy_rise);
  }
  for (const RandomSet& s : random_sets(6, 77)) {
    Effects e;
    e.restitution = 0.5;
    e.coulomb_motor = 0.01;
    check_impacts(s.p, e, s.step, 20, "random set with " + e.describe(), 6);
  }
}

// Total energy with the output at the motor (the drive is then the force of a potential):
// ½Jm θ̇m² + ½JL θ̇L² + U(θm) + ½kc·max(0, δ)² on each face, U the potential of
// sat(K(θR − θm)) + T0.  Every effect but the delay only dissipates.
double total_energy(const Parameters& p, const Effects& e, const numeric::TrajectorySample& s) {
  const double d = s.theta_m - p.theta_R;
  double U = 0.5 * p.K * d * d;
  if (e.saturating() && p.K * std::fabs(d) > e.saturation)
    U = e.saturation * std::fabs(d) - 0.5 * e.saturation * e.saturation / p.K;
  U -= e.torque_offset * s.theta_m;
  double mesh = 0;
  if (e.compliant()) {
    const double x = s.theta_L - s.theta_m;
    for (int side : {+1, -1}) {
      const double delta = side * x - p.backlash / 2;
      if (delta > 0) mesh += 0.5 * e.mesh_stiffness * delta * delta;
    }
  }
  return 0.5 * (p.Jm * s.dtheta_m * s.dtheta_m + p.JL * s.dtheta_L * s.dtheta_L) + U + mesh;
}

TEST(OdeintEffects, TotalEnergyNeverRisesWithTheOutputAtTheMotor) {
  std::vector<std::pair<std::string, Effects>> trials;
  auto add = [&](std::function<void(Effects&)> f) {
    Effects e;
    f(e);
    trials.emplace_back("I", e);
    trials.emplace_back("II", e);
  };
  add([](Effects&) {});
  add([](Effects& e) { e.coulomb_motor = 0.03; e.coulomb_load = 0.02; });
  add([](Effects& e) { e.restitution = 0.7; });
  add([](Effects& e) { e.saturation = 0.3; });
  add([](Effects& e) { e.mesh_stiffness = 400; e.mesh_damping = 4; });
  add([](Effects& e) { e.mesh_stiffness = 100; e.mesh_damping = 0; });
  add([](Effects& e) { e.restitution = 0.5; e.coulomb_load = 0.02; e.saturation = 0.4; e.torque_offset = 0.05; });
  add([](Effects& e) { e.mesh_stiffness = 1000; e.mesh_damping = 2; e.coulomb_motor = 0.02; e.saturation = 0.5; });
  for (const auto& [id, e] : trials) {
    const Parameters p = case_parameters(id);
    const SimulationResult r = run(p, e, case_step(id), 25, 1e-3);
    ASSERT_TRUE(all_finite(r));
    ASSERT_GT(r.samples.size(), 1000u);
    double worst = -INFINITY;
    const double E0 = total_energy(p, e, r.samples.front());
    for (std::size_t i = 1; i < r.samples.size(); ++i) {
      const double rise = total_energy(p, e, r.samples[i]) - total_energy(p, e, r.samples[i - 1]);
      worst = std::max(worst, rise);
      if (rise > 1e-9) {
        ADD_FAILURE() << "case " << id << " " << e.describe() << ": the energy returned "
                      << total_energy(p, e, r.samples[i]) << " at t = " << r.samples[i].t << " instead of at most "
                      << total_energy(p, e, r.samples[i - 1]);
        break;
      }
    }
    std::printf("energy   %-3s %-52s E0 %.4f → %.6f, max rise per ms %+.1e\n", id.c_str(), e.describe().c_str(), E0,
                total_energy(p, e, r.samples.back()), worst);
  }
}

// ---------------------------------------------------------------- restitution

// While the drive presses the bodies together (α > 0) the bounces of e > 0 converge: the
// series is summed once τ∞ ≤ 1e-7·T_servo, after about log(1e-7·T_servo/τ∞₀)/log(e)
// simulated bounces; with e near 1 the series outlast the pressing phase (no summing, and
// no chattering either).
TEST(OdeintEffects, BounceSeriesEndsWithAnAccumulation) {
  struct Trial {
    const char* id;
    double e;
    bool summed;
  };
  const Trial trials[] = {{"V", 0.2, true},   {"V", 0.5, true},   {"I", 0.2, true},    {"III", 0.5, true},
                          {"IV", 0.5, true},  {"VIII", 0.5, true}, {"VII", 0.5, true}, {"VI", 0.95, false},
                          {"IV", 0.99, false}, {"II", 0.999, false}};
  for (const auto& [id, e_value, summed] : trials) {
    const Parameters p = case_parameters(id);
    Effects e;
    e.restitution = e_value;
    const SimulationResult r = run(p, e, case_step(id), 60);
    const std::string label = std::string("case ") + id + " e = " + std::to_string(e_value);
    ASSERT_TRUE(all_finite(r)) << label;
    EXPECT_TRUE(r.status == SimulationStatus::Completed || r.status == SimulationStatus::Rest)
        << label << ": returned " << describe(r) << " instead of completed or rest";
    int accumulations = 0, bounces = 0, series = 0, longest_series = 0;
    for (std::size_t i = 0; i < r.events.size(); ++i) {
      const auto& ev = r.events[i];
      bounces += ev.bounce;
      // The series: the bounces on one face since the last other event.
      if (ev.accumulation) longest_series = std::max(longest_series, series);
      series = ev.bounce && ev.kind == EventKind::Recontact ? series + 1 : ev.bounce ? 1 : 0;
      if (!ev.accumulation) continue;
      ++accumulations;
      EXPECT_EQ(ev.kind, EventKind::Recontact) << label;
      EXPECT_TRUE(ev.after.in_contact) << label;
      EXPECT_FALSE(ev.bounce) << label;
      ASSERT_GT(i, 0u);
      const auto& last_bounce = r.events[i - 1];
      EXPECT_TRUE(last_bounce.bounce) << label;
      EXPECT_EQ(last_bounce.after.face, ev.after.face) << label;
      const double tau_inf = ev.t - last_bounce.t;
      EXPECT_GE(tau_inf, 0.0) << label;
      EXPECT_LE(tau_inf, 1e-7 * numeric::servo_period(p) * (1 + 1e-12)) << label;
    }
    if (summed) {
      EXPECT_GT(accumulations, 0) << label << ": returned no summed series: " << describe(r);
    }
    // A converging series needs about log(1e-7)/log(e) bounces before it is summed.
    const double bound = std::log(1e-9) / std::log(e_value) + 5;
    EXPECT_LE(longest_series, bound) << label << ": returned a series of " << longest_series << " bounces";
    std::printf("bounces  %-4s e = %.3f: %-10s %5zu events, %4d bounces, %2d summed series (at most %2d bounces each)\n",
                id, e_value, numeric::to_string(r.status), r.events.size(), bounces, accumulations, longest_series);
  }
}

// ---------------------------------------------------------------- saturation

TEST(OdeintEffects, SaturatedDriveIsClippedAndSwitchesAtTheLimit) {
  struct Trial {
    const char* id;
    double L, T0;
  };
  const Trial trials[] = {{"V", 0.3, 0}, {"I", 0.5, 0}, {"III", 0.2, 0.05}, {"VIII", 0.1, 0}, {"II", 0.05, -0.01}};
  for (const Trial& tr : trials) {
    const Parameters p = case_parameters(tr.id);
    Effects e;
    e.saturation = tr.L;
    e.torque_offset = tr.T0;
    const double step = case_step(tr.id);
    const SimulationResult r = run(p, e, step, 30, 1e-3);
    const std::string label = std::string("case ") + tr.id + " " + e.describe();
    ASSERT_TRUE(all_finite(r)) << label;
    int switches = 0;
    double worst_event = 0, worst_drive = 0;
    for (const auto& ev : r.events) {
      if (ev.kind != EventKind::Saturation && ev.kind != EventKind::Desaturation) continue;
      ++switches;
      const double demand = p.K * (p.theta_R - ev.theta_o);
      const double miss = std::fabs(std::fabs(demand) - tr.L);
      worst_event = std::max(worst_event, miss);
      EXPECT_LE(miss, 1e-9) << label << ": " << numeric::to_string(ev.kind) << " at t = " << ev.t
                            << " returned K(θR − θo) = " << demand << " instead of ±" << tr.L;
      EXPECT_EQ(ev.after.drive_regime, ev.kind == EventKind::Saturation ? (demand > 0 ? 1 : -1) : 0) << label;
    }
    // The regime in force at every sample (from the start and the events) is that of the
    // demand, and the applied drive (J ω̇ + F ω + ... from the samples, in contact) is
    // sat(K(θR − θo)) + T0, within ±L + T0.
    int regime = numeric::effects_step_start(p, e, step).drive_regime;
    std::size_t next = 0;
    for (std::size_t i = 0; i < r.samples.size(); ++i) {
      const auto& s = r.samples[i];
      while (next < r.events.size() && r.events[next].t <= s.t) regime = r.events[next++].after.drive_regime;
      const double demand = p.K * (p.theta_R - s.theta_o);
      if (regime == 0) {
        EXPECT_LE(std::fabs(demand), tr.L + 1e-9) << label << " t = " << s.t;
      } else {
        EXPECT_GE(regime * demand, tr.L - 1e-9) << label << " t = " << s.t;
      }
      const bool near_event = next < r.events.size() && r.events[next].t - s.t < 3e-3;
      const bool after_event = next > 0 && s.t - r.events[next - 1].t < 3e-3;
      if (i == 0 || i + 1 == r.samples.size() || !s.in_contact || near_event || after_event) continue;
      const auto& a = r.samples[i - 1];
      const auto& b = r.samples[i + 1];
      if (!a.in_contact || !b.in_contact) continue;
      const double acceleration = (b.dtheta_o - a.dtheta_o) / (b.t - a.t);
      const double applied = (p.Jm + p.JL) * acceleration + (p.Fm + p.FL) * s.dtheta_o;
      const double expected = std::clamp(demand, -tr.L, tr.L) + tr.T0;
      worst_drive = std::max(worst_drive, std::fabs(applied - expected));
      EXPECT_NEAR(applied, expected, 1e-5) << label << " t = " << s.t;
      EXPECT_LE(std::fabs(applied - tr.T0), tr.L + 1e-5) << label << " t = " << s.t;
    }
    EXPECT_GT(switches, 0) << label;
    std::printf("saturate %-4s %-32s %2d switches, max |K(θR − θo)| − L at events %.1e, applied drive within %.1e\n",
                tr.id, e.describe().c_str(), switches, worst_event, worst_drive);
  }
}

// ---------------------------------------------------------------- compliance

TEST(OdeintEffects, MeshNeverPulls) {
  struct Trial {
    const char* id;
    double kc, cc, TL;
  };
  const Trial trials[] = {{"V", 400, 4, 0}, {"I", 100, 0, 0}, {"III", 1000, 20, 0.02}, {"VII", 50, 1, 0}, {"II", 2000, 5, 0.01}};
  for (const Trial& tr : trials) {
    const Parameters p = case_parameters(tr.id);
    Effects e;
    e.mesh_stiffness = tr.kc;
    e.mesh_damping = tr.cc;
    e.coulomb_load = tr.TL;
    const SimulationResult r = run(p, e, case_step(tr.id), 30, 1e-3);
    const std::string label = std::string("case ") + tr.id + " " + e.describe();
    ASSERT_TRUE(all_finite(r)) << label;
    auto force = [&](double theta_m, double dtheta_m, double theta_L, double dtheta_L, int side) {
      return tr.kc * (side * (theta_L - theta_m) - p.backlash / 2) + tr.cc * side * (dtheta_L - dtheta_m);
    };
    double min_force = INFINITY;
    int engaged = 0, releases = 0;
    for (const auto& s : r.samples) {
      if (!s.in_contact) continue;
      ++engaged;
      const int side = s.theta_L - s.theta_m > 0 ? 1 : -1;
      const double P = force(s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, side);
      min_force = std::min(min_force, P);
      EXPECT_GE(P, -1e-7) << label << ": the mesh force at t = " << s.t << " returned " << P << " instead of ≥ 0";
    }
    for (const auto& ev : r.events) {
      const auto& h = ev.after;
      const double P = force(h.theta_m, h.dtheta_m, h.theta_L, h.dtheta_L, h.face);
      if (h.in_contact) {
        EXPECT_GE(P, -1e-7) << label << ": " << numeric::to_string(ev.kind) << " at t = " << ev.t;
      }
      if (ev.kind == EventKind::Separation) {
        ++releases;
        EXPECT_NEAR(P, 0.0, 1e-7) << label << ": release at t = " << ev.t << " returned P = " << P << " instead of 0";
      }
    }
    EXPECT_GT(engaged, 0) << label;
    std::printf("mesh     %-4s %-48s %6d engaged samples, min force %+.1e, %d releases at P = 0\n", tr.id,
                e.describe().c_str(), engaged, min_force, releases);
  }
}

TEST(OdeintEffects, StiffHeavilyDampedMeshApproachesTheRigidInelasticModel) {
  const Parameters p = case_parameters("V");
  const double step = case_step("V"), t_end = 6;
  const SimulationResult rigid = run(p, Effects{}, step, t_end, 0.01);
  double previous = INFINITY;
  for (double kc : {1e2, 1e3, 1e4}) {
    Effects e;
    e.mesh_stiffness = kc;
    e.mesh_damping = 10 * std::sqrt(kc);  // damping ratio ζ = 10
    const SimulationResult mesh = run(p, e, step, t_end, 0.01);
    ASSERT_EQ(mesh.samples.size(), rigid.samples.size());
    double worst = 0;
    for (std::size_t i = 0; i < mesh.samples.size(); ++i)
      worst = std::max(worst, std::fabs(mesh.samples[i].theta_o - rigid.samples[i].theta_o));
    std::printf("mesh     kc = %.0e, ζ = 10: max |θo − θo(rigid)| over %g s = %.2e\n", kc, t_end, worst);
    EXPECT_LT(worst, previous) << "kc = " << kc;
    previous = worst;
  }
  EXPECT_LT(previous, 2e-3);
}

// ---------------------------------------------------------------- delay

// The dominant root of J s² + F s + K e^{−sτ} by Newton from the undelayed root.
std::complex<double> dominant_root(double J, double F, double K, double tau) {
  std::complex<double> s(-F / (2 * J), std::sqrt(K / J - F * F / (4 * J * J)));
  for (int i = 0; i < 100; ++i) {
    const std::complex<double> ex = std::exp(-s * tau);
    const std::complex<double> f = J * s * s + F * s + K * ex, df = 2 * J * s + F - K * tau * ex;
    const std::complex<double> ds = f / df;
    s -= ds;
    if (std::abs(ds) < 1e-15 * std::abs(s)) break;
  }
  return s;
}

// Rigid drive (backlash 0): θo − θR solves the linear DDE, dominated by one root pair.
TEST(OdeintEffects, DelayedRigidDriveFollowsTheDominantCharacteristicRoot) {
  for (double tau : {0.05, 0.2, 0.5}) {
    for (const char* id : {"V", "IV"}) {
      Parameters p = case_parameters(id);
      p.backlash = 0;
      Effects e;
      e.delay = tau;
      const double J = p.Jm + p.JL, F = p.Fm + p.FL;
      const std::complex<double> root = dominant_root(J, F, p.K, tau);
      const SimulationResult r = run(p, e, 0.5, 40, 2e-3);
      ASSERT_TRUE(all_finite(r)) << describe(r);
      ASSERT_EQ(r.status, SimulationStatus::Completed) << describe(r);
      // Zero crossings of θo − θR (cubic Hermite between samples) and |θ̇o| there: for
      // A e^{at}cos(ωt + φ) they are π/ω apart and |θ̇o| shrinks by e^{aπ/ω} each.
      std::vector<double> zeros, speeds;
      for (std::size_t i = 1; i < r.samples.size(); ++i) {
        const auto& a = r.samples[i - 1];
        const auto& b = r.samples[i];
        const double xa = a.theta_o - p.theta_R, xb = b.theta_o - p.theta_R;
        if (a.t < 8 || (xa < 0) == (xb < 0) || xa == 0) continue;
        const double h = b.t - a.t;
        auto hermite = [&](double u, double& value, double& slope) {
          const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u,
                       h11 = u * u * u - u * u;
          value = h00 * xa + h10 * h * a.dtheta_o + h01 * xb + h11 * h * b.dtheta_o;
          const double d00 = 6 * u * u - 6 * u, d10 = 3 * u * u - 4 * u + 1, d01 = -6 * u * u + 6 * u, d11 = 3 * u * u - 2 * u;
          slope = (d00 * xa + d10 * h * a.dtheta_o + d01 * xb + d11 * h * b.dtheta_o) / h;
        };
        double u = xa / (xa - xb), value, slope;
        for (int k = 0; k < 20; ++k) {
          hermite(u, value, slope);
          u -= value / (slope * h);
        }
        hermite(u, value, slope);
        zeros.push_back(a.t + u * h);
        speeds.push_back(std::fabs(slope));
      }
      ASSERT_GE(zeros.size(), 6u) << "tau = " << tau;
      const std::size_t n = zeros.size() - 1;
      const double half_period = (zeros.back() - zeros.front()) / n;
      const double omega = M_PI / half_period;
      const double decay = std::log(speeds.back() / speeds.front()) / (zeros.back() - zeros.front());
      std::printf("delay    %-3s τ = %.2f: root %+.9f %+.9fi, simulated %+.9f %+.9fi (%zu zero crossings)\n", id, tau,
                  root.real(), root.imag(), decay, omega, zeros.size());
      EXPECT_NEAR(omega, root.imag(), 2e-5 * root.imag())
          << "τ = " << tau << ": the frequency returned " << omega << " instead of " << root.imag();
      EXPECT_NEAR(decay, root.real(), 2e-5 * std::abs(root))
          << "τ = " << tau << ": the decay rate returned " << decay << " instead of " << root.real();
      // A rigid drive never opens a gap: every separation is followed at once by the impact
      // on the other face, with no change of velocity.
      for (std::size_t i = 0; i + 1 < r.events.size(); ++i)
        if (r.events[i].kind == EventKind::Separation) {
          EXPECT_EQ(r.events[i + 1].kind, EventKind::Recombination);
          EXPECT_EQ(r.events[i + 1].t, r.events[i].t);
          EXPECT_NEAR(r.events[i + 1].dtheta_o, r.events[i].dtheta_o, 1e-12);
        }
    }
  }
}

struct Timing {
  double ms;
  SimulationResult result;
};
Timing timed(const Parameters& p, const Effects& e, double step, double t_end, double tolerance) {
  numeric::OdeintSimulationOptions oo;
  oo.tolerance = tolerance;
  SimulationOptions o;
  o.t_end = t_end;
  Timing best{INFINITY, {}};
  for (int k = 0; k < 3; ++k) {
    const auto start = std::chrono::steady_clock::now();
    SimulationResult r = numeric::simulate_effects_step_with_odeint(p, e, step, o, oo);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (ms < best.ms) best = {ms, std::move(r)};
  }
  return best;
}

double max_event_time_difference(const SimulationResult& a, const SimulationResult& b, const std::string& label) {
  EXPECT_EQ(a.events.size(), b.events.size()) << label << "\n  " << describe(a) << "\n  " << describe(b);
  double worst = 0;
  for (std::size_t i = 0; i < std::min(a.events.size(), b.events.size()); ++i) {
    EXPECT_EQ(a.events[i].kind, b.events[i].kind) << label << ": event " << i;
    if (a.events[i].kind != b.events[i].kind) break;
    if (a.events[i].kind == EventKind::Rest) continue;
    worst = std::max(worst, std::fabs(a.events[i].t - b.events[i].t));
  }
  return worst;
}

// θo(t) of a run stopped at t (the delayed drive at t + τ reads it).
double measured_at(const Parameters& p, const Effects& e, double step, double t) {
  if (t <= 0) return numeric::measured(p, numeric::effects_step_start(p, e, step));
  SimulationOptions o;
  o.t_end = t;
  return numeric::measured(p, numeric::simulate_effects_step_with_odeint(p, e, step, o).final_state);
}

// With a delay every guard reads the delayed drive K(θR − θo(t − τ)): a stuck motor breaks
// away where its magnitude reaches Tm, the drive switches regime where it reaches ±L, and
// the stuck bodies rest only once θo has been constant for τ (no breakaway after).
TEST(OdeintEffects, DelayedGuardsReadTheDelayedDrive) {
  struct Trial {
    const char* id;
    Effects e;
  };
  auto with = [](std::function<void(Effects&)> f) {
    Effects e;
    f(e);
    return e;
  };
  const Trial trials[] = {
      {"I", with([](Effects& e) { e.delay = 1.0; e.coulomb_motor = e.coulomb_load = 0.05; })},
      {"V", with([](Effects& e) { e.delay = 0.6; e.coulomb_motor = e.coulomb_load = 0.1; })},
      {"V", with([](Effects& e) { e.delay = 0.3; e.saturation = 0.4; })},
      {"III", with([](Effects& e) { e.delay = 0.2; e.saturation = 0.25; e.torque_offset = 0.02; })},
  };
  for (const Trial& tr : trials) {
    const Parameters p = case_parameters(tr.id);
    const double step = case_step(tr.id);
    const std::string label = std::string("case ") + tr.id + " " + tr.e.describe();
    SimulationOptions o;
    o.t_end = 40;
    const SimulationResult r = numeric::simulate_effects_step_with_odeint(p, tr.e, step, o);
    ASSERT_TRUE(all_finite(r)) << label;
    int checked = 0;
    double worst = 0;
    for (const auto& ev : r.events) {
      const bool breakaway = ev.kind == EventKind::Slip && ev.body == Body::Motor;
      const bool regime = ev.kind == EventKind::Saturation || ev.kind == EventKind::Desaturation;
      if (!breakaway && !regime) continue;
      const double demand = p.K * (p.theta_R - measured_at(p, tr.e, step, ev.t - tr.e.delay));
      const double level = breakaway ? std::fabs(demand + tr.e.torque_offset) - tr.e.coulomb_motor
                                     : std::fabs(demand) - tr.e.saturation;
      worst = std::max(worst, std::fabs(level));
      EXPECT_NEAR(level, 0.0, 1e-8) << label << ": " << numeric::to_string(ev.kind) << " at t = " << ev.t
                                    << " returned a delayed drive off its limit by " << level;
      ++checked;
    }
    EXPECT_GT(checked, 0) << label << ": " << describe(r);
    if (r.status == SimulationStatus::Rest) {
      const double d = p.K * (p.theta_R - r.theta_o_final) + tr.e.torque_offset;
      EXPECT_LE(std::fabs(d), tr.e.coulomb_motor + tr.e.coulomb_load + 1e-12) << label;
      // The rest is declared at the last stick; nothing moved in the τ after it.
      const double rest_t = r.events.back().t;
      EXPECT_EQ(measured_at(p, tr.e, step, rest_t + tr.e.delay), r.theta_o_final) << label;
    }
    std::printf("delay    %-4s %-46s %-9s %2d guards on the delayed drive, max miss %.1e\n", tr.id, tr.e.describe().c_str(),
                numeric::to_string(r.status), checked, worst);
  }
}

// As τ → 0 the delayed simulation tends to the undelayed one, to first order in τ.
TEST(OdeintEffects, VanishingDelayTendsToTheUndelayedModel) {
  const Parameters p = case_parameters("V");
  const double step = case_step("V");
  Effects base;
  base.coulomb_load = 0.01;
  const SimulationResult undelayed = run(p, base, step, 12);
  std::vector<double> differences;
  for (double tau : {1e-2, 1e-3}) {
    Effects e = base;
    e.delay = tau;
    const SimulationResult delayed = run(p, e, step, 12);
    const double dt = max_event_time_difference(delayed, undelayed, "tau " + std::to_string(tau));
    differences.push_back(dt);
    std::printf("delay    τ = %.0e: %zu events, max |t − t(τ = 0)| = %.3e\n", tau, delayed.events.size(), dt);
  }
  ASSERT_EQ(differences.size(), 2u);
  const double ratio = differences[0] / differences[1];
  EXPECT_GT(ratio, 5.0) << "the event times converge with order log10(" << ratio << ") instead of 1";
  EXPECT_LT(ratio, 20.0) << "the event times converge with order log10(" << ratio << ") instead of 1";
}

// Accuracy (against a run at 1e-13) and time of a 60 s case V record, the delay 0.05 and
// each other effect, at tolerance 1e-10.
TEST(OdeintEffects, SixtySecondRecordsAreAccurateAndFast) {
  const Parameters p = case_parameters("V");
  const double step = case_step("V");
  std::vector<std::pair<std::string, Effects>> trials;
  auto add = [&](const char* name, std::function<void(Effects&)> f) {
    Effects e;
    f(e);
    trials.emplace_back(name, e);
  };
  add("delay 0.05", [](Effects& e) { e.delay = 0.05; });
  add("delay 0.05 + Coulomb", [](Effects& e) { e.delay = 0.05; e.coulomb_load = 0.01; e.coulomb_motor = 0.01; });
  add("delay 0.3 + saturation", [](Effects& e) { e.delay = 0.3; e.saturation = 0.4; });
  add("Coulomb", [](Effects& e) { e.coulomb_load = 0.01; e.coulomb_motor = 0.01; });
  add("restitution 0.5", [](Effects& e) { e.restitution = 0.5; });
  add("saturation 0.3", [](Effects& e) { e.saturation = 0.3; });
  add("compliance 400/4", [](Effects& e) { e.mesh_stiffness = 400; e.mesh_damping = 4; });
  add("torque offset 0.05", [](Effects& e) { e.torque_offset = 0.05; });
  add("all but compliance", [](Effects& e) {
    e.coulomb_load = 0.005; e.restitution = 0.3; e.saturation = 0.5; e.delay = 0.05; e.torque_offset = 0.02; });
  for (const auto& [name, e] : trials) {
    const Timing fast = timed(p, e, step, 60, 1e-10);
    const Timing exact = timed(p, e, step, 60, 1e-13);
    const double dt = max_event_time_difference(fast.result, exact.result, name);
    std::printf("record   case V 60 s, %-22s %4zu events, %-9s %7.2f ms at 1e-10 (%7.2f ms at 1e-13), max |Δt| %.1e\n",
                name.c_str(), fast.result.events.size(), numeric::to_string(fast.result.status), fast.ms, exact.ms, dt);
    EXPECT_LE(dt, 1e-7) << name << ": event times at tolerance 1e-10 returned a difference " << dt
                        << " instead of ≤ 1e-7 from 1e-13";
    EXPECT_LT(fast.ms, 2000.0) << name;  // generous: the test also runs under ASan
  }
}

// ---------------------------------------------------------------- statuses

TEST(OdeintEffects, EveryStatusPathReturns) {
  const Parameters p = case_parameters("V");
  const double step = case_step("V");
  struct Trial {
    std::string name;
    Parameters p;
    Effects e;
    SimulationOptions o;
    std::vector<SimulationStatus> allowed;
  };
  std::vector<Trial> trials;
  auto add = [&](std::string name, std::function<void(Parameters&, Effects&, SimulationOptions&)> f,
                 std::vector<SimulationStatus> allowed) {
    Trial t{std::move(name), p, {}, {}, std::move(allowed)};
    t.o.t_end = 20;
    f(t.p, t.e, t.o);
    trials.push_back(std::move(t));
  };
  using S = SimulationStatus;
  add("e = 0.999", [](Parameters&, Effects& e, SimulationOptions&) { e.restitution = 0.999; }, {S::Completed, S::Rest});
  add("tiny Coulomb", [](Parameters&, Effects& e, SimulationOptions&) { e.coulomb_motor = e.coulomb_load = 1e-9; },
      {S::Completed, S::Rest});
  add("huge stiffness", [](Parameters&, Effects& e, SimulationOptions& o) { e.mesh_stiffness = 1e7; e.mesh_damping = 1; o.t_end = 2.2; },
      {S::Completed});
  add("undamped mesh", [](Parameters&, Effects& e, SimulationOptions&) { e.mesh_stiffness = 50; }, {S::Completed});
  add("event limit", [](Parameters&, Effects& e, SimulationOptions& o) { e.restitution = 0.9; o.max_events = 7; },
      {S::EventLimit});
  add("chattering (zeno rule)", [](Parameters&, Effects&, SimulationOptions& o) { o.zeno_impacts = 2; o.zeno_window = 10; },
      {S::Chattering});
  add("stop after separations", [](Parameters&, Effects& e, SimulationOptions& o) { e.delay = 0.1; o.stop_after_separations = 2; },
      {S::Completed});
  add("rest (Coulomb)", [](Parameters&, Effects& e, SimulationOptions&) { e.coulomb_load = 0.2; e.coulomb_motor = 0.2; },
      {S::Rest});
  add("rest with delay", [](Parameters&, Effects& e, SimulationOptions&) { e.coulomb_load = 0.2; e.coulomb_motor = 0.2; e.delay = 0.3; },
      {S::Rest});
  add("non-finite parameters", [](Parameters& q, Effects&, SimulationOptions&) { q.K = NAN; }, {S::NonFinite});
  add("infinite offset", [](Parameters&, Effects& e, SimulationOptions&) { e.torque_offset = INFINITY; }, {S::NonFinite});
  // A delay that destabilises the loop: the motion grows without bound (to ~1e7 rad by
  // t = 75; beyond ~1e11 the gap's sign is rounding and the impacts chatter).
  add("unstable delay", [](Parameters&, Effects& e, SimulationOptions& o) { e.delay = 3; o.t_end = 75; },
      {S::Completed, S::NonFinite, S::Chattering});
  add("everything", [](Parameters&, Effects& e, SimulationOptions&) {
        e.coulomb_load = 0.01; e.coulomb_motor = 0.02; e.restitution = 0.6; e.saturation = 0.3; e.delay = 0.2; e.torque_offset = 0.03; },
      {S::Completed, S::Rest});
  add("everything, compliant", [](Parameters&, Effects& e, SimulationOptions&) {
        e.coulomb_load = 0.01; e.coulomb_motor = 0.02; e.mesh_stiffness = 300; e.mesh_damping = 1; e.saturation = 0.3;
        e.delay = 0.2; e.torque_offset = 0.03; },
      {S::Completed, S::Rest});
  add("backlash 0, Coulomb and restitution", [](Parameters& q, Effects& e, SimulationOptions&) {
        q.backlash = 0; e.coulomb_load = 0.01; e.restitution = 0.5; },
      {S::Completed, S::Rest});
  for (const Trial& t : trials) {
    const auto start = std::chrono::steady_clock::now();
    const SimulationResult r = numeric::simulate_effects_step_with_odeint(t.p, t.e, step, t.o);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const bool allowed = std::find(t.allowed.begin(), t.allowed.end(), r.status) != t.allowed.end();
    EXPECT_TRUE(allowed) << t.name << ": returned " << describe(r) << " instead of the expected status";
    if (r.status != SimulationStatus::NonFinite) {
      EXPECT_TRUE(all_finite(r)) << t.name << ": a NaN in the result";
    }
    EXPECT_LE(static_cast<long>(r.events.size()), t.o.max_events) << t.name;
    std::printf("status   %-36s %-11s %6zu events, t_final %7.3f, %8.2f ms\n", t.name.c_str(), numeric::to_string(r.status),
                r.events.size(), r.t_final, ms);
  }
}

// Effects on random parameter sets: no NaN, a status, stuck bodies at rest, events
// ordered in time, the after-states consistent with the event kinds.
TEST(OdeintEffects, RandomParametersWithEveryEffectStayConsistent) {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> u(0, 1);
  int runs = 0;
  std::size_t events = 0;
  for (const RandomSet& s : random_sets(16, 9)) {
    Effects e;
    if (u(rng) < 0.6) e.coulomb_motor = 0.05 * u(rng);
    if (u(rng) < 0.6) e.coulomb_load = 0.05 * u(rng);
    if (u(rng) < 0.5) e.saturation = 0.1 + u(rng);
    if (u(rng) < 0.4) {
      e.mesh_stiffness = 50 + 500 * u(rng);
      e.mesh_damping = 5 * u(rng);
    } else if (u(rng) < 0.6) {
      e.restitution = 0.9 * u(rng);
    }
    if (u(rng) < 0.4) e.delay = 0.02 + 0.2 * u(rng);
    if (u(rng) < 0.4) e.torque_offset = 0.1 * (u(rng) - 0.5);
    SimulationOptions o;
    o.t_end = 30;
    o.sample_interval = 0.05;
    o.track_extremes = true;
    const SimulationResult r = numeric::simulate_effects_step_with_odeint(s.p, e, s.step, o);
    const std::string label = e.describe();
    ++runs;
    events += r.events.size();
    ASSERT_TRUE(all_finite(r)) << label;
    EXPECT_TRUE(r.status == SimulationStatus::Completed || r.status == SimulationStatus::Rest) << label << ": " << describe(r);
    double previous = 0;
    for (const auto& ev : r.events) {
      EXPECT_GE(ev.t, previous) << label << ": events out of order";
      previous = ev.t;
      EXPECT_TRUE(!ev.after.motor_stuck || ev.after.dtheta_m == 0) << label;
      EXPECT_TRUE(!ev.after.load_stuck || ev.after.dtheta_L == 0) << label;
      const bool stick_or_slip = ev.kind == EventKind::Stick || ev.kind == EventKind::Slip;
      EXPECT_TRUE(!stick_or_slip || ev.body != Body::None) << label;
      const bool motor = ev.body == Body::Motor || ev.body == Body::Both, load = ev.body == Body::Load || ev.body == Body::Both;
      EXPECT_TRUE(ev.kind != EventKind::Stick || !motor || ev.after.motor_stuck) << label;
      EXPECT_TRUE(ev.kind != EventKind::Stick || !load || ev.after.load_stuck) << label;
      if (!e.compliant() && ev.after.in_contact) {
        EXPECT_NEAR(ev.after.theta_L - ev.after.theta_m, ev.after.face * s.p.backlash / 2, 1e-12) << label;
        EXPECT_EQ(ev.after.dtheta_L, ev.after.dtheta_m) << label;
      }
      EXPECT_NEAR(ev.theta_o, measured_of(s.p, ev.after), 0) << label;
    }
    // Extremes bracket the samples.
    for (const auto& sample : r.samples) {
      EXPECT_LE(sample.theta_o, r.extremes.theta_o_max + 1e-9) << label;
      EXPECT_GE(sample.theta_o, r.extremes.theta_o_min - 1e-9) << label;
    }
    if (!e.compliant()) {
      for (const auto& sample : r.samples)
        EXPECT_LE(std::fabs(sample.theta_L - sample.theta_m), s.p.backlash / 2 + 1e-9) << label << " t = " << sample.t;
    }
  }
  std::printf("random   %d runs with random effects: %zu events, all finite and consistent\n", runs, events);
}

}  // namespace
