// numeric/evaluators/phi_kernels.hpp (internal) — the hot kernels of phi_functions.hpp as inline
// definitions: load_kernels and damped_pair (the closed forms' per-evaluation work) are inlined
// into StableSegments' evaluations (parametric.cpp), with the series and helpers they use; the
// out-of-line load_kernels and damped_pair (phi_functions.cpp) call these, so both are one
// definition and give the same bits.  The methods are documented in phi_functions.hpp.
#pragma once

#include "evaluators/phi_functions.hpp"

#include <array>
#include <cmath>

namespace backlash::numeric::detail {

inline constexpr int factorial_count = 40;

constexpr std::array<double, factorial_count> make_inverse_factorials() {
  std::array<double, factorial_count> out{};
  double f = 1.0;
  out[0] = 1.0;
  for (int k = 1; k < factorial_count; ++k) {
    f *= k;
    out[k] = 1.0 / f;
  }
  return out;
}
inline constexpr std::array<double, factorial_count> inverse_factorial = make_inverse_factorials();

// Σ_{j<terms} x^j/(j+n)! by Horner.
inline double phi_series(int n, double x, int terms) {
  double sum = inverse_factorial[n + terms - 1];
  for (int j = terms - 2; j >= 0; --j) sum = sum * x + inverse_factorial[n + j];
  return sum;
}

// Terms of Σ x^j/(j+n)! (n ≥ 1) for full double precision when |x| ≤ m ≤ 1:
// the first omitted term m^J/(J+1)! stays below 2^-56.
inline int series_terms(double m) {
  if (m <= 1.0 / 64) return 8;
  if (m <= 1.0 / 8) return 11;
  if (m <= 0.5) return 15;
  return 19;
}

// Σ_j h_j(x, y)/(j+n+1)! for n = 1 and 2 at once (max(|x|,|y|) ≤ m ≤ 1); the
// first omitted term (J+1)·m^J/(J+2)! stays below 2^-56.
inline void pair_series(double x, double y, double m, double& a1, double& a2) {
  const int terms = m <= 1.0 / 64 ? 7 : m <= 1.0 / 8 ? 10 : m <= 0.25 ? 13 : 23;
  double h = 1.0, xp = 1.0;
  a1 = inverse_factorial[2];
  a2 = inverse_factorial[3];
  for (int j = 1; j < terms; ++j) {
    xp *= x;
    h = xp + y * h;
    a1 += h * inverse_factorial[j + 2];
    a2 += h * inverse_factorial[j + 3];
  }
}

// e^x, φ1(x), φ2(x): one Horner series (φ1 = 1 + xφ2, e^x = 1 + xφ1) for
// |x| < 1/8; else expm1 and φ2 = (φ1 − 1)/x, which loses at most a factor 16.
// Inlined into the kernels (their two nodes: no call, no returned struct).
[[gnu::always_inline]] inline PhiPair phi_pair_of(double x) {
  const double ax = std::fabs(x);
  if (ax < 0.125) {
    const double phi2 = phi_series(2, x, series_terms(ax));
    const double phi1 = 1.0 + x * phi2;
    return {1.0 + x * phi1, phi1, phi2};
  }
  // one libm call: e^x − 1 does not cancel for x < −1, 1 + expm1(x) keeps e^x's
  // relative accuracy for x ≥ −1
  double e, em1;
  if (x < -1.0) {
    e = std::exp(x);
    em1 = e - 1.0;
  } else {
    em1 = std::expm1(x);
    e = em1 + 1.0;
  }
  const double phi1 = em1 / x;
  return {e, phi1, (phi1 - 1.0) / x};
}

// A0 = exp[x, y] = (e^x − e^y)/(x − y) of two close nodes (d = x − y ≠ 0): e^{(x+y)/2}·shc(d/2),
// shc(h) = sinh(h)/h by its series, for |d| < 1; else the difference quotient of px.e and py.e.
[[gnu::always_inline]] inline double exp_divided_difference(double x, double y, double d, const PhiPair& px,
                                                            const PhiPair& py) {
  const double half = 0.5 * d;
  if (std::fabs(half) < 0.5) {
    const double h2 = half * half;
    double shc = inverse_factorial[19];
    for (int j = 8; j >= 0; --j) shc = shc * h2 + inverse_factorial[2 * j + 1];
    return std::exp(0.5 * (x + y)) * shc;
  }
  return (px.e - py.e) / d;
}

// load_kernels (phi_functions.hpp).
[[gnu::always_inline]] inline LoadKernels load_kernels_of(double x, double y) {
  // Both nodes ±0 (a segment's start, t = 0): the values the series below give there, exactly
  // (each of its terms past the first is ±0 added to a nonzero constant).
  if (x == 0 && y == 0) return {1, 1, inverse_factorial[2], 1, 1, inverse_factorial[2], inverse_factorial[3]};
  const PhiPair px = phi_pair_of(x), py = phi_pair_of(y);
  LoadKernels k{px.e, px.phi1, px.phi2, py.e, py.phi1, 0, 0};
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double m = ax > ay ? ax : ay;
  const double d = x - y;
  if (m <= 0.25 || (m <= 1.0 && std::fabs(d) < 0.25 * m)) {
    pair_series(x, y, m, k.a1, k.a2);
  } else if (std::fabs(d) >= 0.25 * m) {
    // separated nodes (m > 1/4): the difference quotients lose at most ~100 ulp
    k.a1 = (px.phi1 - py.phi1) / d;
    k.a2 = (px.phi2 - py.phi2) / d;
  } else {
    // close nodes away from 0: A0 = exp[x, y], then peel the zeros off the larger node
    const double a0 = exp_divided_difference(x, y, d, px, py);
    const bool x_larger = ax >= ay;
    const double node = x_larger ? x : y;
    const PhiPair& other = x_larger ? py : px;
    k.a1 = (a0 - other.phi1) / node;
    k.a2 = (k.a1 - other.phi2) / node;
  }
  return k;
}

// damped_pair(rates, t) (phi_functions.hpp).
[[gnu::always_inline]] inline DampedPair damped_pair_of(const DampedRates& r, double t) {
  const double alpha = r.alpha;
  // t = ±0 (a segment's start): the series below gives C = 1, S = 1 and e^{−α·0} = 1 exactly,
  // so {1, 1·1·t} = {1, t}, its sign of zero too — for finite α and D (else NaN, as below).
  if (t == 0 && std::isfinite(alpha) && std::isfinite(r.D)) return {1, t};
  const double z = r.D * t * t;
  if (std::fabs(z) <= 0.25) {
    // C = Σ z^k/(2k)!, S/t = Σ z^k/(2k+1)!
    double c = inverse_factorial[20], s = inverse_factorial[21];
    for (int k = 9; k >= 0; --k) {
      c = c * z + inverse_factorial[2 * k];
      s = s * z + inverse_factorial[2 * k + 1];
    }
    const double decay = std::exp(-alpha * t);
    return {decay * c, decay * s * t};
  }
  if (z < 0) {
    const double omega = r.omega;
    const double decay = std::exp(-alpha * t);
    return {decay * std::cos(omega * t), decay * std::sin(omega * t) / omega};
  }
  const double delta = r.delta;
  if (delta * t <= 20.0) {
    const double decay = std::exp(-alpha * t);
    return {decay * std::cosh(delta * t), decay * std::sinh(delta * t) / delta};
  }
  // two real exponentials; the slow rate α − δ = w²/(α + δ) without cancellation
  const double slow = std::exp(-r.slow * t);
  const double fast = std::exp(-r.fast * t);
  return {0.5 * (slow + fast), 0.5 * (slow - fast) / delta};
}

}  // namespace backlash::numeric::detail
