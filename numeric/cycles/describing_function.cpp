#include "backlash/numeric/describing_function.hpp"

#include "backlash/numeric/parametric.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::numeric {

std::complex<double> backlash_describing_function(double A, double b) {
  if (!(A > b / 2)) return {0.0, 0.0};
  const double beta = 1 - b / A;
  const double root = std::sqrt(std::max(0.0, 1 - beta * beta));
  const double re = (M_PI / 2 + std::asin(beta) + beta * root) / M_PI;
  const double im = -(1 - beta * beta) / M_PI;
  return {re, im};
}

std::optional<DescribingFunctionCycle> DescribingFunctionPrediction::predicted() const {
  std::optional<DescribingFunctionCycle> best;
  for (const DescribingFunctionCycle& c : cycles)
    if (c.stable && (!best || c.amplitude > best->amplitude)) best = c;
  return best;
}

namespace {

// Largest real part of the roots of J s² + F s + K N (N complex).
double growth_rate(double J, double F, double K, std::complex<double> N) {
  const std::complex<double> disc = std::sqrt(std::complex<double>(F * F, 0) - 4.0 * J * K * N);
  const std::complex<double> r1 = (-F + disc) / (2 * J), r2 = (-F - disc) / (2 * J);
  return std::max(r1.real(), r2.real());
}

// g(β) = Re N − c (Im N)², β = 1 − b/A ∈ (−1, 1), c = JK/F²: zero on a predicted cycle.
double balance(double beta, double c) {
  const double root = std::sqrt(std::max(0.0, 1 - beta * beta));
  const double re = (M_PI / 2 + std::asin(beta) + beta * root) / M_PI;
  const double im = -(1 - beta * beta) / M_PI;
  return re - c * im * im;
}

}  // namespace

DescribingFunctionPrediction describing_function_prediction(const Parameters& p) {
  DescribingFunctionPrediction out;
  if (p.measured_at != model::MeasuredAt::Load) {
    out.reason = "the backlash is outside the loop (output at the motor): the loop is linear, the describing function "
                 "predicts no cycle";
    return out;
  }
  if (!(p.backlash > 0)) {
    out.reason = "no backlash";
    return out;
  }
  out.applicable = true;
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, K = p.K, b = p.backlash;
  if (!(F > 0)) {
    out.reason = "no friction: G(jω) lies on the negative real axis and meets −1/N(A) nowhere";
    return out;
  }
  const double c = J * K / (F * F);
  const auto g = [c](double beta) { return balance(beta, c); };
  // scan with points clustered at both ends, refine by bisection
  const int n = 20000;
  double previous_beta = -1 + 1e-12, previous = g(previous_beta);
  for (int k = 1; k <= n; ++k) {
    const double u = static_cast<double>(k) / n;
    const double beta = -std::cos(M_PI * u) * (1 - 1e-12);
    const double value = g(beta);
    if ((previous < 0) != (value < 0)) {
      double lo = previous_beta, hi = beta, glo = previous;
      for (int it = 0; it < 200 && hi - lo > 1e-16; ++it) {
        const double mid = 0.5 * (lo + hi), gm = g(mid);
        if ((gm < 0) == (glo < 0)) { lo = mid; glo = gm; } else { hi = mid; }
      }
      const double beta_star = 0.5 * (lo + hi);
      DescribingFunctionCycle cycle;
      cycle.amplitude = b / (1 - beta_star);
      const std::complex<double> N = backlash_describing_function(cycle.amplitude, b);
      cycle.frequency = -K * N.imag() / F;
      cycle.period = 2 * M_PI / cycle.frequency;
      cycle.load_peak_to_peak = 2 * cycle.amplitude - b;
      cycle.motor_peak_to_peak = 2 * cycle.amplitude;
      const double above = cycle.amplitude * (1 + 1e-6);
      cycle.stable = growth_rate(J, F, K, backlash_describing_function(above, b)) < 0;
      out.cycles.push_back(cycle);
    }
    previous_beta = beta;
    previous = value;
  }
  if (out.cycles.empty()) out.reason = "−1/N(A) does not meet the Nyquist curve of G: no cycle predicted";
  return out;
}

// The cold guess's root of g (docs/design.md, "The limit-cycle contract"): the same bits as scanning the 64
// values β_k = −cos(πk/64)(1 − 1e-12) down from β = 1 for the first g(β_k) < 0 and bisecting
// [β_k, β_k+1] (to hi − lo ≤ 1e-15; β_64 = 1 − 1e-12), with fewer evaluations of g.  On
// (−π/(2c), 1) the exact g is increasing: g' = 2√(1 − β²)/π + 4cβ(1 − β²)/π² > 0.  The
// computed g differs from the exact one (with the same c and M_PI) by at most E (error_bound),
// so a computed g(x) < −2E proves the computed sign negative at every β ≤ x of the increasing
// range, and g(x) ≥ 2E non-negative at every β ≥ x: the scan becomes a binary search whose
// answer is certified that way, and the bisection's steps outside [r − δ, r + δ] around
// Newton's root r are known without evaluating g.  Anything not certified: the scan and the
// bisection as they were (check_describing_function_guess compares with them).
namespace {

constexpr int kGridPoints = 64;
constexpr double kTop = 1 - 1e-12;

double grid_beta(int k) { return -std::cos(M_PI * k / kGridPoints) * (1 - 1e-12); }

// A bound on |computed g − exact g| on [lo, hi] ⊂ (−1, 1): asin within 1 ulp, each operation
// rounded once, √ of 1 − β² (rounded) magnifies its error by 1/√(1 − β²); twice the sum.
double error_bound(double lo, double hi, double c) {
  const double u = 0x1p-53, x_min = 1 - std::max(lo * lo, hi * hi);
  const double im_max = (lo <= 0 && hi >= 0 ? 1 : 1 - std::min(lo * lo, hi * hi)) / M_PI;
  return 2 * u * (8 + 1 / std::sqrt(x_min) + c * (2 * im_max + 4 * im_max * im_max + u));
}

// A grid index inside the increasing range (β_k > −π/(4c), half its bound), near its lowest.
int lowest_increasing_index(double c) {
  const double floor_beta = -0.5 * M_PI / (2 * c);
  int k = std::max(1, static_cast<int>(std::ceil(kGridPoints / M_PI * std::acos(std::min(1.0, -floor_beta)))));
  while (k < kGridPoints - 1 && !(grid_beta(k) > floor_beta)) ++k;
  return k;
}

// The bisection from [lo, hi] as the scan runs it; the signs of g outside (a, b) are given.
double bisect(double lo, double hi, double c, double a = -INFINITY, double b = INFINITY) {
  for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    const bool negative = mid <= a ? true : mid >= b ? false : balance(mid, c) < 0;
    (negative ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// A point of the increasing range and the computed g there.
struct Sample {
  double beta, g;
};

// The exact g' at β (positive in the increasing range).
double balance_slope(double beta, double c) {
  const double x = 1 - beta * beta;
  return 2 * std::sqrt(x) / M_PI + 4 * c * beta * x / (M_PI * M_PI);
}

// Whether the computed g is negative on [lo, a] and non-negative on [b, hi]: g(a) < −2E on
// [lo, a], g(b) ≥ 2E on [b, b'] and g(b') ≥ 2E on [b', hi], b' = (b + hi)/2 (E grows without
// bound towards β = 1, where the top bracket ends: the far part gets its own bound).
bool certified_window(double lo, double hi, double a, double b, double c) {
  const double b_far = 0.5 * (b + hi);
  return balance(a, c) < -2 * error_bound(lo, a, c) && balance(b, c) >= 2 * error_bound(b, b_far, c) &&
         balance(b_far, c) >= 2 * error_bound(b_far, hi, c);
}

// The bisection of [lo, hi] (g(lo) < 0, both in the increasing range): the root r by Newton's
// method kept inside its bracket (a step out of it bisects), then a window [r − δ, r + δ] whose
// outside is certified (certified_window); without a certificate every step evaluates g.
double certified_bisection(Sample lo, Sample hi, double c) {
  double left = lo.beta, right = hi.beta, r = lo.beta - lo.g * (hi.beta - lo.beta) / (hi.g - lo.g), delta = INFINITY;
  for (int it = 0; it < 40 && r > left && r < right; ++it) {
    const double g = balance(r, c), slope = balance_slope(r, c);
    (g < 0 ? left : right) = r;
    delta = 4 * error_bound(r, r, c) / slope;
    double next = r - g / slope;
    if (!(next > left && next < right)) next = 0.5 * (left + right);
    const double step = std::fabs(next - r);
    r = next;
    if (!(step > delta / 8)) break;
  }
  for (int attempt = 0; attempt < 5 && std::isfinite(delta); ++attempt, delta *= 16) {
    const double a = r - delta, b = r + delta;
    if (!(a > lo.beta && b < hi.beta)) break;
    if (certified_window(lo.beta, hi.beta, a, b, c)) return bisect(lo.beta, hi.beta, c, a, b);
  }
  return bisect(lo.beta, hi.beta, c);
}

// The scan and the bisection as they were, from index k_from down under hi (every grid value).
double scanned_root(double c, int k_from, double hi) {
  for (int k = k_from; k >= 0; --k) {
    const double lo = grid_beta(k);
    if (balance(lo, c) < 0) return bisect(lo, hi, c);
    hi = lo;
  }
  return NAN;
}

// β of the root of largest amplitude: the scan's answer, NaN where it finds none.
double largest_root(double c) {
  Sample pos{grid_beta(kGridPoints - 1), 0};
  pos.g = balance(pos.beta, c);
  if (pos.g < 0) return certified_bisection(pos, {kTop, balance(kTop, c)}, c);
  const int k_low = lowest_increasing_index(c);
  Sample neg{grid_beta(k_low), 0};
  const double E = std::isfinite(c) ? error_bound(neg.beta, pos.beta, c) : INFINITY;
  if (!(k_low < kGridPoints - 1) || !std::isfinite(E) || !((neg.g = balance(neg.beta, c)) < 0))
    return scanned_root(c, kGridPoints - 2, pos.beta);
  for (int k_neg = k_low, k_pos = kGridPoints - 1; k_pos - k_neg > 1;) {
    const int k = (k_neg + k_pos) / 2;
    const Sample s{grid_beta(k), balance(grid_beta(k), c)};
    (s.g < 0 ? neg : pos) = s;
    (s.g < 0 ? k_neg : k_pos) = k;
  }
  // Every grid value above pos is non-negative when g(β_pos) ≥ 2E: the scan stops at neg too.
  if (!(pos.g >= 2 * E)) return scanned_root(c, kGridPoints - 2, grid_beta(kGridPoints - 1));
  return certified_bisection(neg, pos, c);
}

}  // namespace

double describing_function_separation_velocity(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, K = p.K, b = p.backlash;
  if (p.measured_at != model::MeasuredAt::Load || !(b > 0) || !(F > 0)) return 0;
  const double c = J * K / (F * F);
  // The root of largest amplitude (largest β): the first sign change coming down from β = 1.
  const double beta = largest_root(c);
  if (std::isnan(beta)) return 0;
  const double A = b / (1 - beta);
  const double omega = -K * backlash_describing_function(A, b).imag() / F;
  const double swing = A - b / 2, slope = omega * cot_phi(p);
  return omega * swing / std::sqrt(1 + slope * slope);
}

}  // namespace backlash::numeric
