#include "backlash/numeric/first_crossing.hpp"

#include "hybrid/balancing.hpp"

#include <boost/math/tools/roots.hpp>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace backlash::numeric {

namespace {

struct Sample {
  double t, w, w1, w2, rate_norm;  // w and its first two derivatives, ‖D x'(t)‖∞
};

// The logarithmic norm μ∞(A) = max_i (a_ii + Σ_{j≠i} |a_ij|): ‖e^{At}‖∞ ≤ e^{μ∞(A) t} for t ≥ 0
// (Dahlquist).  It is never larger than ‖A‖∞ and, unlike it, is not inflated by a fast decaying
// mode (a load whose friction stops it in microseconds has a_33 = −FL/JL ≪ 0): the growth bound
// of a stiff segment then allows intervals on the slow time scale instead of the fast one.
double log_norm(const SmallMatrix& A) {
  double mu = -INFINITY;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    double row = A(i, i);
    for (Eigen::Index j = 0; j < A.cols(); ++j)
      if (j != i) row += std::fabs(A(i, j));
    mu = std::max(mu, row);
  }
  return A.rows() > 0 ? mu : 0.0;
}

// A stiff segment's state mixes scales: in contact x = (θ, θ̇) with θ̇ ~ √(K/J)·θ, and A has
// the entry K/J.  Measured in ‖·‖∞ the growth bound e^{μ∞(A) h} then allows intervals of
// 1/μ∞(A) ~ J/K (1e-12 s for K = 1e12) where the motion's time scale is √(J/K) (1e-6 s): the
// search bisects a million times too deep, and stops at min_interval as a false "grazing".
// The same bound holds in any diagonally scaled norm ‖D·‖∞ (ẑ = D z obeys ẑ' = D A D⁻¹ ẑ), and
// with D balancing A (Osborne's iteration, the LAPACK gebal rule, powers of two: exact) μ∞ is
// √(K/J) again.  The scaling is taken only when it lowers μ∞ by more than kBalanceGain: for
// matrices with entries of one scale (the thesis's cases) the bound, and so every interval
// and event time, stays exactly the unscaled one.
constexpr double kBalanceGain = 16;

struct Witness {
  const LinearWitness& lw;
  SmallRow eA, eA2, eA3;
  SmallVector scale;  // D: the bounds are in ‖D·‖∞
  double eAc, eA2c, mu_A, norm_c, norm_eA2, norm_eA3;

  explicit Witness(const LinearWitness& w) : lw(w) {
    eA = w.e * w.A;
    eA2 = eA * w.A;
    eA3 = eA2 * w.A;
    eAc = eA.dot(w.c);
    eA2c = eA2.dot(w.c);
    mu_A = log_norm(w.A);
    scale = SmallVector::Ones(w.A.rows());
    if (mu_A > 0) {
      const SmallVector d = detail::balancing(w.A);
      const SmallMatrix balanced = d.asDiagonal() * w.A * d.cwiseInverse().asDiagonal();
      const double mu_balanced = log_norm(balanced);
      if (mu_balanced * kBalanceGain < mu_A) {
        scale = d;
        mu_A = mu_balanced;
      }
    }
    norm_c = w.c.cwiseAbs().maxCoeff();
    norm_eA2 = eA2.cwiseQuotient(scale.transpose()).cwiseAbs().sum();
    norm_eA3 = eA3.cwiseQuotient(scale.transpose()).cwiseAbs().sum();
  }

  // ‖D z‖∞
  double rate_norm(const SmallVector& z) const { return z.cwiseProduct(scale).cwiseAbs().maxCoeff(); }

  Sample at(double t) const {
    const SmallVector x = lw.state(t);
    const double w = (lw.value ? lw.value(t) : lw.e.dot(x)) - lw.level;
    const double w1 = eA.dot(x) + lw.e.dot(lw.c);
    const double w2 = eA2.dot(x) + eAc;
    const SmallVector z = lw.A * x + lw.c;  // x' obeys z' = A z
    return {t, w, w1, w2, rate_norm(z)};
  }

  // sup |w'''| on [a.t, a.t + h]: w''' = eA² z = (eA² D⁻¹)(D z) and ‖D z(t)‖∞ ≤
  // e^{μ∞(DAD⁻¹)(t−a)} ‖D z(a)‖∞ (the supremum of e^{μ s} over s ∈ [0, h] is 1 when μ ≤ 0).
  double third_bound(const Sample& a, double h) const {
    return norm_eA2 * std::exp(std::max(0.0, mu_A) * h) * a.rate_norm;
  }
};

bool same_sign(double x, double y) { return (x > 0 && y > 0) || (x < 0 && y < 0); }

// Whether w''(0) is resolved from the error of the start's time.  The flight starts at an event
// located to a tolerance δt (CrossingOptions::time_tolerance relative to the time unit, times
// the segment's length in units): a start shifted by δt along the motion has w''(0) moved by
// w'''·δt.  On the separation line w''(0) = 0 exactly, and what is computed there is that shift,
// of order 0.1 rad/s² for K = 1e12 (w''' ~ 1e19 rad/s³, δt ~ 1e-20 s).  Taken as the leading
// term it certifies a departure of only ~|w''/w'''| (5e-21 s), and the search from there finds
// the spurious zero of w''t²/2 + w'''t³/6 at −3w''/w''' as a return to the face just left: a
// flight of no length (docs/physics.md, leaving a face).  A bounce's w''(0) (the torque after
// the impact) is a genuine leading term however small, as long as it exceeds that shift.
constexpr double kStartTimeUncertainty = 1e-12;  // in time units: 100 × time_tolerance

bool quadratic_resolved(double second, double third, double time_unit) {
  if (!std::isfinite(third)) return true;
  return std::fabs(second) > std::fabs(third) * kStartTimeUncertainty * time_unit;
}

}  // namespace

std::optional<double> certified_departure(const LinearWitness& witness, double noise) {
  const Witness W(witness);
  const SmallVector x0 = witness.state(0);
  const double z0 = W.rate_norm(witness.A * x0 + witness.c);  // ‖D x'(0)‖∞, with ‖D x'(t)‖∞ ≤ e^{μ t} z0
  const double second = W.eA.dot(witness.A * x0 + witness.c);           // w''(0) = eA x'(0)
  const double third = W.eA2.dot(witness.A * x0 + witness.c);           // w'''(0) = eA² x'(0)
  const double scale = std::max(std::fabs(second), 1e-300);
  const double growth = std::max(0.0, W.mu_A);  // ‖D x'(t)‖∞ ≤ e^{μ∞(DAD⁻¹) t} z0
  // w'' dominant: |w''(0)| > t0 sup|w'''|, sup|w'''| ≤ ‖eA²‖ e^{μ t0} z0.
  if (std::fabs(second) > 1e-12 * std::max(1.0, z0) && quadratic_resolved(second, third, witness.time_unit)) {
    double t0 = std::sqrt(2 * noise / scale);
    for (int attempt = 0; attempt < 60; ++attempt, t0 *= 0.5)
      if (std::fabs(second) > t0 * W.norm_eA2 * std::exp(growth * t0) * z0) return t0;
    return std::nullopt;
  }
  if (third == 0 || !std::isfinite(third)) return std::nullopt;
  // w''' dominant (w'' = 0): |w'''(0)| > t0 sup|w''''|, sup|w''''| ≤ ‖eA³‖ e^{μ t0} z0.
  double t0 = std::cbrt(6 * noise / std::fabs(third));
  for (int attempt = 0; attempt < 60; ++attempt, t0 *= 0.5)
    if (std::fabs(third) > t0 * W.norm_eA3 * std::exp(growth * t0) * z0) return t0;
  return std::nullopt;
}

std::optional<Crossing> first_crossing(const LinearWitness& witness, double t_begin, double t_end,
                                       const CrossingOptions& options) {
  if (!(t_end > t_begin)) return std::nullopt;
  const Witness W(witness);
  long examined = 0;
  // Depth-first, left half first: a stack of intervals whose top is the leftmost.
  std::vector<std::pair<Sample, Sample>> stack;
  stack.push_back({W.at(t_begin), W.at(t_end)});
  while (!stack.empty()) {
    if (++examined > options.max_intervals)
      throw SearchBudgetExhausted("the certified event search exhausted its budget of " +
                                  std::to_string(options.max_intervals) + " intervals");
    auto [a, b] = stack.back();
    stack.pop_back();
    if (!std::isfinite(a.w) || !std::isfinite(b.w)) throw std::runtime_error("first_crossing: non-finite witness");
    if (a.w == 0 && a.t > t_begin) return Crossing{a.t, false, examined};
    const double h = b.t - a.t;
    const double M3 = witness.third_derivative_bound ? witness.third_derivative_bound(a.t, b.t) : W.third_bound(a, h);
    const double M2 = 0.5 * (std::fabs(a.w2) + std::fabs(b.w2) + h * M3);
    const double M1 = 0.5 * (std::fabs(a.w1) + std::fabs(b.w1) + h * M2);
    const bool sign_change = !same_sign(a.w, b.w);
    if (!sign_change && std::fabs(a.w) + std::fabs(b.w) > h * M1) continue;  // excluded
    const bool monotone = same_sign(a.w1, b.w1) && 0.5 * (std::fabs(a.w1) + std::fabs(b.w1) - h * M2) > 0;
    if (monotone || h < options.min_interval * witness.time_unit) {
      if (sign_change) {
        if (b.w == 0) return Crossing{b.t, false, examined};
        const auto f = [&](double t) { return W.at(t).w; };
        boost::uintmax_t iterations = 200;
        const double tolerance = options.time_tolerance, unit = witness.time_unit;
        const auto root = boost::math::tools::toms748_solve(
            f, a.t, b.t, a.w, b.w,
            [tolerance, unit](double lo, double hi) { return hi - lo <= tolerance * std::max(unit, std::fabs(hi)); },
            iterations);
        return Crossing{0.5 * (root.first + root.second), false, examined};
      }
      if (monotone) continue;  // monotone without a sign change: no root
      // Uncertified down to the resolution: the witness touches the level here.
      return Crossing{std::fabs(a.w) <= std::fabs(b.w) ? a.t : b.t, true, examined};
    }
    const Sample m = W.at(a.t + 0.5 * h);
    stack.push_back({m, b});
    stack.push_back({a, m});
  }
  return std::nullopt;
}

}  // namespace backlash::numeric
