#include "evaluators/phi_functions.hpp"

#include "evaluators/phi_kernels.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace backlash::numeric {

using detail::exp_divided_difference;
using detail::inverse_factorial;
using detail::phi_pair_of;
using detail::phi_series;
using detail::series_terms;

double phi(int n, double x) {
  if (n < 0 || n > 4) throw std::invalid_argument("phi: n must be 0..4");
  if (n == 0) return std::exp(x);
  if (std::fabs(x) < 1.0) return phi_series(n, x, series_terms(std::fabs(x)));
  double value = std::expm1(x) / x;  // φ_1
  for (int k = 1; k < n; ++k) value = (value - inverse_factorial[k]) / x;
  return value;
}

Phi12 phi12(double x) {
  const double ax = std::fabs(x);
  if (ax < 1.0) {
    const int terms = series_terms(ax);
    return {phi_series(1, x, terms), phi_series(2, x, terms)};
  }
  const double phi1 = std::expm1(x) / x;
  return {phi1, (phi1 - inverse_factorial[1]) / x};
}

double exp_divided_difference(int n, double x, double y) {
  if (n < 0 || n > 3) throw std::invalid_argument("exp_divided_difference: n must be 0..3");
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double m = ax > ay ? ax : ay;
  if (m <= 1.0) {
    // Σ_j h_j(x, y)/(j+n+1)!, h_j = Σ_{i≤j} x^i y^{j−i} = x^j + y·h_{j−1}.
    constexpr int terms = 24;
    double h = 1.0, xp = 1.0, sum = inverse_factorial[n + 1];
    for (int j = 1; j < terms; ++j) {
      xp *= x;
      h = xp + y * h;
      sum += h * inverse_factorial[j + n + 1];
    }
    return sum;
  }
  const double d = x - y;
  if (std::fabs(d) >= 0.25 * m) {
    // well separated nodes: the difference quotient is accurate
    if (n == 0) return (std::exp(x) - std::exp(y)) / d;
    return (phi(n, x) - phi(n, y)) / d;
  }
  // close nodes, both of magnitude > 3/4: A_0 from the midpoint, then peel zeros off.
  const double mid = 0.5 * (x + y), half = 0.5 * d;
  double a0;
  if (std::fabs(half) < 0.5) {
    const double h2 = half * half;
    // sinh(h)/h = Σ h^{2k}/(2k+1)!
    double shc = inverse_factorial[19];
    for (int k = 8; k >= 0; --k) shc = shc * h2 + inverse_factorial[2 * k + 1];
    a0 = std::exp(mid) * shc;
  } else {
    a0 = (std::exp(x) - std::exp(y)) / d;
  }
  // divide by the larger node: A_n = (A_{n−1} − φ_n(other))/(node)
  const double node = ax >= ay ? x : y, other = ax >= ay ? y : x;
  double value = a0;
  for (int k = 1; k <= n; ++k) value = (value - phi(k, other)) / node;
  return value;
}

PhiPair phi_pair(double x) { return phi_pair_of(x); }

ExpPhi1 exp_phi1(double x) {
  const PhiPair p = phi_pair_of(x);
  return {p.e, p.phi1};
}

LoadKernels load_kernels(double x, double y) { return detail::load_kernels_of(x, y); }

namespace {

// Σ_j h_j(x, y)/(j+n+1)! for n = 1, 2, 3 at once (max(|x|,|y|) ≤ m ≤ 1).
void triple_series(double x, double y, double m, double& a1, double& a2, double& a3) {
  const int terms = m <= 1.0 / 64 ? 7 : m <= 1.0 / 8 ? 10 : m <= 0.25 ? 13 : 23;
  double h = 1.0, xp = 1.0;
  a1 = inverse_factorial[2];
  a2 = inverse_factorial[3];
  a3 = inverse_factorial[4];
  for (int j = 1; j < terms; ++j) {
    xp *= x;
    h = xp + y * h;
    a1 += h * inverse_factorial[j + 2];
    a2 += h * inverse_factorial[j + 3];
    a3 += h * inverse_factorial[j + 4];
  }
}

// φ3 from φ2: the series below |x| = 1/8, the recurrence above (a factor ≤ 16 lost).
double phi3_from(double x, double phi2) {
  const double ax = std::fabs(x);
  return ax < 0.125 ? phi_series(3, x, series_terms(ax)) : (phi2 - 0.5) / x;
}

}  // namespace

CoupledKernels coupled_kernels(double x, double y) {
  const PhiPair px = phi_pair_of(x), py = phi_pair_of(y);
  CoupledKernels k{px.e, px.phi1, px.phi2, py.e, py.phi1, py.phi2, 0, 0, 0};
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double m = ax > ay ? ax : ay;
  const double d = x - y;
  if (m <= 0.25 || (m <= 1.0 && std::fabs(d) < 0.25 * m)) {
    triple_series(x, y, m, k.a1, k.a2, k.a3);
  } else if (std::fabs(d) >= 0.25 * m) {
    k.a1 = (px.phi1 - py.phi1) / d;
    k.a2 = (px.phi2 - py.phi2) / d;
    k.a3 = (phi3_from(x, px.phi2) - phi3_from(y, py.phi2)) / d;
  } else {
    const double a0 = exp_divided_difference(x, y, d, px, py);
    const bool x_larger = ax >= ay;
    const double node = x_larger ? x : y, other = x_larger ? y : x;
    const PhiPair& o = x_larger ? py : px;
    k.a1 = (a0 - o.phi1) / node;
    k.a2 = (k.a1 - o.phi2) / node;
    k.a3 = (k.a2 - phi3_from(other, o.phi2)) / node;
  }
  return k;
}

DampedRates damped_rates(double alpha, double w2) {
  DampedRates r;
  r.alpha = alpha;
  r.w2 = w2;
  r.D = alpha * alpha - w2;
  r.omega = std::sqrt(-r.D);  // NaN unless D ≤ 0, as √D is unless D ≥ 0: each is read only on its side
  r.delta = std::sqrt(r.D);
  r.fast = alpha + r.delta;
  r.slow = w2 / r.fast;
  return r;
}

DampedPair damped_pair(const DampedRates& r, double t) { return detail::damped_pair_of(r, t); }

DampedPair damped_pair(double alpha, double w2, double t) { return damped_pair(damped_rates(alpha, w2), t); }

}  // namespace backlash::numeric
