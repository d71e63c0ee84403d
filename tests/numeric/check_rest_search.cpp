// Issue 19, speed at the limit: the rest search's points after a certified quiet state are not
// evaluated (numeric/hybrid/rest_search.hpp, FreeFlightRestBound; docs/design.md "The event
// loop").  The bisection's every decision, and so the Rest event's time, must stay what the search
// that judges all 33 points of every level gives — kept here as the reference, verbatim.
//   item19_every_rest_time_is_the_reference_bit_for_bit: random drives (output at the motor with
//     under-, critically and over-damped motors and loads from frictionless up; some at the load,
//     where the bound is not usable) and random flights, in closed form after a bounce
//     (LinearFlight) and on the separation line of the generated cases I and II; random rest
//     velocities.  Every rest time equals the reference's; after every certified state a scan of the
//     flight to the end finds no velocity ≥ rest_velocity; the bound saves most evaluations.
//   item19_a_wrong_rule_is_caught: the same flights with the rule made wrong on purpose — the margin
//     2 instead of 0.9, or the motor's bound without its rate term (|θ̇m| alone) — give rest times
//     that differ from the reference's, and certified states the scan contradicts: the checks above
//     have the power to see a wrong skip.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/linear_flight.hpp"
#include "hybrid/rest_search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

namespace {

using namespace backlash;
using namespace backlash::numeric;

// The search at main before the bound: every point of every level judged.
template <class StateAt>
double reference_rest_time(const StateAt& state_at, double remaining, double rest_velocity) {
  double lo = 0, hi = remaining;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = 0.5 * (lo + hi);
    bool moving = false;
    for (int k = 0; k <= 32 && !moving; ++k) {
      const auto s = state_at(mid + (remaining - mid) * k / 32.0);
      moving = std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) >= rest_velocity;
    }
    (moving ? lo : hi) = mid;
  }
  return hi;
}

struct Velocities {
  double theta_m, dtheta_m, dtheta_L;
};

// A decaying flight: its state at τ (the closed form's own θm), the number of evaluations and
// the last time evaluated.
struct TestFlight {
  std::function<Velocities(double)> at;
  mutable long evaluations = 0;
  mutable double last = NAN;
  Velocities operator()(double t) const {
    ++evaluations;
    last = t;
    return at(t);
  }
};

// A random drive: K = 1, θR from 0 to 2, the motor's damping from 2 % of critical to three times
// it (a tenth of the draws exactly critical, near half below 0.3), the load frictionless in a tenth.
Parameters random_drive(std::mt19937_64& random, bool at_motor) {
  std::uniform_real_distribution<double> unit(0, 1);
  Parameters p;
  p.measured_at = at_motor ? model::MeasuredAt::Motor : model::MeasuredAt::Load;
  p.K = 1;
  p.theta_R = 2 * unit(random);
  p.Jm = 0.2 + unit(random);
  p.JL = 0.2 + unit(random);
  const double critical = 2 * std::sqrt(p.K * p.Jm);
  const double kind = unit(random);  // light damping: later swings near the envelope (the bound's edge)
  p.Fm = (kind < 0.1 ? 1.0 : kind < 0.55 ? 0.02 + 0.28 * unit(random) : 0.3 + 2.7 * unit(random)) * critical;
  p.FL = unit(random) < 0.1 ? 0 : 0.05 + unit(random);
  p.backlash = 0.1;
  return p;
}

// The first of 1, 2, 4, … s (up to 2^20) where both velocities are below v at that time and at
// 32 points before it back to its half; NAN when none.
double a_resting_time(const TestFlight& f, double v) {
  for (double T = 1; T < 1.1e6; T *= 2) {
    bool rests = true;
    for (int k = 0; k <= 32 && rests; ++k) {
      const Velocities s = f.at(T * (0.5 + k / 64.0));
      rests = std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) < v;
    }
    if (rests) return T;
  }
  return NAN;
}

// One flight's rest searched by the reference and by rest_time with `quiet` (a rule on the
// closed form's state); counts the differences, the evaluations of both, and the certified states
// after which a scan of 64 points up to `remaining` finds a velocity ≥ v (a wrong certificate,
// whether or not it changed a decision).
struct Tally {
  long flights = 0, differences = 0, reference_evaluations = 0, evaluations = 0, certified = 0, wrong = 0;
};
void compare(const TestFlight& flight, double remaining, double v,
             const std::function<bool(const Velocities&)>& quiet, Tally& tally) {
  flight.evaluations = 0;
  const double reference = reference_rest_time(flight, remaining, v);
  tally.reference_evaluations += flight.evaluations;
  const auto scanned = [&](const Velocities& s) {
    if (!quiet(s)) return false;
    const double from = flight.last;
    ++tally.certified;
    for (int i = 1; i <= 64; ++i) {
      const Velocities later = flight.at(from + (remaining - from) * i / 64.0);
      if (std::max(std::fabs(later.dtheta_m), std::fabs(later.dtheta_L)) >= v) {
        ++tally.wrong;
        break;
      }
    }
    return true;
  };
  flight.evaluations = 0;
  const double fast = detail::rest_time(flight, remaining, v, scanned);
  tally.evaluations += flight.evaluations;
  ++tally.flights;
  if (reference != fast) {
    if (++tally.differences <= 3) std::printf("  differs: %.17g vs reference %.17g (v = %g)\n", fast, reference, v);
  }
}

// A random flight after a bounce: x0 near θR, velocities up to 1 rad/s.
TestFlight bounce_flight(const Parameters& p, std::mt19937_64& random) {
  std::uniform_real_distribution<double> spread(-1, 1);
  SmallVector x0(4);
  const double load_speed = p.FL == 0 && random() % 2 ? 0 : spread(random);  // a frictionless load that can rest
  x0 << p.theta_R + 0.3 * spread(random), spread(random), p.theta_R + 0.3 * spread(random), load_speed;
  const LinearFlight flight(free_mode_segment(p), x0);
  return TestFlight{[flight](double t) {
    const SmallVector x = flight.state(t);
    return Velocities{x(0), x(1), x(3)};
  }};
}

// A separation-line flight of a generated case (the closed form Flight::from_separation_line runs).
TestFlight line_flight(const EvaluatorPtr& evaluator, double v0) {
  return TestFlight{[evaluator, v0](double t) {
    const FreeState f = evaluator->free_state(t, v0);
    return Velocities{f.theta_m, f.dtheta_m, f.dtheta_L};
  }};
}

using Rule = std::function<bool(const detail::FreeFlightRestBound&, const Velocities&, double)>;

// The flights of both kinds, each searched with `rule` for its rest at a random rest velocity.
Tally run_all(const Rule& rule, long& usable) {
  std::mt19937_64 random(1919019);
  std::uniform_real_distribution<double> unit(0, 1);
  Tally tally;
  const auto search = [&](const TestFlight& flight, const detail::FreeFlightRestBound& bound) {
    const double v = std::pow(10.0, -11 + 8 * unit(random));
    const double T = a_resting_time(flight, v);
    if (!std::isfinite(T)) return;
    usable += bound.usable;
    const auto quiet = [&](const Velocities& s) { return rule(bound, s, v); };
    compare(flight, T * (1 + 3 * unit(random)), v, quiet, tally);
  };
  for (int set = 0; set < 200; ++set) {
    const Parameters p = random_drive(random, set % 5 != 4);
    const detail::FreeFlightRestBound bound(free_mode_segment(p));
    for (int i = 0; i < 6; ++i) search(bounce_flight(p, random), bound);
  }
  for (const char* id : {"I", "II"}) {
    const EvaluatorPtr evaluator = generated_case_evaluator(id);
    const detail::FreeFlightRestBound bound(free_mode_segment(evaluator->parameters()));
    for (int i = 0; i < 100; ++i) search(line_flight(evaluator, (unit(random) - 0.5) * 4), bound);
  }
  return tally;
}

TEST(RestSearch, item19_every_rest_time_is_the_reference_bit_for_bit) {
  long usable = 0;
  const Tally t = run_all(
      [](const detail::FreeFlightRestBound& b, const Velocities& s, double v) {
        return b.quiet_after(s.theta_m, s.dtheta_m, s.dtheta_L, v);
      },
      usable);
  std::printf("%ld flights (%ld with a usable bound): %ld differences; evaluations %ld, reference %ld; %ld "
              "certified states, %ld contradicted by a scan\n",
              t.flights, usable, t.differences, t.evaluations, t.reference_evaluations, t.certified, t.wrong);
  EXPECT_GT(t.flights, 1000);
  EXPECT_GT(t.certified, 5000);
  EXPECT_EQ(t.differences, 0);
  EXPECT_EQ(t.wrong, 0);
  EXPECT_LT(4 * t.evaluations, t.reference_evaluations);  // the bound saves most evaluations
}

TEST(RestSearch, item19_a_wrong_rule_is_caught) {
  long usable = 0;
  const Tally margin = run_all(
      [](const detail::FreeFlightRestBound& b, const Velocities& s, double v) {
        return b.usable && b.velocity_bound(s.theta_m, s.dtheta_m, s.dtheta_L) < 2 * v;
      },
      usable);
  const Tally no_rate = run_all(
      [](const detail::FreeFlightRestBound& b, const Velocities& s, double v) {
        return b.usable && std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) < b.margin * v;
      },
      usable);
  std::printf("margin 2: %ld of %ld differ, %ld of %ld certified states contradicted; |θ̇m| alone: %ld of %ld differ, "
              "%ld of %ld contradicted\n",
              margin.differences, margin.flights, margin.wrong, margin.certified, no_rate.differences, no_rate.flights,
              no_rate.wrong, no_rate.certified);
  EXPECT_GT(margin.differences, 0);
  EXPECT_GT(no_rate.differences, 0);
  EXPECT_GT(margin.wrong, 20);
  EXPECT_GT(no_rate.wrong, 20);
}

}  // namespace
