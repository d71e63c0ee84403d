// backlash/numeric/scales.hpp — what double precision and the certified searches can
// compute, decided before any work is done.
//
// Three checks, each with the reason in words when it fails:
//   parameters   every parameter and every rate built from them (K/J, F/J, Fm/Jm, FL/JL,
//                F², 4JK) is a finite, normal double, and the time scales are not further
//                apart than `max_stiffness` (the fastest rate times the slowest time scale):
//                beyond that an event search over one slow time scale needs more intervals
//                than any budget (K = 1e140 with J = 1 is refused at once instead of running
//                for minutes);
//   resolution   a motion of size S (|θ − θR| of the angles, plus |θR| itself for absolute
//                angles) is resolved when double precision represents the angles to a
//                `backlash_resolution` fraction of the backlash: ε·S ≤ 1e-6·b.  Beyond it the
//                gap θL − θm between two angles of size S is rounding noise (a step of 1e16
//                with b = 0.3), and an answer would be invented, not computed;
//   rigid drive  b = 0 needs no resolution: the bodies never separate.
// The effects' parameters pass the same checks (effect_scale_problem): each a finite, normal
// double (or 0) inside its admissible range (the table of effects), and the mesh's rate held to
// `max_stiffness` like the modes' own; a delay is at least `min_delay_fraction` of the fastest
// time scale (docs/effects.md, "Delay").
#pragma once

#include "backlash/numeric/parametric.hpp"

#include <cmath>
#include <optional>
#include <string>

namespace backlash::numeric {

struct Effects;

/// Largest stiffness (fastest rate × slowest time scale) accepted.
inline constexpr double max_stiffness = 1e9;
/// The fraction of the backlash to which angles must be resolved.
inline constexpr double backlash_resolution = 1e-6;

/// The fastest rate (1/s) of the contact and free modes: a + √k bounds |roots of s² + a s + k|.
double fastest_mode_rate(const Parameters& p);

/// Why double precision or the searches cannot handle these parameters, or nothing.  The
/// message names the parameters (K, motor.J, motor.F, load.J, load.F, backlash).
std::optional<std::string> parameter_scale_problem(const Parameters& p);

/// The fastest rate (1/s) of every mode with the effects: fastest_mode_rate(p) and the
/// engaged mesh's, sqrt(kc·(1/Jm + 1/JL)) + cc·(1/Jm + 1/JL).
double fastest_mode_rate(const Parameters& p, const Effects& e);

/// The shortest delay resolved, in units of the fastest time scale 1/fastest_mode_rate(p, e):
/// a shorter one changes the motion by less than the integration's own error while costing
/// t_end/τ steps (docs/effects.md, "Delay").
inline constexpr double min_delay_fraction = 1e-3;

/// Why double precision or the searches cannot handle these effect parameters, or nothing.
/// The message names the parameter by its case-file key ("compliance.stiffness", "delay").
std::optional<std::string> effect_scale_problem(const Parameters& p, const Effects& e);

/// Why a simulation to `t_end` cannot resolve its event times, or nothing: a time t carries
/// ε·t of rounding, held (like the angles) to `backlash_resolution` of the fastest time scale,
/// so t_end ≤ 1e-6/(ε·fastest_mode_rate(p, e)) — 3e9 s for the thesis's cases.  Beyond it the
/// closed forms' sin and cos would be evaluated at arguments whose phase is rounding.
std::optional<std::string> time_resolution_problem(const Parameters& p, const Effects& e, double t_end);

/// The largest motion size S at which the backlash is still resolved (infinite for b = 0).
double resolvable_scale(const Parameters& p);

/// The size of a state's motion for the resolution rule: max(|θm − θR|, |θL − θR|) + |θR|.
double motion_scale(const Parameters& p, double theta_m, double theta_L);

/// Whether a motion of size `scale` is resolved, `resolvable` being resolvable_scale(p): finite and
/// at most that (resolution_problem's rule, for a loop that keeps resolvable_scale(p)).
inline bool motion_resolved(double scale, double resolvable) { return std::isfinite(scale) && scale <= resolvable; }

/// Why a motion of size `scale` cannot be resolved, or nothing; `what` names its origin
/// ("the step 1e16", "the velocity 1e20").
std::optional<std::string> resolution_problem(const Parameters& p, double scale, const std::string& what);

}  // namespace backlash::numeric
