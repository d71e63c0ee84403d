// backlash/numeric/describing_function.hpp — the classical prediction of a
// backlash limit cycle: compared with the exact one in the report (reports/), and the first
// guess of a cold limit-cycle search (limit_cycle.hpp).
//
// The textbook model (Tustin; Gelb & Vander Velde, ch. 5): the drive is one
// rigid body J = Jm + JL, F = Fm + FL in the loop K(θR − θL), and the gear is
// a position backlash (hysteresis) of total width b between the motor angle
// θm and the measured load angle θL:
//     θm = −G(s)·θL (about θR),   G(s) = K/(s(Js + F)),   θL = B_b(θm).
// For θm = A sin ωt (A > b/2) the fundamental of θL is N(A)·A sin, with
//     Re N = (π/2 + arcsin β + β√(1 − β²))/π,   Im N = −(1 − β²)/π,   β = 1 − b/A,
// and a limit cycle is predicted where 1 + N(A)G(jω) = 0, i.e. where −1/N(A)
// meets the Nyquist curve of G.  With this G that is
//     Re N(A) = Jω²/K,   Im N(A) = −Fω/K,
// so ω = −K·Im N(A)/F and Re N − (JK/F²)(Im N)² = 0 fixes A.  Every solution
// is reported with its stability (the roots of Js² + Fs + K·N(A) move into
// the left half plane as A grows past a stable cycle).  The load's swing on a
// predicted cycle is 2A − b, the motor's 2A.
//
// The model cannot see how inertia and friction are split between motor and
// load (only J, F, K, b enter), and it replaces the load's free drift across
// the backlash (with its own deceleration FL/JL) by an instantaneous follow of
// a sinusoidal motor: the exact cycles of the thesis's cases show what that costs.
#pragma once

#include "backlash/numeric/parameters.hpp"

#include <complex>
#include <optional>
#include <string>
#include <vector>

namespace backlash::numeric {

/// N(A) of a backlash of total width b (unit slope); 0 for A ≤ b/2.
std::complex<double> backlash_describing_function(double amplitude, double backlash);

struct DescribingFunctionCycle {
  double amplitude = 0;            ///< A: amplitude of the motor angle (the backlash input)
  double frequency = 0;            ///< ω, rad/s
  double period = 0;               ///< 2π/ω
  double load_peak_to_peak = 0;    ///< 2A − b
  double motor_peak_to_peak = 0;   ///< 2A
  bool stable = false;
};

struct DescribingFunctionPrediction {
  bool applicable = false;         ///< output at the load (the backlash inside the loop)
  std::string reason;              ///< when not applicable or no cycle
  std::vector<DescribingFunctionCycle> cycles;  ///< every intersection, by increasing amplitude
  /// The predicted (stable) cycle of largest amplitude, if any.
  std::optional<DescribingFunctionCycle> predicted() const;
};

DescribingFunctionPrediction describing_function_prediction(const Parameters& p);

/// The first guess of a cold limit-cycle search (limit_cycle.hpp) [rad/s]: the predicted cycle of
/// largest amplitude read as a sinusoid θo − θR = (A − b/2) sin ωt of the load that leaves contact
/// on the separation line θo − θR = cot φ·θ̇o, so  v = ω(A − b/2)/√(1 + ω² cot² φ).  Its root is
/// the first sign change on 64 values of β down from 1, bisected to 1e-15; the signs that the
/// computation can prove without evaluating are not evaluated (docs/design.md, "The limit-cycle
/// contract"; the same bits; describing_function_prediction scans 20,000 for the report's table).
/// 0 when the prediction does not apply or finds no cycle.
double describing_function_separation_velocity(const Parameters& p);

}  // namespace backlash::numeric
