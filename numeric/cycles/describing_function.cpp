#include "backlash/numeric/describing_function.hpp"

#include "backlash/numeric/parametric.hpp"

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

double describing_function_separation_velocity(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, K = p.K, b = p.backlash;
  if (p.measured_at != model::MeasuredAt::Load || !(b > 0) || !(F > 0)) return 0;
  const double c = J * K / (F * F);
  // The root of largest amplitude (largest β): the first sign change coming down from β = 1,
  // where g > 0, on 64 points clustered at both ends, then bisected.
  const int n = 64;
  double hi = 1 - 1e-12;
  for (int k = n - 1; k >= 0; --k) {
    double lo = -std::cos(M_PI * k / n) * (1 - 1e-12);
    if (balance(lo, c) < 0) {
      for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
        const double mid = 0.5 * (lo + hi);
        (balance(mid, c) < 0 ? lo : hi) = mid;
      }
      const double A = b / (1 - 0.5 * (lo + hi));
      const double omega = -K * backlash_describing_function(A, b).imag() / F;
      const double swing = A - b / 2, slope = omega * cot_phi(p);
      return omega * swing / std::sqrt(1 + slope * slope);
    }
    hi = lo;
  }
  return 0;
}

}  // namespace backlash::numeric
