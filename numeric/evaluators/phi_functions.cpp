#include "evaluators/phi_functions.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace backlash::numeric {

namespace {

constexpr int factorial_count = 40;

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
constexpr std::array<double, factorial_count> inverse_factorial = make_inverse_factorials();

// Σ_{j<terms} x^j/(j+n)! by Horner.
double phi_series(int n, double x, int terms) {
  double sum = inverse_factorial[n + terms - 1];
  for (int j = terms - 2; j >= 0; --j) sum = sum * x + inverse_factorial[n + j];
  return sum;
}

// Terms of Σ x^j/(j+n)! (n ≥ 1) for full double precision when |x| ≤ m ≤ 1:
// the first omitted term m^J/(J+1)! stays below 2^-56.
int series_terms(double m) {
  if (m <= 1.0 / 64) return 8;
  if (m <= 1.0 / 8) return 11;
  if (m <= 0.5) return 15;
  return 19;
}

}  // namespace

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

namespace {

// Σ_j h_j(x, y)/(j+n+1)! for n = 1 and 2 at once (max(|x|,|y|) ≤ m ≤ 1); the
// first omitted term (J+1)·m^J/(J+2)! stays below 2^-56.
void pair_series(double x, double y, double m, double& a1, double& a2) {
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

}  // namespace

namespace {

// e^x, φ1(x), φ2(x): one Horner series (φ1 = 1 + xφ2, e^x = 1 + xφ1) for
// |x| < 1/8; else expm1 and φ2 = (φ1 − 1)/x, which loses at most a factor 16.
// Inlined into the kernels below (their two nodes: no call, no returned struct).
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

}  // namespace

PhiPair phi_pair(double x) { return phi_pair_of(x); }

ExpPhi1 exp_phi1(double x) {
  const PhiPair p = phi_pair_of(x);
  return {p.e, p.phi1};
}

LoadKernels load_kernels(double x, double y) {
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
    const double half = 0.5 * d;
    double a0;
    if (std::fabs(half) < 0.5) {
      const double h2 = half * half;
      double shc = inverse_factorial[19];
      for (int j = 8; j >= 0; --j) shc = shc * h2 + inverse_factorial[2 * j + 1];
      a0 = std::exp(0.5 * (x + y)) * shc;
    } else {
      a0 = (px.e - py.e) / d;
    }
    const bool x_larger = ax >= ay;
    const double node = x_larger ? x : y;
    const PhiPair& other = x_larger ? py : px;
    k.a1 = (a0 - other.phi1) / node;
    k.a2 = (k.a1 - other.phi2) / node;
  }
  return k;
}

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
    const double half = 0.5 * d;
    double a0;
    if (std::fabs(half) < 0.5) {
      const double h2 = half * half;
      double shc = inverse_factorial[19];
      for (int j = 8; j >= 0; --j) shc = shc * h2 + inverse_factorial[2 * j + 1];
      a0 = std::exp(0.5 * (x + y)) * shc;
    } else {
      a0 = (px.e - py.e) / d;
    }
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

DampedPair damped_pair(const DampedRates& r, double t) {
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

DampedPair damped_pair(double alpha, double w2, double t) { return damped_pair(damped_rates(alpha, w2), t); }

}  // namespace backlash::numeric
