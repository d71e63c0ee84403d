// numeric/hybrid/rest_search.hpp (internal) — when a decaying closed-form segment comes to rest.
#pragma once

#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/quiet_tail.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::numeric::detail {

/// The first time in [0, remaining] after which both velocities stay below `rest_velocity`:
/// bisection on "any motion left in [mid, remaining]", judged at 33 evenly spaced points of
/// that interval, to 1e-12 relative (200 halvings at most).  `state_at(t)` gives a state with
/// dtheta_m and dtheta_L; the caller knows the segment is at rest at `remaining`.
///
/// `quiet_after(s)`: true only when the velocities the closed form gives at every time after
/// that of the state s are certified below `rest_velocity` (FreeFlightRestBound) — a level meets
/// no motion at its points from there on, so they are not evaluated, and a later level's points
/// from the earliest such time on neither.  The decision of every level ("some point has
/// max(|θ̇m|, |θ̇L|) ≥ rest_velocity") and so the time returned are the same bits as without it
/// (docs/design.md, "The event loop": the rest).
template <class StateAt, class QuietAfter>
double rest_time(const StateAt& state_at, double remaining, double rest_velocity, const QuietAfter& quiet_after) {
  double lo = 0, hi = remaining;
  double quiet_from = INFINITY;  // every point at or after it is below rest_velocity (certified)
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = 0.5 * (lo + hi);
    bool moving = false;
    for (int k = 0; k <= 32 && !moving; ++k) {
      const double t = mid + (remaining - mid) * k / 32.0;
      if (t >= quiet_from) break;
      const auto s = state_at(t);
      moving = std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) >= rest_velocity;
      if (!moving && k < 32 && quiet_after(s)) quiet_from = t;
    }
    (moving ? lo : hi) = mid;
  }
  return hi;
}

/// rest_time judging every point (no bound).
template <class StateAt>
double rest_time(const StateAt& state_at, double remaining, double rest_velocity) {
  return rest_time(state_at, remaining, rest_velocity, [](const auto&) { return false; });
}

/// A bound on both velocities of a free flight (free_mode_segment, output at the motor: the motor
/// not driven by the load) at every time after that of a state x = (θm, θ̇m, θL, θ̇L), in rad/s.
/// The motor's velocity u = θ̇m obeys u'' = −k u − a u' (k = K/Jm > 0, a = Fm/Jm ≥ 0: the
/// derivative of θ̈m = −k θm − a θ̇m + c), so E = k u² + u'² has E' = −2a u'² ≤ 0 — the log-norm of
/// the rates in the scaling (√k, 1) is 0 for every damping, over-, critically or under-damped,
/// without modes — and |u(t)| ≤ √(E(t0)/k) = √(u² + u'²/k) for t ≥ t0; the load's velocity
/// decays on its own, |θ̇L(t)| = e^{−β(t−t0)}|θ̇L(t0)| (β = FL/JL ≥ 0).  u' = θ̈m is formed from x
/// with a relative 1e-12 of its terms allowed for its rounding (a few ulps) and the closed form's
/// at x (angles in error coordinates, θR = 0: no cancellation against θR).  Not usable (another
/// form: the output at the load, whose motor is driven by θL) → rest_time judges every point.
struct FreeFlightRestBound {
  bool usable = false;
  double k = 0, a = 0, c = 0;  // θ̈m = −k θm − a θ̇m + c

  explicit FreeFlightRestBound(const LinearSegment& free) {
    if (!free_mode_form(free) || free.A(1, 2) != 0 || !(free.A(1, 0) < 0)) return;
    usable = true;
    k = -free.A(1, 0);
    a = -free.A(1, 1);
    c = free.c(1);
  }

  /// sup over t ≥ t0 of max(|θ̇m(t)|, |θ̇L(t)|) for the flight through (θm, θ̇m, θ̇L) at t0.
  double velocity_bound(double theta_m, double dtheta_m, double dtheta_L) const {
    const double rate = -k * theta_m - a * dtheta_m + c;  // u' = θ̈m
    const double rate_bound = std::fabs(rate) + 1e-12 * (k * std::fabs(theta_m) + a * std::fabs(dtheta_m) + std::fabs(c));
    const double motor = std::sqrt(dtheta_m * dtheta_m + rate_bound * rate_bound / k) * (1 + 1e-12);
    return std::max(motor, std::fabs(dtheta_L));
  }

  /// The share of rest_velocity the bound must stay below: the closed form's values at the later
  /// points (which rest_time compares) differ from the exact flight through this state by their
  /// rounding — ulps of the decayed terms, ≥ 1e13 times less than the other tenth; an absolute
  /// floor of rounding (ulps of the angles) is below the bound's own rate term, 1e-12·√k·|θm|.
  static constexpr double margin = 0.9;

  /// Whether every later velocity is certified below rest_velocity (velocity_bound < margin ×
  /// rest_velocity).  θm is the closed form's own, in the frame of the segment's c (without an
  /// offset added after it).
  bool quiet_after(double theta_m, double dtheta_m, double dtheta_L, double rest_velocity) const {
    return usable && velocity_bound(theta_m, dtheta_m, dtheta_L) < margin * rest_velocity;
  }
};

}  // namespace backlash::numeric::detail
