// numeric/hybrid/sample_band.hpp (internal) — where a segment's measured angle can turn, for
// leaving out the samples that certainly lie in a band (SimulationOptions::sample_band).
//
// Both closed forms whose measured angle oscillates are a damped oscillator about θR
// (parametric.hpp): contact, e = θo − θR with α = F/2J, w² = K/J; free flight measured at the
// motor, e = θm − θR with α = Fm/2Jm, w² = K/Jm.  Underdamped (α < w, ωd = √(w² − α²)),
//   ė(τ) = e^{−ατ}·[ė0 cos ωd τ − ((α ė0 + w² e0)/ωd) sin ωd τ] = e^{−ατ}·M cos(ωd τ + ψ),
// so its turns (ė = 0) are τ_j = (π/2 − ψ + jπ)/ωd: the extremes of e on [0, d] are at 0, d
// and these.  Free flight measured at the load is monotone (θ̇L = θ̇m0·e^{−(FL/JL)τ}): no turns.
#pragma once

namespace backlash::numeric::detail {

/// The turns of e'' + 2α e' + w² e = 0 from (e0, ė0) in (0, duration), ascending, into
/// `turns` (at most `capacity`); their count, or −1 when they are not given by the formula
/// above (not clearly underdamped: ωd < 1e-3·w, or more than `capacity` turns).
int damped_turns(double alpha, double w2, double e0, double de0, double duration, double* turns, int capacity);

}  // namespace backlash::numeric::detail
