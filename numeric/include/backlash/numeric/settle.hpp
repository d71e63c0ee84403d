// backlash/numeric/settle.hpp — the time a step response takes to settle: onto its limit
// cycle, or to rest (the `map` command's settle_time; docs/design.md, "Design-space maps").
//
// The step experiment of docs/physics.md: rest in contact, θo = θR − A at t = 0.  θo is
// sampled at t_k = k·h, h = t_end / samples (k = 0 … samples, the recorder's exact grid),
// and the band it must end in is
//   - rest:  |θo − θ∞| ≤ tol, θ∞ the value at which the motion stopped (status rest: the
//            simulator proved no further event), or θR when it did not stop by t_end and the
//            point has no limit cycle (the only equilibrium of the loop without Coulomb
//            friction; with Coulomb friction a sticking rest is reached as "rest");
//   - cycle: θo ∈ [θo_min − tol, θo_max + tol], the cycle's exact extremes
//            (limit_cycle.hpp), when the point has a limit cycle and the motion did not stop;
// with tol = fraction·|A| (2 % by default: the classic settling band).  The settle time is the
// first sample time t_k after which every sample lies in the band (0 when all do) — exact up
// to the sampling step h, which is part of the definition (t_end = 60 s, 2000 samples:
// h = 0.03 s).  Not settled: the sample at t_end is outside the band (status "not_settled",
// time NaN).  A simulation that stopped early (chattering, event_limit, ... :
// hybrid_simulation.hpp) gives that status and NaN — never a guess.
#pragma once

#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <cmath>
#include <string>

namespace backlash::numeric {

struct SettleOptions {
  double step = 0;         ///< A [rad] (0: nothing is computed, status "no_step")
  double t_end = 60;       ///< [s]
  int samples = 2000;      ///< h = t_end / samples
  double fraction = 0.02;  ///< tol = fraction·|A|
};

struct Settle {
  std::string status = "no_step";  ///< "settled" | "not_settled" | "no_step" | a simulation status
  double time = NAN;               ///< [s]; NaN unless settled
  double band_low = NAN, band_high = NAN;  ///< the band [rad], absolute (θR included)
};

/// The settle time of `model`'s step response; `cycle` is the point's limit-cycle search
/// result (its status decides the band), its angles in the model's own coordinates.
Settle settle_time(const ValidatedEffectModel& model, const LimitCycle& cycle, const SettleOptions& options);
/// The same for the nominal model (no effects): simulate_step on `evaluator`.
Settle settle_time(const ValidatedEvaluator& evaluator, const LimitCycle& cycle, const SettleOptions& options);

}  // namespace backlash::numeric
