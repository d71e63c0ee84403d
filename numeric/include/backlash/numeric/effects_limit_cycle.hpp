// backlash/numeric/effects_limit_cycle.hpp — limit cycles of the model with effects.
//
// The section Σ is the set of states just after a separation leaving the face −1
// (rigid contact ending, or the compliant mesh releasing), and P: Σ → Σ the full
// return map (the next separation leaving that face).  No symmetry is assumed,
// so a torque offset, which breaks the odd symmetry about θR, is handled alike.
//   1. From seeds — the step experiment, and free flights leaving face −1 on the
//      nominal separation line at several velocities — P is iterated until the
//      section state stops moving (a stable cycle), the motion comes to rest (with
//      Coulomb friction: a dead band) or grows without bound.
//   2. Without delay the fixed point is polished by Newton's method on
//      F(s) = P(s) − s in the section's coordinates — (θo, θ̇o) for rigid gears,
//      (θm, θ̇m, θL, θ̇L) with a compliant mesh — with a central-difference
//      Jacobian; the multiplier is the largest eigenvalue (in modulus) of DP (the
//      others vanish: P's range is Σ).  With a delay the state is a whole history:
//      the cycle is the converged iteration and the multiplier the ratio of
//      successive steps of the iteration.
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
