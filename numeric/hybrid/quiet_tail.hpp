// numeric/hybrid/quiet_tail.hpp (internal) — the slow tail of a free flight, certified at once.
//
// The unit gap profile of the dividing lines (dividing_lines.cpp) searches the gap f = θL − θm of
// the flight from the separation line for a return to 0 and for the zeros of its slope f' over a
// horizon of 40 slowest time scales — 40·JL/FL for a nearly frictionless load, 3.2·10⁶ s for case
// IV at FL = 1e-5 — where first_crossing's intervals stay at the free mode's growth bound
// e^{μ∞ h} (seconds: μ∞ counts the motor's coupling, not its decay).  Long before the horizon the
// motor has settled on the load's slow motion and f, f' keep their signs; this certifies that on
// the free mode's own structure (segment_dynamics.hpp): the load decays on its own, θ̈L = −β θ̇L
// (β = FL/JL), and the motor is the damped block θ̈m = −k θm − a θ̇m − kL θL + c (k = K/Jm at the
// motor, kL = K/Jm at the load, a = Fm/Jm), driven by the load's position when measured there.
// Its derivatives q = (θm''', θm'''') obey q' = M q + (0, −kL β² θ̇L), M = [[0, 1], [−k, −a]], so
// from the state at one time T alone, with e^{Mτ} in closed form (cosh/sinh, cos/sin or 1, τ:
// docs/design.md, "The event loop"),
//   sup over [a, b] of |f''''| ≤ β³|θ̇L(T)| e^{−β(a−T)} + sup |(e^{Mτ} q(T))₂| + kL β²|θ̇L(T)| ∫₀^{b−T} |(e^{Mσ})₂₂| dσ,
// which decays with the motor's own rates instead of growing with e^{μ∞ h}: the certified search
// of f' from T to the horizon with that bound (LinearWitness::third_derivative_bound) takes a few
// intervals per window.
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <functional>

namespace backlash::numeric::detail {

/// Whether A, c have the free mode's form (segment_dynamics.cpp, free_mode_segment), finite, its
/// rates ≥ 0 (−A(1, 0), −A(1, 1), −A(1, 2), −A(3, 3)).
bool free_mode_form(const SmallMatrix& A, const SmallVector& c);
bool free_mode_form(const LinearSegment& s);

/// The bound above on sup |d⁴/dt⁴ (θL − θm)| over [a, b] ⊂ [T, ∞) (b − a, a ≥ T in s) for the
/// flight of `free_segment` (free_mode_segment) through the state `xT` = (θm, θ̇m, θL, θ̇L) at T,
/// its rounding allowed for (the derivatives at T are formed from xT: a relative 1e-6 of their
/// terms' size, as first_crossing.cpp's sample noise).  Empty when the segment is not of the free
/// mode's form (a negative rate, a coupling the free mode has not).
std::function<double(double, double)> gap_slope_third_derivative_bound(const LinearSegment& free_segment,
                                                                       const SmallVector& xT, double T);

/// Whether the gap f = θL − θm of the flight `state` (x(t) in closed form, of `free_segment`)
/// and its slope f' = θ̇L − θ̇m are non-zero with one sign at `from` (`gap_at_from`: f there, from
/// the closed form) and f' has no zero in (from, horizon] — the certified search of f' with the
/// bound above, within `budget` intervals: so f and f' have no zero on [from, horizon].  False
/// when that is not certified (a zero, a grazing, the budget spent, a non-finite state).
bool gap_moves_away_from(const LinearSegment& free_segment, const std::function<SmallVector(double)>& state,
                         double gap_at_from, double from, double horizon, double time_unit, long budget);

/// A quiet tail of a free flight's gap (docs/design.md, "The event loop"): the earliest τ0 of
/// 0, w/4, w/2, w, 2w, … (w = `first_window`, s) below `horizon` from which the gap change
/// Δx(τ) = (θL − θm)(τ) − (θL − θm)(0) of the flight through x0 = x(0) = (θm, θ̇m, θL, θ̇L) on the
/// free segment (A, c) stays strictly between the levels `level_a` and `level_b` (rad) for every
/// τ in [τ0, horizon] — by more than a margin of 1e-6·max(1, the angles' size), far above the
/// rounding and the validated closed forms' error (1e-9), so a search of the closed form over
/// [τ0, horizon] finds no crossing of either level.  The proof is from the flight's exact modes:
/// the load's position moves monotonically, θL(τ) − θL(0) = θ̇L(0)(1 − e^{−βτ})/β (β = FL/JL,
/// θ̇L(0) τ for β = 0); the motor, not driven by the load (output at the motor) and under-damped
/// (Fm² < 4 K Jm), swings about θm∞ = θR within e^{−ατ}√(y1² + ((α y1 + θ̇m(0))/ω)²)
/// (α = Fm/(2Jm), ω² = K/Jm − α², y1 = θm(0) − θR).  INFINITY when no such τ0 is certified
/// (another form of flight: the output at the load, a motor damped at least critically).
double quiet_gap_from(const SmallMatrix& A, const SmallVector& c, const SmallVector& x0, double level_a,
                      double level_b, double horizon, double first_window);

}  // namespace backlash::numeric::detail
