// backlash/numeric/effects_limit_cycle.hpp — limit cycles of the model with effects.
//
// The section Σ is the set of states just after a separation leaving the face −1
// (rigid contact ending, or the compliant mesh releasing), and P: Σ → Σ the full
// return map (the next separation leaving that face).  No symmetry is assumed,
// so a torque offset, which breaks the odd symmetry about θR, is handled alike.
//   1. From seeds — the step experiment, and free flights leaving face −1 on the
//      nominal separation line at several velocities — P is iterated (Steffensen)
//      until the section state stops moving (a stable cycle), the motion comes to
//      rest (with Coulomb friction: a dead band) or grows without bound; when it
//      does not settle, P², P³, P⁴ (a period-k cycle is a fixed point of P^k), then
//      Newton's method on F(s) = P^k(s) − s along Σ with a central-difference
//      Jacobian (slow or unstable cycles; a stable one preferred).  Nothing settled:
//      the status unresolved, never none.
//   2. Without delay the multiplier is the eigenvalue of largest modulus of DP^k
//      restricted to Σ (central differences; its modulus for a complex pair), or the
//      one-ray Richardson estimate when that agrees with it to 1e-3.  With a delay
//      the state is a whole history: the cycle is the converged iteration of one
//      continuous run (period k when the crossings repeat every k), the multiplier
//      the ratio of successive steps.  stable ⇔ |multiplier| < 1; a cycle whose
//      figures are not finite or beyond the divergence bound is not reported.
//   3. On the cycle one period is simulated with exact extremes: amplitude
//      max|θo − θR|, peak-to-peak of θo, θm, θL, period, separation velocity (NaN
//      for a cycle without a separation: with restitution the bodies can bounce from
//      face to face without ever staying in contact).
// Without effects this is find_limit_cycle on the nominal evaluator (limit_cycle.hpp).
#pragma once

#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <cmath>
#include <optional>
#include <vector>

namespace backlash::numeric {

struct EffectLimitCycleOptions {
  double step = NAN;            ///< the step experiment used as the first seed (NaN: none)
  std::vector<double> seed_velocities{0.05, 0.2, 0.6, 1.5};  ///< further seeds (× max(1, |θR|))
  int max_cycles = 300;         ///< full cycles iterated per seed
  double tolerance = 1e-13;     ///< convergence of the iteration (relative to the section state)
  double horizon = 0;           ///< time allowed for one return (0: 60 slowest time scales)
  bool general = false;         ///< use this method even without effects (tests)
  std::optional<HybridState> warm_start;  ///< a neighbouring cycle's section state, tried first (sweeps)
};

LimitCycle find_limit_cycle(const ValidatedEffectModel& model, const EffectLimitCycleOptions& options = {});

}  // namespace backlash::numeric
