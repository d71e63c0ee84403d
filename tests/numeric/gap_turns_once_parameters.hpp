// tests/numeric/gap_turns_once_parameters.hpp — the random parameter sets of the tests of a flight
// whose gap turns at most once (check_gap_turns_once: the nominal event loop;
// check_effects_gap_turns_once: the effects engine).
#pragma once

#include "backlash/numeric/hybrid_simulation.hpp"

#include <cmath>
#include <random>

namespace backlash::testing {

/// A random parameter set: the output at the load (any damping), or at the motor with the motor
/// over-damped (`kind` 1) or under-damped (`kind` 2).  The nominal model's under-damped motors
/// (Fm ≥ 0) were not seen to return before the opposite face's crossing (nor is it proved they
/// cannot): `kind` 2 draws a negative Fm (swings that grow, with a narrow backlash), which does —
/// flights on which the shortcut, forced, must be caught missing the return.
inline numeric::Parameters random_gap_parameters(std::mt19937_64& random, int kind) {
  std::uniform_real_distribution<double> inertia(0.1, 1.0), friction(0.0, 0.5), gap(0.05, 0.5), over(1.05, 3.0);
  numeric::Parameters p;
  p.K = 1;
  p.theta_R = 1;
  p.Jm = inertia(random);
  p.JL = inertia(random);
  p.FL = friction(random);
  p.backlash = kind == 2 ? 0.2 * gap(random) : gap(random);  // under-damped: swings past the backlash
  p.measured_at = kind == 0 ? model::MeasuredAt::Load : model::MeasuredAt::Motor;
  const double critical = std::sqrt(4 * p.K * p.Jm);
  p.Fm = kind == 1 ? over(random) * critical : kind == 2 ? -0.5 * critical * friction(random) : friction(random);
  return p;
}

}  // namespace backlash::testing
