// check_: properties of the hybrid model away from the thesis's eight cases —
// any reference θR, steps of either sign, every pole structure the parametric
// evaluators cover, and the sweeps of figures 31 and 32.
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"
#include "backlash/numeric/validated_family.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using namespace backlash::numeric;

Parameters load_measured(double Jm, double Fm, double JL, double FL) {
  Parameters p;
  p.Jm = Jm; p.Fm = Fm; p.JL = JL; p.FL = FL;
  p.K = 1; p.theta_R = 1; p.backlash = 0.3;
  p.measured_at = backlash::model::MeasuredAt::Load;
  return p;
}

ValidatedEvaluator validated(const Parameters& p) {
  ValidatedParametricFamily family;
  auto e = family.at(p);
  EXPECT_TRUE(e.has_value());
  return *e;
}

TEST(SweepFigures31And32, ThesisCasesAreSweepPoints) {
  // Figure 31 at FL/F = .25, .75 and figure 32 at JL/Jm = 1 are cases VI, V (JL = Jm) and VIII, VII (JL = 4 Jm).
  SweepOptions options;
  const auto rows31 = run_sweep(figure31_points(5), options);
  ASSERT_EQ(rows31.size(), 10u);
  const double case_VI = find_limit_cycle(validated(load_measured(0.5, 0.3, 0.5, 0.1))).peak_to_peak;
  const double case_V = find_limit_cycle(validated(load_measured(0.5, 0.1, 0.5, 0.3))).peak_to_peak;
  EXPECT_NEAR(rows31[1].cycle.peak_to_peak, case_VI, 1e-9) << "fig. 31 at FL/F = .25 returned " << rows31[1].cycle.peak_to_peak;
  EXPECT_NEAR(rows31[3].cycle.peak_to_peak, case_V, 1e-9);
  for (const SweepRow& r : rows31) EXPECT_EQ(r.status, SweepStatus::LimitCycle) << r.point.series << " x=" << r.point.x;
}

TEST(SweepFigure31, MagnitudeIsContinuousAcrossTheEqualRatesBranch) {
  // FL/F = .5 with JL = Jm is Fm/Jm = FL/JL (cot φ = 0): the cycle must sit between its neighbours.
  const auto rows = run_sweep(figure31_points(21), SweepOptions{});
  for (size_t i = 1; i + 1 < 21; ++i) {
    ASSERT_EQ(rows[i].status, SweepStatus::LimitCycle) << "x = " << rows[i].point.x;
    const double lo = std::min(rows[i - 1].cycle.peak_to_peak, rows[i + 1].cycle.peak_to_peak);
    const double hi = std::max(rows[i - 1].cycle.peak_to_peak, rows[i + 1].cycle.peak_to_peak);
    EXPECT_GE(rows[i].cycle.peak_to_peak, lo - 1e-3) << "x = " << rows[i].point.x;
    EXPECT_LE(rows[i].cycle.peak_to_peak, hi + 1e-3) << "x = " << rows[i].point.x;
  }
}

TEST(LimitCycleGenerality, ReferenceShiftMovesTheCycleRigidly) {
  Parameters p = load_measured(0.5, 0.1, 0.5, 0.3);
  const LimitCycle a = find_limit_cycle(validated(p));
  p.theta_R = -2.5;
  const LimitCycle b = find_limit_cycle(validated(p));
  ASSERT_EQ(b.status, CycleStatus::LimitCycle);
  EXPECT_NEAR(a.peak_to_peak, b.peak_to_peak, 1e-9);
  EXPECT_NEAR(a.theta_o_max - 1, b.theta_o_max + 2.5, 1e-9);
  EXPECT_NEAR(a.period, b.period, 1e-9);
}

TEST(LimitCycleGenerality, EveryLoadMeasuredPoleStructureHasAStableCycle) {
  const Parameters structures[] = {load_measured(0.5, 0.1, 0.5, 0.3),   // generic
                                   load_measured(0.5, 0.2, 0.5, 0.0),   // FL = 0
                                   load_measured(0.5, 0.0, 0.5, 0.3),   // Fm = 0
                                   load_measured(0.5, 0.2, 0.5, 0.2)};  // Fm/Jm = FL/JL
  for (const Parameters& p : structures) {
    const LimitCycle c = find_limit_cycle(validated(p));
    EXPECT_EQ(c.status, CycleStatus::LimitCycle) << "Fm=" << p.Fm << " FL=" << p.FL << ": " << c.reason;
    EXPECT_TRUE(c.stable) << "multiplier " << c.multiplier;
  }
}

TEST(HybridSimulationGenerality, NegativeStepMirrorsPositiveStep) {
  const ValidatedEvaluator e = validated(load_measured(0.5, 0.1, 0.5, 0.3));
  SimulationOptions o;
  o.t_end = 30;
  const SimulationResult up = simulate_step(e, 0.62, o), down = simulate_step(e, -0.62, o);
  ASSERT_EQ(up.events.size(), down.events.size());
  for (size_t i = 0; i < up.events.size(); ++i) {
    EXPECT_NEAR(up.events[i].t, down.events[i].t, 1e-9);
    EXPECT_EQ(up.events[i].kind, down.events[i].kind);
    EXPECT_NEAR(up.events[i].theta_o - 1, -(down.events[i].theta_o - 1), 1e-9);
  }
}

TEST(HybridSimulationGenerality, MotorMeasuredCasesSettle) {
  Parameters p = load_measured(0.6, 0.48, 0.4, 0.32);
  p.measured_at = backlash::model::MeasuredAt::Motor;
  SimulationOptions o;
  o.t_end = 200;
  const SimulationResult r = simulate_step(validated(p), 1.0, o);
  EXPECT_EQ(r.status, SimulationStatus::Rest) << "returned " << to_string(r.status) << " instead of rest";
  EXPECT_NEAR(r.theta_o_final, 1.0, 1e-8);
  EXPECT_EQ(find_limit_cycle(validated(p)).status, CycleStatus::None);
}

}  // namespace

namespace {

TEST(HybridSimulationGenerality, EventTimesDoNotDependOnTheReference) {
  // Shift invariance: θR = 1000 must give the events of θR = 1 (the separation witness Tc is
  // evaluated from the deviation θo − θR, never by cancelling two large numbers).
  Parameters p = load_measured(0.5, 0.1, 0.5, 0.3);
  const ValidatedEvaluator near = validated(p);
  p.theta_R = 1000;
  const ValidatedEvaluator far = validated(p);
  SimulationOptions o;
  o.t_end = 60;
  const SimulationResult a = simulate_step(near, 0.62, o), b = simulate_step(far, 0.62, o);
  ASSERT_EQ(a.events.size(), b.events.size());
  double worst = 0;
  for (size_t i = 0; i < a.events.size(); ++i) worst = std::max(worst, std::fabs(a.events[i].t - b.events[i].t));
  EXPECT_LT(worst, 1e-9) << "event times moved by " << worst << " when theta_R went from 1 to 1000";
}

}  // namespace

namespace {

TEST(SweepFigure32, SeriesNamesAreCsvSafe) {
  for (const SweepPoint& p : figure32_points(2)) EXPECT_EQ(p.series.find(','), std::string::npos) << p.series;
  for (const SweepPoint& p : figure31_points(2)) EXPECT_EQ(p.series.find(','), std::string::npos) << p.series;
}

}  // namespace
