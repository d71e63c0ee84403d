// discrepancy/src/two_body_signals.hpp (internal) — the measured-drive workflow on a drive with
// a gap (two_body_drive.hpp): a record prepared for the torque domain, the linear regression of
// the summed equation, and Ceres's covariance.
#pragma once

#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/discrepancy/two_body_drive.hpp"
#include "backlash/measurements/inverse_dynamics_signals.hpp"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace backlash::discrepancy::two_body {

/// The parameters of the summed equation
///   r = Ū + T0 − (Jm·âm + Fm·v̂m + JL·âL + FL·v̂L + Tm·s̄m + TL·s̄L)      [torque]
/// all terms through the same zero-phase filter.
enum Index { kJm = 0, kFm, kJL, kFL, kTm, kTL, kT0, kCount };
using Theta = std::array<double, kCount>;
using FreeSet = std::array<bool, kCount>;
extern const char* const kName[kCount];  ///< "motor.J", …, "coulomb_motor", "coulomb_load", "torque_offset"

/// One record: the motor's (and the load's, when logged) filtered position and derivatives.
struct Signals {
  std::string name;
  double fs = 0;
  std::vector<double> t, qm, qL, u;        ///< as logged (u = gain·drive); qL empty: motor encoder alone
  std::vector<double> qmf, vm, am, Uf;     ///< filtered; Uf the held drive, filtered
  std::vector<double> sm_f;                ///< filtered sgn v̂m
  std::vector<signed char> sm;             ///< sgn v̂m, 0 at rest
  std::size_t begin = 0, end = 0;          ///< the filter's end transients left out
  std::size_t reach = 0;                   ///< the filter's length (+2): samples left out around a sign change
  measurements::ButterworthLowPass filter;
  double rest_speed = 0;
  bool load_logged() const { return !qL.empty(); }
  std::size_t size() const { return t.size(); }
};

/// The load's side: measured (both encoders) or observed (load_observer).
struct LoadSide {
  std::vector<double> qL, vL, aL, sL_f;  ///< position, filtered derivatives, filtered sgn v̂L
  std::vector<signed char> sL;
};

/// The filtered motor signals and the held drive through `filter` (effective length `edge`
/// samples: the ends and the neighbourhood of a change of sign left out by that much).
void filter_signals(Signals& s, const measurements::ButterworthLowPass& filter, std::size_t edge);

/// sgn v̂ with rest: the encoder's count unchanged over k−1, k, k+1 (when `counted`) or
/// |v̂| ≤ rest_speed.
std::vector<signed char> signs_of(const std::vector<double>& q, const std::vector<double>& v, double rest_speed, bool counted);

/// The load side from its position (filtered and differentiated as the motor's).
LoadSide load_side(const Signals& s, std::vector<double> qL, bool counted);

/// The residual at every sample.
std::vector<double> residuals(const Signals& s, const LoadSide& l, const Theta& m);

/// Least squares of the free parameters on `samples` (the others held); frictions < 0 refitted
/// at 0 (then `clamped`).  ok = false: no physical drive (an inertia ≤ 0 or a viscous friction < 0).
struct LinearFit {
  Theta m{};
  bool ok = false, clamped = false;
  double sse = INFINITY;
};
LinearFit solve(const Signals& s, const LoadSide& l, const Theta& start, const FreeSet& free,
                const std::vector<std::size_t>& samples);

/// The load's Coulomb friction per unit inertia β = TL/JL read on its coasting in flight (both
/// encoders): where the raw gap θL − θm lies inside the faces x0 ± b/2 by a margin (15 % of b
/// and two encoder counts) and the load moves one way, the load encoder follows
///   θL(t) = p + v0·(1 − e^{−αt})/α − β·sL·(t/α − (1 − e^{−αt})/α²),   α = FL/JL given,
/// linear in each flight's p, v0 and the shared β.  ΔBIC of β against β = 0 with n_eff = n/τ_int.
struct FlightFit {
  bool ok = false;           ///< enough flights (at least 20 samples in runs of 8 or more)
  double beta = 0, sigma = NAN, delta_bic = INFINITY;
  std::size_t samples = 0, flights = 0;
};
FlightFit flight_coulomb(const Signals& s, const LoadSide& l, double x0, double b, double alpha);

/// max(1, τ_int) of r (measurements::integrated_autocorrelation_time); 1 when r has fewer than
/// two samples or all its samples are equal (nothing correlated to count: a fit that is exact,
/// e.g. the gap of a rigid drive read on whole encoder counts).
double tau_int_or_one(const std::vector<double>& r);

/// Levenberg–Marquardt polish of `x` on `residual` (n residuals) and one σ per parameter:
/// Ceres's covariance (numeric central differences) scaled by the residual variance and τ_int.
/// `lower`: each parameter's lower bound (−∞: none); `relative_step` of the differences.
std::vector<double> ceres_sigma(const std::function<void(const double*, double*)>& residual, std::size_t n,
                                std::vector<double>& x, const std::vector<double>& lower, bool polish,
                                double relative_step = 1e-6);

/// The torque residual's noise level for the model m (two_body_noise.cpp; docs/discrepancy.md).
TwoBodyNoise noise_level(const Signals& s, const Theta& m);

/// The workflow (find_drive_discrepancy routes a case with backlash > 0 here).
DriveDiscrepancyResult find(const model::CaseSpec& spec, const measurements::MeasuredRecord& data, const DriveOptions& options);

}  // namespace backlash::discrepancy::two_body
