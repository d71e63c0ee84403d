// numeric/hybrid/rest_search.hpp (internal) — when a decaying closed-form segment comes to rest.
#pragma once

#include <algorithm>
#include <cmath>

namespace backlash::numeric::detail {

/// The first time in [0, remaining] after which both velocities stay below `rest_velocity`:
/// bisection on "any motion left in [mid, remaining]", judged at 33 evenly spaced points of
/// that interval, to 1e-12 relative (200 halvings at most).  `state_at(t)` gives a state with
/// dtheta_m and dtheta_L; the caller knows the segment is at rest at `remaining`.
template <class StateAt>
double rest_time(const StateAt& state_at, double remaining, double rest_velocity) {
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

}  // namespace backlash::numeric::detail
