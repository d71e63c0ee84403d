// check_parametric_as_before — the parametric closed forms after issue 19's per-evaluation cuts
// (the kernels' phi_pair inlined, the damped pair's D, √(−D), √D and rates formed once per
// parameter set) give the bits of the formulas they replace, kept here verbatim as the reference:
//   check_kernels_as_before   phi_pair, exp_phi1, load_kernels, coupled_kernels on random nodes
//                             across every branch (series, expm1/exp, separated, close, equal, 0;
//                             load_kernels' shortcut at x = y = ±0);
//   check_damped_pair_as_before
//                             damped_pair(α, w², t) and damped_pair(damped_rates(α, w²), t) on
//                             every branch (series, under-damped, cosh/sinh, two exponentials;
//                             the shortcut at t = ±0, with α or D not finite there too);
//   check_segments_as_before  StableSegments::free_state / contact_state, every component, on
//                             random parameter sets of both outputs (FL = 0, Fm = 0, equal rates,
//                             critical damping included).
#include "backlash/numeric/parametric.hpp"
#include "evaluators/phi_functions.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

namespace {

namespace n = backlash::numeric;

// ---- the formulas as they were (int36, numeric/evaluators/phi_functions.cpp) ----
constexpr std::array<double, 40> make_inverse_factorials() {
  std::array<double, 40> out{};
  double f = 1.0;
  out[0] = 1.0;
  for (int k = 1; k < 40; ++k) {
    f *= k;
    out[k] = 1.0 / f;
  }
  return out;
}
constexpr std::array<double, 40> inverse_factorial = make_inverse_factorials();

double phi_series(int n, double x, int terms) {
  double sum = inverse_factorial[n + terms - 1];
  for (int j = terms - 2; j >= 0; --j) sum = sum * x + inverse_factorial[n + j];
  return sum;
}
int series_terms(double m) {
  if (m <= 1.0 / 64) return 8;
  if (m <= 1.0 / 8) return 11;
  if (m <= 0.5) return 15;
  return 19;
}
n::PhiPair old_phi_pair(double x) {
  const double ax = std::fabs(x);
  if (ax < 0.125) {
    const double phi2 = phi_series(2, x, series_terms(ax));
    const double phi1 = 1.0 + x * phi2;
    return {1.0 + x * phi1, phi1, phi2};
  }
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
int pair_terms(double m) { return m <= 1.0 / 64 ? 7 : m <= 1.0 / 8 ? 10 : m <= 0.25 ? 13 : 23; }
double shc_a0(double x, double y, double d, double ex, double ey) {
  const double half = 0.5 * d;
  if (std::fabs(half) < 0.5) {
    const double h2 = half * half;
    double shc = inverse_factorial[19];
    for (int j = 8; j >= 0; --j) shc = shc * h2 + inverse_factorial[2 * j + 1];
    return std::exp(0.5 * (x + y)) * shc;
  }
  return (ex - ey) / d;
}
n::LoadKernels old_load_kernels(double x, double y) {
  const n::PhiPair px = old_phi_pair(x), py = old_phi_pair(y);
  n::LoadKernels k{px.e, px.phi1, px.phi2, py.e, py.phi1, 0, 0};
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double m = ax > ay ? ax : ay;
  const double d = x - y;
  if (m <= 0.25 || (m <= 1.0 && std::fabs(d) < 0.25 * m)) {
    double h = 1.0, xp = 1.0;
    k.a1 = inverse_factorial[2];
    k.a2 = inverse_factorial[3];
    for (int j = 1; j < pair_terms(m); ++j) {
      xp *= x;
      h = xp + y * h;
      k.a1 += h * inverse_factorial[j + 2];
      k.a2 += h * inverse_factorial[j + 3];
    }
  } else if (std::fabs(d) >= 0.25 * m) {
    k.a1 = (px.phi1 - py.phi1) / d;
    k.a2 = (px.phi2 - py.phi2) / d;
  } else {
    const double a0 = shc_a0(x, y, d, px.e, py.e);
    const bool x_larger = ax >= ay;
    const double node = x_larger ? x : y;
    const n::PhiPair& other = x_larger ? py : px;
    k.a1 = (a0 - other.phi1) / node;
    k.a2 = (k.a1 - other.phi2) / node;
  }
  return k;
}
double old_phi3_from(double x, double phi2) {
  const double ax = std::fabs(x);
  return ax < 0.125 ? phi_series(3, x, series_terms(ax)) : (phi2 - 0.5) / x;
}
n::CoupledKernels old_coupled_kernels(double x, double y) {
  const n::PhiPair px = old_phi_pair(x), py = old_phi_pair(y);
  n::CoupledKernels k{px.e, px.phi1, px.phi2, py.e, py.phi1, py.phi2, 0, 0, 0};
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double m = ax > ay ? ax : ay;
  const double d = x - y;
  if (m <= 0.25 || (m <= 1.0 && std::fabs(d) < 0.25 * m)) {
    double h = 1.0, xp = 1.0;
    k.a1 = inverse_factorial[2];
    k.a2 = inverse_factorial[3];
    k.a3 = inverse_factorial[4];
    for (int j = 1; j < pair_terms(m); ++j) {
      xp *= x;
      h = xp + y * h;
      k.a1 += h * inverse_factorial[j + 2];
      k.a2 += h * inverse_factorial[j + 3];
      k.a3 += h * inverse_factorial[j + 4];
    }
  } else if (std::fabs(d) >= 0.25 * m) {
    k.a1 = (px.phi1 - py.phi1) / d;
    k.a2 = (px.phi2 - py.phi2) / d;
    k.a3 = (old_phi3_from(x, px.phi2) - old_phi3_from(y, py.phi2)) / d;
  } else {
    const double a0 = shc_a0(x, y, d, px.e, py.e);
    const bool x_larger = ax >= ay;
    const double node = x_larger ? x : y, other = x_larger ? y : x;
    const n::PhiPair& o = x_larger ? py : px;
    k.a1 = (a0 - o.phi1) / node;
    k.a2 = (k.a1 - o.phi2) / node;
    k.a3 = (k.a2 - old_phi3_from(other, o.phi2)) / node;
  }
  return k;
}
n::DampedPair old_damped_pair(double alpha, double w2, double t) {
  const double D = alpha * alpha - w2;
  const double z = D * t * t;
  if (std::fabs(z) <= 0.25) {
    double c = inverse_factorial[20], s = inverse_factorial[21];
    for (int k = 9; k >= 0; --k) {
      c = c * z + inverse_factorial[2 * k];
      s = s * z + inverse_factorial[2 * k + 1];
    }
    const double decay = std::exp(-alpha * t);
    return {decay * c, decay * s * t};
  }
  if (z < 0) {
    const double omega = std::sqrt(-D);
    const double decay = std::exp(-alpha * t);
    return {decay * std::cos(omega * t), decay * std::sin(omega * t) / omega};
  }
  const double delta = std::sqrt(D);
  if (delta * t <= 20.0) {
    const double decay = std::exp(-alpha * t);
    return {decay * std::cosh(delta * t), decay * std::sinh(delta * t) / delta};
  }
  const double slow = std::exp(-(w2 / (alpha + delta)) * t);
  const double fast = std::exp(-(alpha + delta) * t);
  return {0.5 * (slow + fast), 0.5 * (slow - fast) / delta};
}
// StableSegments::free_state / contact_state as they were (int36, numeric/evaluators/parametric.cpp).
n::FreeState old_free_state(const n::Parameters& p, double t, double v0) {
  const double cot = n::cot_phi(p), a = p.Fm / p.Jm, b = p.FL / p.JL, k = p.K / p.Jm;
  const double a_minus_b = a - b, gap_factor = k - b * a_minus_b;
  const double alpha_m = p.Fm / (2 * p.Jm), w2_m = p.K / p.Jm;
  n::FreeState s;
  const double y = -b * t;
  const double theta0 = p.theta_R + cot * v0;
  if (p.measured_at == backlash::model::MeasuredAt::Load) {
    const n::LoadKernels q = old_load_kernels(-a * t, y);
    const double t2 = t * t, t3 = t2 * t;
    s.theta_L = theta0 + v0 * t * q.phi1_y;
    s.dtheta_L = v0 * q.exp_y;
    s.theta_m = theta0 + v0 * (t * q.phi1_x + a_minus_b * t2 * q.phi2_x - k * t3 * q.a2);
    s.dtheta_m = v0 * (q.exp_x + a_minus_b * t * q.phi1_x - k * t2 * q.a1);
    s.gap = v0 * gap_factor * t3 * q.a2;
  } else {
    const n::PhiPair load = old_phi_pair(y);
    s.theta_L = theta0 + v0 * t * load.phi1;
    s.dtheta_L = v0 * load.e;
    const double e0 = theta0 - p.theta_R;
    const n::DampedPair q = old_damped_pair(alpha_m, w2_m, t);
    const double e = e0 * q.c + (v0 + alpha_m * e0) * q.s;
    s.theta_m = p.theta_R + e;
    s.dtheta_m = v0 * q.c - (alpha_m * v0 + w2_m * e0) * q.s;
    s.gap = e0 + v0 * t * load.phi1 - e;
  }
  return s;
}
n::ContactState old_contact_state(const n::Parameters& p, double t, double theta_o0, double dtheta_o0) {
  const double alpha_c = (p.Fm + p.FL) / (2 * (p.Jm + p.JL)), w2_c = p.K / (p.Jm + p.JL);
  const double e0 = theta_o0 - p.theta_R;
  const n::DampedPair q = old_damped_pair(alpha_c, w2_c, t);
  return {p.theta_R + e0 * q.c + (dtheta_o0 + alpha_c * e0) * q.s,
          dtheta_o0 * q.c - (alpha_c * dtheta_o0 + w2_c * e0) * q.s};
}
// ---- end of the reference ----

std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }
#define EXPECT_BITS(a, b) EXPECT_EQ(bits(a), bits(b)) << #a << " = " << (a) << " vs " << (b)

// A node of every kind: 0, ±0, tiny, around the switches 1/64, 1/8, 1/4, 1, large, up to ±60.
double random_node(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> kind(0, 9);
  switch (kind(rng)) {
    case 0: return 0.0;
    case 1: return -0.0;
    case 2: return u(rng) * 1e-6;
    case 3: return u(rng) / 64;
    case 4: return u(rng) / 8;
    case 5: return u(rng) / 4;
    case 6: return u(rng);
    case 7: return u(rng) * 2;
    case 8: return u(rng) * 10;
    default: return u(rng) * 60;
  }
}

TEST(ParametricAsBefore, check_kernels_as_before) {
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> relation(0, 3);
  for (int i = 0; i < 400000; ++i) {
    const double x = random_node(rng);
    double y = random_node(rng);
    const int r = relation(rng);
    if (r == 1) y = x;                                    // equal nodes
    else if (r == 2) y = x * (1 + 0.2 * u(rng));          // close nodes
    else if (r == 3) y = x * (1 + 1e-9 * u(rng));         // very close nodes
    const n::PhiPair p = n::phi_pair(x), op = old_phi_pair(x);
    EXPECT_BITS(p.e, op.e);
    EXPECT_BITS(p.phi1, op.phi1);
    EXPECT_BITS(p.phi2, op.phi2);
    const n::ExpPhi1 e = n::exp_phi1(x);
    EXPECT_BITS(e.exp_x, op.e);
    EXPECT_BITS(e.phi1_x, op.phi1);
    const n::LoadKernels k = n::load_kernels(x, y), ok = old_load_kernels(x, y);
    const double* a = &k.exp_x;
    const double* b = &ok.exp_x;
    for (int j = 0; j < 7; ++j) EXPECT_BITS(a[j], b[j]) << " component " << j << " at " << x << ", " << y;
    const n::CoupledKernels c = n::coupled_kernels(x, y), oc = old_coupled_kernels(x, y);
    a = &c.exp_x;
    b = &oc.exp_x;
    for (int j = 0; j < 9; ++j) EXPECT_BITS(a[j], b[j]) << " component " << j << " at " << x << ", " << y;
    if (HasFailure()) return;
  }
}

TEST(ParametricAsBefore, check_damped_pair_as_before) {
  std::mt19937_64 rng(20);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<int> kind(0, 4);
  for (int i = 0; i < 400000; ++i) {
    const double alpha = std::pow(10.0, 4 * u(rng) - 2) * (i % 17 == 0 ? 0 : 1);
    double w2 = 0;
    switch (kind(rng)) {
      case 0: w2 = alpha * alpha; break;                               // critical
      case 1: w2 = alpha * alpha * (1 + 1e-12 * (u(rng) - 0.5)); break;  // nearly critical
      case 2: w2 = alpha * alpha * (1 + 4 * u(rng)); break;            // under-damped
      case 3: w2 = alpha * alpha * u(rng); break;                      // over-damped
      default: w2 = std::pow(10.0, 6 * u(rng) - 3); break;
    }
    // t = ±0 (damped_pair's shortcut at a segment's start), α and D not finite there too
    const double t = i % 101 == 0 ? (i % 202 == 0 ? 0.0 : -0.0) : std::pow(10.0, 6 * u(rng) - 3);
    if (t == 0 && i % 5 == 0) w2 = i % 10 == 0 ? INFINITY : NAN;
    const n::DampedPair a = n::damped_pair(alpha, w2, t), b = n::damped_pair(n::damped_rates(alpha, w2), t);
    const n::DampedPair o = old_damped_pair(alpha, w2, t);
    EXPECT_BITS(a.c, o.c);
    EXPECT_BITS(a.s, o.s);
    EXPECT_BITS(b.c, o.c);
    EXPECT_BITS(b.s, o.s);
    if (HasFailure()) return;
  }
}

TEST(ParametricAsBefore, check_segments_as_before) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<int> kind(0, 5);
  for (int set = 0; set < 4000; ++set) {
    n::Parameters p;
    p.Jm = std::pow(10.0, 2 * u(rng) - 1);
    p.JL = std::pow(10.0, 2 * u(rng) - 1);
    p.K = std::pow(10.0, 2 * u(rng) - 1);
    p.Fm = std::pow(10.0, 3 * u(rng) - 2);
    p.FL = std::pow(10.0, 3 * u(rng) - 2);
    switch (kind(rng)) {
      case 0: p.FL = 0; break;
      case 1: p.Fm = 0; break;
      case 2: p.FL = p.Fm * p.JL / p.Jm; break;                 // equal rates
      case 3: p.Fm = 2 * std::sqrt(p.Jm * p.K); break;          // motor critical
      case 4: p.FL = 2 * std::sqrt((p.Jm + p.JL) * p.K) - p.Fm; break;  // contact critical
      default: break;
    }
    p.theta_R = set % 7 == 0 ? 0.0 : 4 * u(rng) - 2;  // θR = 0: the signs of zeros at t = ±0
    p.measured_at = set % 2 ? backlash::model::MeasuredAt::Motor : backlash::model::MeasuredAt::Load;
    const n::StableSegments segments(p);
    for (int i = 0; i < 100; ++i) {
      const double t = i == 0 ? 0.0 : i == 1 ? -0.0 : std::pow(10.0, 5 * u(rng) - 3);
      const double v0 = i == 2 ? 0.0 : 4 * u(rng) - 2, x0 = i == 3 ? p.theta_R : p.theta_R + 4 * u(rng) - 2;
      const n::FreeState f = segments.free_state(t, v0), of = old_free_state(p, t, v0);
      EXPECT_BITS(f.theta_m, of.theta_m);
      EXPECT_BITS(f.dtheta_m, of.dtheta_m);
      EXPECT_BITS(f.theta_L, of.theta_L);
      EXPECT_BITS(f.dtheta_L, of.dtheta_L);
      EXPECT_BITS(f.gap, of.gap);
      const n::ContactState c = segments.contact_state(t, x0, v0), oc = old_contact_state(p, t, x0, v0);
      EXPECT_BITS(c.theta_o, oc.theta_o);
      EXPECT_BITS(c.dtheta_o, oc.dtheta_o);
      if (HasFailure()) return;
    }
  }
}

}  // namespace
