// numeric/evaluators/phi_functions.hpp (internal) — the stable building blocks of the
// parametric evaluators.
//
// Every segment solution is a combination of divided differences of the
// exponential e^{st} over the poles of its transform: the inverse Laplace
// transform of 1/∏(s − p_i) is the divided difference e^{·t}[p_1, …, p_n]
// (confluent where poles repeat).  Written that way a solution is continuous
// in the parameters — merging poles merge the divided difference's nodes
// instead of blowing up partial-fraction coefficients like 1/(p_1 − p_2)².
// With x = p·t the divided differences we need are
//
//   φ_n(x)      = Σ_{j≥0} x^j/(j+n)!          = exp[0^n, x]   (φ_0 = e^x, φ_1 = expm1(x)/x)
//   A_n(x, y)   = exp[0^n, x, y]               = (φ_n(x) − φ_n(y))/(x − y)
//
// evaluated without cancellation:
//   φ_n:  |x| < 1 → the Taylor series (Horner, 8–19 terms by |x|);
//         else     → φ_1 = expm1(x)/x and the recurrence φ_{n+1} = (φ_n − 1/n!)/x
//                    (cancellation bounded by a factor e for |x| ≥ 1).
//         (load_kernels, the hot path, switches at |x| = 1/8 for φ1, φ2: one
//         series below, expm1 and one division above — a factor ≤ 16 lost.)
//   A_n:  max(|x|,|y|) ≤ 1/4, or ≤ 1 with close nodes
//                                 → Σ_j h_j(x,y)/(j+n+1)!, h_j the complete
//                                   homogeneous polynomial (7–23 terms by size);
//         |x − y| ≥ max(|x|,|y|)/4 → the difference quotient of φ_n (loses at most
//                                   ~100 ulp: the nodes are well separated);
//         otherwise (close nodes, away from 0) → A_0 = e^m·sinh(h)/h with
//                                   m = (x+y)/2, h = (x−y)/2 (series for small h),
//                                   then A_n = (A_{n−1} − φ_n(x))/y, which is
//                                   stable because |y| ≥ 3/4 there.
// For a second-order factor y'' + 2αy' + w²y (poles −α ± sqrt(α² − w²)) the
// response is written with C(t) = cosh(sqrt(D) t) and S(t) = sinh(sqrt(D) t)/sqrt(D),
// D = α² − w², which are entire functions of z = D t²: C = Σ z^k/(2k)!,
// S = t·Σ z^k/(2k+1)!.  Series for |z| ≤ 1/4, cos/sin(ω t)/ω for D < 0,
// cosh/sinh for D > 0 (and, for δt > 20, the two exponentials with the slow
// rate α − δ formed as w²/(α + δ) so it never cancels) — so under-damped,
// critically damped and over-damped are one continuous function and the
// critical case is the limit, not a special formula.
#pragma once

#include "backlash/numeric/parametric.hpp"  // DampedRates

namespace backlash::numeric {

/// φ_n(x) = Σ_{j≥0} x^j/(j+n)!, n = 0…4 (accurate to a few ulps for x ≤ 0 and moderate x > 0).
double phi(int n, double x);

/// φ1(x) and φ2(x), phi(1, x) and phi(2, x) bit for bit, with one expm1 for |x| ≥ 1 (phi(2, x)
/// forms φ1 on its way: φ2 = (φ1 − 1)/x) and one choice of series length below.
struct Phi12 {
  double phi1, phi2;
};
Phi12 phi12(double x);

/// exp[0^n, x, y]: the divided difference of exp over n zeros and x, y; n = 0…3.
double exp_divided_difference(int n, double x, double y);

/// e^x, φ1(x), φ2(x) with one libm call (coupled_kernels' own, bit for bit: a flow that needs
/// only one node's kernels computes just those).
struct PhiPair {
  double e, phi1, phi2;
};
PhiPair phi_pair(double x);

/// e^x and φ1(x) with one libm call.
struct ExpPhi1 {
  double exp_x, phi1_x;
};
ExpPhi1 exp_phi1(double x);

/// Everything the output-at-load free mode needs at x = −a·t, y = −b·t, computed
/// together (two expm1 calls in the generic case): e^x, φ1(x), φ2(x), e^y,
/// φ1(y), A1 = exp[0, x, y], A2 = exp[0, 0, x, y].
struct LoadKernels {
  double exp_x, phi1_x, phi2_x, exp_y, phi1_y, a1, a2;
};
LoadKernels load_kernels(double x, double y);

/// Everything a free flight with constant forcing needs at x = −a·t, y = −b·t (the motor
/// driven by a load that coasts under a constant torque, effect_modes.hpp), with two libm
/// calls: e^x, φ1(x), φ2(x), e^y, φ1(y), φ2(y), A1, A2, A3 = exp[0^n, x, y].
struct CoupledKernels {
  double exp_x, phi1_x, phi2_x, exp_y, phi1_y, phi2_y, a1, a2, a3;
};
CoupledKernels coupled_kernels(double x, double y);

/// e^{-αt}·C(t) and e^{-αt}·S(t) of y'' + 2αy' + w²y = 0 (α ≥ 0, w² ≥ 0):
///   y(t)  = y0·c + (ẏ0 + α y0)·s,    ẏ(t) = ẏ0·c − (α ẏ0 + w² y0)·s.
struct DampedPair {
  double c, s;
};
DampedPair damped_pair(double alpha, double w2, double t);

/// The parameter-only part of damped_pair(α, w², t), formed once: damped_pair(damped_rates(α, w²), t)
/// is damped_pair(α, w², t) bit for bit (the same expressions in the same order).
DampedRates damped_rates(double alpha, double w2);
DampedPair damped_pair(const DampedRates& rates, double t);

}  // namespace backlash::numeric
