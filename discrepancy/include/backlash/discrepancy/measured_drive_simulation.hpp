// backlash/discrepancy/measured_drive_simulation.hpp — a rigid drive driven by a measured (logged)
// drive signal, simulated exactly (semantics: docs/effects.md, "Measured drive (rigid)").
//
// A real servo record (EMPS: a DC motor driving a carriage through a ball screw, logged
// at 1 kHz) gives the drive as a data column.  With backlash 0 the motor and the load are
// one body:
//   J·v' = u(t) + T0 − F·v − Tc·s,   x' = v,
//   J = Jm + JL > 0, F = Fm + FL ≥ 0, Tc = coulomb_motor + coulomb_load ≥ 0 (one friction),
//   u(t) = sat_L(gain·drive_k), sat_L(z) = min(L, max(−L, z)), the offset T0 added after
//   the clipping (as D = sat(…) + T0 in effects.md).
// Units are the record's own: x and v in its length (or angle) unit, the drive torque,
// T0, Tc and L in its force (or torque) unit, J in force·s²/length, F in force·s/length
// (EMPS: m, N, kg, N·s/m).
//
// Zero-order hold with delay τ ≥ 0: sample k acts on [t_k + τ, t_{k+1} + τ); where
// t − τ < t_0 the first sample acts.  Every boundary is computed as the double t_k + τ.
//
// Coulomb friction with sticking (Tc > 0), with a = u + T0 the net drive of a piece:
//   moving       s = sgn(v);
//   at v = 0     stuck while |a| ≤ Tc; else it moves off with s = sgn(a).
// A moving body whose velocity reaches 0 is decided there with the drive acting then:
// Stick (|a| ≤ Tc), Reversal (|a| > Tc, against the old motion), or nothing (the zero is
// at a piece boundary and the next piece pushes on in the same direction).  A stuck body
// breaks away (Slip) at the first piece boundary where |a| > Tc.  With Tc = 0 there is
// no sticking: v passes through 0 and nothing is an event.
//
// Exact solution.  On a hold piece the forcing c = a − Tc·s is constant; with q = c/J,
// k = F/J and z = −k·h (h the time into the piece):
//   v(h) = v0·e^z + q·h·φ1(z),   x(h) = x0 + v0·h·φ1(z) + q·h²·φ2(z),
//   φ1(z) = (e^z − 1)/z, φ2(z) = (e^z − 1 − z)/z²   (series for |z| < 1/8, expm1 above),
// one formula for F > 0 and F = 0 (φ1 = 1, φ2 = 1/2: x0 + v0 h + c h²/(2J)).  When c
// opposes the motion (c·s < 0) the velocity reaches 0 at
//   h* = (J/F)·ln(1 − F·v0/c) = w·log1p(k·w)/(k·w),   w = −v0/q > 0   (F = 0: h* = w),
// so a piece is at most two closed forms: motion to the zero, then sticking or the
// reversed motion (whose forcing points away from 0: no second zero in the piece).
// No root finding and no step size.
//
// Guarantee.  For valid input every output is finite (std::overflow_error, never NaN,
// if the magnitudes overflow a double).  Each piece adds a few ulps of |x| and of its
// increment, so after n pieces |Δx| ≲ n·(few ulp)·max|x| (and likewise v); an event's
// time is h* of the computed state, so it is off by that state's |Δv|/|v'| plus a few
// ulps.  A zero is never missed: the sign of c·s is checked on every piece.  Tiny
// velocities: only v == 0 is rest (a body moving at 1e-300 moves on, and reaches 0 at its
// own h*).  A velocity that reaches 0 only within rounding of a piece's end (the closed
// form's v there is 0 or has the wrong sign, also by underflow) is set to exactly 0 and
// decided at the start of the next piece, with that piece's drive.
// Checked against an independent Boost.Odeint reference (piece by piece, its own
// stick/slip handling) in tests/discrepancy/check_measured_drive_simulation.cpp.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/parametric.hpp"

#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace backlash::discrepancy {

struct RigidDrive {
  double J = 1;         ///< total inertia Jm + JL, > 0
  double F = 0;         ///< total viscous friction Fm + FL, ≥ 0
  double coulomb = 0;   ///< Tc ≥ 0, with sticking
  double offset = 0;    ///< T0, added after the clipping
  double saturation = std::numeric_limits<double>::infinity();  ///< L > 0 (∞: no limit)
  double delay = 0;     ///< τ ≥ 0 [s]: sample k acts from t_k + τ
  double gain = 1;      ///< torque per unit of the drive column
};

/// The net drive a = sat_L(gain·drive) + T0 that one logged value exerts.
double applied_torque(const RigidDrive& model, double drive);

/// From a case's parameters and effects: J = Jm + JL, F = Fm + FL, Tc = coulomb_motor +
/// coulomb_load, T0 = the torque offset, L = saturation, τ = delay, gain = drive_gain (K and
/// θR are unused: the loop is open).  std::invalid_argument for what needs a gap or a
/// mesh: backlash > 0, restitution ≠ 0, compliance.
RigidDrive rigid_drive_of(const numeric::Parameters& p, const numeric::Effects& e, double drive_gain);

enum class DriveEventKind {
  Stick,     ///< a moving body reached v = 0 with |a| ≤ Tc
  Slip,      ///< a body at rest (stuck, or started at rest) moved off: |a| > Tc
  Reversal,  ///< a moving body reached v = 0 and moved off the other way at once
};
const char* to_string(DriveEventKind kind);  ///< "stick", "slip", "reversal"

struct DriveEvent {
  double t = 0;  ///< [s]
  DriveEventKind kind = DriveEventKind::Stick;
  double x = 0;  ///< position there (v = 0 at every event)
};

struct MeasuredDriveRun {
  std::vector<double> x, v;         ///< at t[first], …, t[last] (x[0] = x0, v[0] = v0)
  std::vector<DriveEvent> events;   ///< in time order, the first max_events of them
  std::size_t event_count = 0;      ///< all events, also those beyond max_events
  /// Held by friction at t[last].  v = 0 without it: at rest, not yet decided (a zero
  /// reached at t[last], or a start at rest with first == last).  Either way a run that
  /// continues from (x.back(), v.back()) behaves as this one would have: an at-rest start
  /// is decided at once.
  bool stuck_at_end = false;
};

/// Simulates from (x0, v0) at t[first] to t[last] (inclusive), with an output at every
/// sample in between; pieces are split at the outputs and at the shifted samples t_k + τ.
/// A start at rest (v0 == 0, or start_stuck, which requires v0 == 0) is decided at once
/// by the static rule: a Slip at t[first] when |a| > Tc, stuck (no event) otherwise.  The
/// samples used are those from the one acting at t[first] (which precedes `first` when
/// τ > 0) to `last`; only they are checked, so a window of a long record costs its own
/// length (plus τ/period), and samples outside it need not be valid.
/// std::invalid_argument, naming the problem, for: t and drive of different lengths,
/// first > last, last out of range, a used t not finite or not strictly increasing, a
/// used drive sample not finite, J ≤ 0, F < 0, Tc < 0, L ≤ 0, τ < 0, a non-finite
/// parameter (L = +∞ allowed) or x0, v0, start_stuck with v0 ≠ 0.
/// Cost: one exp/expm1 (or an 8–11-term series) per piece, a log1p per zero; the outputs
/// are allocated once (about 15–20 ns per piece: 0.5 ms for an EMPS record of 24 841
/// samples, bench/time_measured_drive.cpp).
MeasuredDriveRun simulate_measured_drive(const RigidDrive& model, std::span<const double> t,
                                         std::span<const double> drive, std::size_t first, std::size_t last,
                                         double x0, double v0, bool start_stuck = false,
                                         std::size_t max_events = 10'000);

}  // namespace backlash::discrepancy
