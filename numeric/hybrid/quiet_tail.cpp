#include "hybrid/quiet_tail.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace backlash::numeric::detail {

namespace {

// The relative rounding allowed for the state x(T) of the closed form and the derivatives formed
// from it (first_crossing.cpp's kSampleNoise: far above their ulps times the closed forms'
// cancellation).  It enters only through terms that decay with the motor's rates.
constexpr double kStateNoise = 1e-6;

// Rates and exponentials rounded the safe way: a rate ≥ 0 known to a relative 1e-12, taken toward
// 0 (a slower decay), its exponential rounded up.
constexpr double kRateMargin = 1 - 1e-12, kUp = 1 + 1e-12;

double decay(double rate, double tau) { return std::exp(-rate * kRateMargin * tau) * kUp; }

// ∫₀^τ e^{−rate σ} dσ ≤ min(τ, 1/rate).
double decay_integral(double rate, double tau) { return rate > 0 ? std::min(tau, 1 / (rate * kRateMargin)) : tau; }

// The motor block M = [[0, 1], [−k, −a]] (k, a ≥ 0), with α = a/2 and disc = α² − k:
// e^{Mτ} = e^{−ατ}(C(τ) I + S(τ) N), N = M + αI (N² = disc·I), C, S = cosh(rτ), sinh(rτ)/r with
// r = √disc (eigenvalues λ1,2 = −α ± r), cos(ωτ), sin(ωτ)/ω with ω = √−disc, or 1, τ.  Always
// |C| ≤ e^{rτ}, |S| ≤ τ e^{rτ} (r = 0 for complex roots); with distinct real roots exactly
// e^{−ατ}C = (e^{λ1τ} + e^{λ2τ})/2, e^{−ατ}S = (e^{λ1τ} − e^{λ2τ})/(2r); with complex ones
// |C| ≤ 1, |S| ≤ 1/ω.  Each bound below is the smaller of the general one and the exact form's.
struct MotorBlock {
  double k, alpha, disc, r, slow;  // slow = α − r ≥ 0, the slower decay rate (stably: k/(α + r))

  MotorBlock(double k_, double a) : k(k_), alpha(a / 2), disc(alpha * alpha - k_) {
    r = disc > 0 ? std::sqrt(disc) : 0;
    slow = disc < 0 ? alpha : (alpha + r > 0 ? k / (alpha + r) : 0);
  }

  // sup over τ ∈ [ta, tb] of |(e^{Mτ} q)₂| for q known to within dq (componentwise):
  // (e^{Mτ} q)₂ = e^{−ατ}(C q₂ + S P), P = (N q)₂ = −k q₁ − α q₂.
  double second(const double q[2], const double dq[2], double ta, double tb) const {
    const double P = -k * q[0] - alpha * q[1], dP = k * dq[0] + alpha * dq[1];
    const double Q = std::fabs(q[1]) + dq[1];
    double bound = decay(slow, ta) * (Q + tb * (std::fabs(P) + dP));
    if (disc > 0) {  // the modes' weights ((1 ∓ α/r) q₂ ∓ (k/r) q₁)/2, each with its own rounding
      const double slow_part = std::fabs(q[1] + P / r) + std::fabs(1 - alpha / r) * dq[1] + k / r * dq[0];
      const double fast_part = std::fabs(q[1] - P / r) + (1 + alpha / r) * dq[1] + k / r * dq[0];
      bound = std::min(bound, 0.5 * slow_part * decay(slow, ta) + 0.5 * fast_part * decay(alpha + r, ta));
    } else if (disc < 0) {
      bound = std::min(bound, decay(alpha, ta) * (Q + (std::fabs(P) + dP) / std::sqrt(-disc)));
    }
    return bound;
  }

  // ∫₀^tb |(e^{Mσ})₂₂| dσ: q = (0, 1), P = −α.
  double forced(double tb) const {
    double bound = tb * (1 + tb * alpha);
    if (disc > 0) {
      bound = std::min(bound, 0.5 * std::fabs(1 - alpha / r) * decay_integral(slow, tb) +
                                  0.5 * (1 + alpha / r) * decay_integral(alpha + r, tb));
    } else if (disc < 0) {
      bound = std::min(bound, (1 + alpha / std::sqrt(-disc)) * decay_integral(alpha, tb));
    }
    return bound * kUp;
  }
};


// The gap change Δx(τ) = (θL − θm)(τ) − (θL − θm)(0) of the flight through x0 = x(0), for
// τ ≥ τ0, within [low, high] (docs/design.md, "The event loop": a quiet tail).  With the motor not
// driven by the load (A(1, 2) = 0) and under-damped (disc = α² − k < 0, ω = √−disc):
//   θL(τ) − θL(0) = D(τ) = v0 (1 − e^{−βτ})/β (v0 τ for β = 0): monotone, between D(τ0) and D(h)
//     for τ ∈ [τ0, h];
//   θm(τ) − θm∞ = e^{−ατ}(y1 cos ωτ + (P/ω) sin ωτ), θm∞ = c/k, y1 = θm(0) − θm∞,
//     P = α y1 + θ̇m(0): of modulus ≤ E(τ0) = e^{−ατ0} √(y1² + (P/ω)²) for τ ≥ τ0;
// so Δx = D(τ) + y1 − (θm(τ) − θm∞) lies in [min(D(τ0), D(h)) + y1 − E, max(…) + y1 + E].
struct GapTail {
  double alpha, omega, beta, v0, y1, amplitude, margin, low, high, h, end_move;

  // D(τ), its exponential rounded the safe way for the bound (e^{−βτ} up: D toward 0 is not
  // safe in either direction, so the margin, ≥ 1e-6, covers the ulps of both).
  double load_move(double tau) const { return beta > 0 ? -v0 * std::expm1(-beta * tau) / beta : v0 * tau; }
  bool quiet_after(double tau0) const {
    const double d0 = load_move(tau0), envelope = amplitude * decay(alpha, tau0);
    return std::min(d0, end_move) + y1 - envelope > low + margin &&
           std::max(d0, end_move) + y1 + envelope < high - margin;
  }
};

}  // namespace

bool free_mode_form(const SmallMatrix& A, const SmallVector& c) {
  if (A.rows() != 4 || A.cols() != 4 || c.size() != 4) return false;
  const bool fixed_rows = A(0, 0) == 0 && A(0, 1) == 1 && A(0, 2) == 0 && A(0, 3) == 0 && A(1, 3) == 0 &&
                          A(2, 0) == 0 && A(2, 1) == 0 && A(2, 2) == 0 && A(2, 3) == 1 && A(3, 0) == 0 &&
                          A(3, 1) == 0 && A(3, 2) == 0 && c(0) == 0 && c(2) == 0 && c(3) == 0;
  bool finite = true;  // (a loop: Eigen's allFinite on these dynamic sizes costs hundreds of instructions)
  for (int i = 0; i < 16; ++i) finite = finite && std::isfinite(A.data()[i]);
  for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(c.data()[i]);
  return fixed_rows && A(1, 0) <= 0 && A(1, 1) <= 0 && A(1, 2) <= 0 && A(3, 3) <= 0 && finite;
}
bool free_mode_form(const LinearSegment& s) { return free_mode_form(s.A, s.c); }

double quiet_gap_from(const SmallMatrix& A, const SmallVector& c, const SmallVector& x0, double level_a,
                      double level_b, double horizon, double first_window) {
  // (the motor driven by the load — the output at the load, cases III–VIII — asked first: no tail)
  if (A.rows() != 4 || A.cols() != 4 || A(1, 2) != 0 || !free_mode_form(A, c) || x0.size() != 4) return INFINITY;
  if (!std::isfinite(x0(0)) || !std::isfinite(x0(1)) || !std::isfinite(x0(2)) || !std::isfinite(x0(3)) || !(horizon > 0))
    return INFINITY;
  const double k = -A(1, 0), alpha = -A(1, 1) / 2, disc = alpha * alpha - k;
  if (!(k > 0) || !(disc < 0) || !(first_window > 0) || !std::isfinite(first_window)) return INFINITY;
  GapTail g;
  g.alpha = alpha;
  g.omega = std::sqrt(-disc);
  g.beta = -A(3, 3);
  g.v0 = x0(3);
  g.y1 = x0(0) - c(1) / k;
  g.amplitude = std::hypot(g.y1, (alpha * g.y1 + x0(1)) / g.omega) * kUp;
  g.low = std::min(level_a, level_b);
  g.high = std::max(level_a, level_b);
  g.h = horizon;
  g.end_move = g.load_move(horizon);
  const double scale = std::fabs(x0(0)) + std::fabs(x0(2)) + std::fabs(c(1) / k) + g.amplitude + std::fabs(g.end_move) +
                       std::fabs(g.low) + std::fabs(g.high);
  g.margin = kStateNoise * std::max(1.0, scale);
  if (!g.quiet_after(horizon)) return INFINITY;  // not even the horizon's own state is clear: no tail
  // The first of τ0 = 0, w/4, w/2, w, 2w, … that passes (the test is monotone in τ0: D(τ0) moves
  // toward D(h) and E decays), so at most twice the earliest time that would.
  if (g.quiet_after(0)) return 0;
  for (double tau0 = first_window / 4; tau0 < horizon; tau0 *= 2)
    if (g.quiet_after(tau0)) return tau0;
  return horizon;
}

std::function<double(double, double)> gap_slope_third_derivative_bound(const LinearSegment& free_segment,
                                                                       const SmallVector& xT, double T) {
  if (!free_mode_form(free_segment) || xT.size() != 4 || !xT.allFinite()) return {};
  const SmallMatrix& A = free_segment.A;
  const double beta = -A(3, 3), load_gain = -A(1, 2);
  // x''' = A²(A x + c) at T, and the size of its terms (the rounding it carries).
  SmallVector d = A * xT + free_segment.c;
  SmallVector size = A.cwiseAbs() * xT.cwiseAbs() + free_segment.c.cwiseAbs();
  for (int i = 0; i < 2; ++i) {
    d = A * d;
    size = A.cwiseAbs() * size;
  }
  const double q[2] = {d(0), d(1)}, dq[2] = {kStateNoise * size(0), kStateNoise * size(1)};
  const double load_speed = std::fabs(xT(3)) * (1 + kStateNoise);  // |θ̇L(s)| ≤ |θ̇L(T)| for s ≥ T
  const MotorBlock motor(-A(1, 0), -A(1, 1));
  return [=](double a, double b) {
    const double ta = std::max(0.0, a - T), tb = std::max(0.0, b - T);
    const double load = beta * beta * beta * load_speed * decay(beta, ta);  // |θL''''| = β³|θ̇L|
    const double forcing = load_gain * beta * beta * load_speed * motor.forced(tb);
    return (load + motor.second(q, dq, ta, tb) + forcing) * (1 + 1e-9) + 1e-300;
  };
}

bool gap_moves_away_from(const LinearSegment& free_segment, const std::function<SmallVector(double)>& state,
                         double gap_at_from, double from, double horizon, double time_unit, long budget) {
  try {
    const SmallVector x = state(from);
    const double slope = x(3) - x(1);
    const double slope_noise = kStateNoise * (std::fabs(x(3)) + std::fabs(x(1)));
    const double gap_noise = kStateNoise * (std::fabs(x(2)) + std::fabs(x(0)));
    if (!(std::fabs(slope) > slope_noise) || !(std::fabs(gap_at_from) > gap_noise) || !(slope * gap_at_from > 0))
      return false;
    LinearWitness w;  // f' = θ̇L − θ̇m
    w.A = free_segment.A;
    w.c = free_segment.c;
    w.e = SmallRow::Zero(4);
    w.e(1) = -1;
    w.e(3) = 1;
    w.state = state;
    w.time_unit = time_unit;
    w.third_derivative_bound = gap_slope_third_derivative_bound(free_segment, x, from);
    if (!w.third_derivative_bound) return false;
    CrossingOptions options;
    options.max_intervals = budget;
    return !first_crossing(w, from, horizon, options);
  } catch (const std::runtime_error&) {  // the budget spent, a non-finite state: not certified
    return false;
  }
}

}  // namespace backlash::numeric::detail
