// Issue 20, slider drags at ≥ 30 fps: the dividing lines of a nearly frictionless load.  Dragging
// FL from 0 reaches FL = 1e-5, where the unit gap profile (numeric/hybrid/dividing_lines.cpp)
// searched the gap's return and its slope's zeros over the horizon 40·JL/FL (3.2·10⁶ s on case
// IV) in intervals of the free mode's growth bound: ~2·10⁶ intervals, its budget (main).  Now its
// searches stop where the gap and its slope are certified to keep one sign up to the horizon, on
// the free mode's structure (numeric/hybrid/quiet_tail.hpp):
//   item20_case_IV_dividing_lines_cost_set_by_the_motor  the closed-form evaluations of case IV's
//        dividing lines (both faces) at FL = 1e-5 and 1e-6: at most those over the motor's own
//        horizon (40 of the slowest time scales without the load's friction: 400 s) plus, per
//        doubling of the horizon beyond it, one window of the certified search (main: ~4·10⁶);
//   item20_profiles_bit_for_bit_with_the_whole_searches  on random free modes (either shaft
//        measured, FL from 1e-3 to 1), the profile — knots, values, end, return — bit for bit the
//        one of the whole searches, and the searches' stop taken on most of those with FL ≤ 1e-2;
//   item20_quiet_tail_bound_holds  the bound on |f''''| the certificate rests on holds at sampled
//        points of random flights (beyond the samples' own rounding).
#include "counting_evaluator.hpp"
#include "thesis_cases_two_to_four.hpp"

#include "backlash/numeric/dividing_lines.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "backlash/numeric/validation.hpp"
#include "hybrid/linear_flight.hpp"
#include "hybrid/quiet_tail.hpp"
#include "hybrid/unit_gap_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using namespace backlash::numeric;

// The thesis's cases II–IV with the load's friction FL (θR = 0: the error coordinates the facade runs them in).
Parameters thesis_case(int number, double FL) { return backlash::testing::thesis_case_two_to_four(number, FL, 0); }

// The explorer's grid: the default one and its negatives (both faces).
std::vector<double> both_faces() {
  std::vector<double> v = default_dividing_line_grid();
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) v.push_back(-v[i]);
  return v;
}

struct Counted {
  std::shared_ptr<const backlash::testing::CountingEvaluator> counter;
  ValidationResult validated;
};

Counted counted(const Parameters& p) {
  auto counter = std::make_shared<const backlash::testing::CountingEvaluator>(parametric_evaluator(p));
  ValidationResult validated = validate(counter);
  return {counter, std::move(validated)};
}

// Closed-form evaluations of the dividing lines of both faces over `horizon` (0: the default).
long trace_cost(const Counted& c, double horizon, DividingLines* lines = nullptr) {
  TraceOptions options;
  options.horizon = horizon;
  const long before = c.counter->evaluations;
  const DividingLines traced = trace_dividing_lines(c.validated.evaluator(), both_faces(), options);
  if (lines) *lines = traced;
  return c.counter->evaluations - before;
}

// Closed-form evaluations of the unit gap profile over `horizon`.
long profile_cost(const Counted& c, double horizon, bool quiet_tail = true) {
  const long before = c.counter->evaluations;
  detail::unit_gap_profile(c.validated.evaluator(), horizon, quiet_tail);
  return c.counter->evaluations - before;
}

TEST(DividingLinesSmallFriction, item20_case_IV_dividing_lines_cost_set_by_the_motor) {
  for (double FL : {1e-5, 1e-6}) {
    const Parameters p = thesis_case(4, FL);
    const Counted c = counted(p);
    ASSERT_TRUE(c.validated.passed());
    Parameters frictionless = p;
    frictionless.FL = 0;
    const double motor_horizon = 40 * slowest_time_scale(frictionless), horizon = 40 * slowest_time_scale(p);
    DividingLines lines;
    const long cost = trace_cost(c, 0, &lines), motor_cost = trace_cost(c, motor_horizon);
    const long profile = profile_cost(c, horizon), motor_profile = profile_cost(c, motor_horizon);
    const double doublings = std::ceil(std::log2(horizon / motor_horizon));
    std::printf("case IV, FL = %g: horizon %g s: %ld evaluations (the profile %ld); the motor's horizon %g s: %ld (%ld)\n",
                FL, horizon, cost, profile, motor_horizon, motor_cost, motor_profile);
    EXPECT_TRUE(lines.work_limit.empty()) << lines.work_limit;
    // The profile: beyond the motor's horizon only the certificate's windows, each decided by an
    // interval or two (two samples at most).
    EXPECT_LE(profile, motor_profile + 2 * doublings) << "FL = " << FL;
    // The lines: the profile and each point's root in its bracket, which ends at the horizon (a
    // few more iterations of TOMS 748 per point for the wider bracket, as before).
    EXPECT_LE(cost, 2 * motor_cost) << "FL = " << FL;
  }
}

// A random free mode: either shaft measured, the thesis's scales, FL log-uniform in [1e-3, 1].
Parameters random_case(std::mt19937_64& random) {
  const auto log_uniform = [&random](double lo, double hi) {
    return lo * std::pow(hi / lo, std::uniform_real_distribution<double>(0, 1)(random));
  };
  Parameters p;
  p.measured_at = random() % 2 ? model::MeasuredAt::Motor : model::MeasuredAt::Load;
  p.Jm = log_uniform(0.1, 2), p.JL = log_uniform(0.1, 2), p.Fm = log_uniform(0.02, 1), p.K = log_uniform(0.3, 3);
  p.FL = log_uniform(1e-3, 1), p.backlash = 0.3, p.theta_R = 0;
  return p;
}

TEST(DividingLinesSmallFriction, item20_profiles_bit_for_bit_with_the_whole_searches) {
  std::mt19937_64 random(2020);
  int compared = 0, stopped = 0, light = 0, turns = 0;
  for (int i = 0; i < 60 && compared < 40; ++i) {
    const Parameters p = random_case(random);
    const Counted c = counted(p);
    if (!c.validated.passed()) continue;
    const double horizon = 40 * slowest_time_scale(p);
    const long before = c.counter->evaluations;
    const detail::UnitGapProfile quiet = detail::unit_gap_profile(c.validated.evaluator(), horizon);
    const long quiet_cost = c.counter->evaluations - before;
    const detail::UnitGapProfile whole = detail::unit_gap_profile(c.validated.evaluator(), horizon, false);
    const long whole_cost = c.counter->evaluations - before - quiet_cost;
    const std::string label = "set " + std::to_string(i) + " (FL = " + std::to_string(p.FL) + ")";
    EXPECT_EQ(quiet.valid, whole.valid) << label;
    EXPECT_EQ(quiet.end, whole.end) << label;
    EXPECT_EQ(quiet.returns, whole.returns) << label;
    EXPECT_EQ(quiet.complete, whole.complete) << label;
    EXPECT_EQ(quiet.knots, whole.knots) << label;
    EXPECT_EQ(quiet.values, whole.values) << label;
    ++compared;
    turns += whole.knots.size() > 3;
    if (p.FL <= 1e-2) {
      ++light;
      stopped += 4 * quiet_cost < whole_cost;
    }
  }
  std::printf("%d profiles compared (%d with turns of the gap); FL <= 1e-2: %d, the searches stopped early on %d\n",
              compared, turns, light, stopped);
  EXPECT_GE(compared, 30);
  EXPECT_GE(turns, 5);  // profiles with turns are exercised
  EXPECT_GE(2 * stopped, light);  // the stop is taken on most light loads
}

// The bound on sup |f| over [a, b] ⊂ [T, ∞) from x(T) alone, against f = e·A²(A x + c)
// (e = (0, −1, 0, 1)) at sampled points of random flights (LinearFlight from random states, the
// separation line's unit flight among them), beyond those samples' own rounding (1e-13 of their
// terms' size: a few hundred ulps).
TEST(DividingLinesSmallFriction, item20_quiet_tail_bound_holds) {
  std::mt19937_64 random(2021);
  std::uniform_real_distribution<double> unit(0, 1), state(-2, 2);
  long checked = 0, resolved = 0;
  for (int i = 0; i < 200; ++i) {
    const Parameters p = random_case(random);
    const LinearSegment free = free_mode_segment(p);
    SmallVector x0(4);
    if (i % 4 == 0) x0 << 0, 1, 0, 1; else x0 << state(random), state(random), state(random), state(random);
    const LinearFlight flight(free, x0);
    const double T = 50 * unit(random);
    const auto bound = detail::gap_slope_third_derivative_bound(free, flight.state(T), T);
    ASSERT_TRUE(bound) << "set " << i;
    SmallRow e = SmallRow::Zero(4);
    e(1) = -1, e(3) = 1;
    const SmallRow eA2 = e * free.A * free.A;
    const SmallRow size_row = e.cwiseAbs() * free.A.cwiseAbs() * free.A.cwiseAbs();
    for (int j = 0; j < 5; ++j) {
      const double a = T + std::pow(10.0, 4 * unit(random) - 1) * unit(random);
      const double b = a + std::pow(10.0, 4 * unit(random) - 2);
      const double M = bound(a, b);
      for (int k = 0; k <= 20; ++k) {
        const double s = a + (b - a) * k / 20;
        const SmallVector x = flight.state(s);
        const double fourth = eA2.dot(free.A * x + free.c);
        const double rounding = 1e-13 * size_row.dot(free.A.cwiseAbs() * x.cwiseAbs() + free.c.cwiseAbs());
        EXPECT_LE(std::fabs(fourth), M + rounding) << "set " << i << ", s = " << s << " in [" << a << ", " << b << "], T = " << T;
        ++checked;
        resolved += rounding < 0.1 * M;
      }
    }
  }
  std::printf("%ld points checked, %ld where the bound is ten times the samples' rounding\n", checked, resolved);
  EXPECT_GE(2 * resolved, checked);
}

}  // namespace
