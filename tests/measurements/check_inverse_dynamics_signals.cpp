// check_inverse_dynamics_signals — properties of the signals for inverse
// dynamics on random inputs.
//
//  * Random Butterworth designs (order 1 … 10, fc from fs/200 to 0.45·fs) follow
//    the closed form |H(f)|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))^(2n)) and are stable.
//  * zero_phase_filter is linear, keeps the length and passes constants.
//  * derivatives are exact on random quadratics, the acceleration on cubics.
//  * welch_psd keeps Parseval: Σ P·Δf is the segments' windowed mean square.
//  * autocorrelation by FFT equals the direct sums; τ_int ignores offset and scale.
//  * uniform_sample_rate accepts jitter under the tolerance, refuses one sample
//    beyond it and names it.
// Fixed seeds: every run checks the same inputs.
#include "backlash/measurements/inverse_dynamics_signals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace backlash::measurements;

constexpr double pi = std::numbers::pi;
constexpr double eps = std::numeric_limits<double>::epsilon();
using Random = std::mt19937_64;

double uniform(Random& random, double low, double high) { return std::uniform_real_distribution<double>(low, high)(random); }
std::size_t between(Random& random, std::size_t low, std::size_t high) {
  return std::uniform_int_distribution<std::size_t>(low, high)(random);
}

std::string show(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

void expect_near(double actual, double expected, double tolerance, const std::string& what) {
  EXPECT_LE(std::abs(actual - expected), tolerance)
      << what << " returned " << show(actual) << " instead of " << show(expected) << " (± " << show(tolerance) << ")";
}

std::vector<double> random_signal(Random& random, std::size_t n, double scale) {
  std::vector<double> x(n);
  std::normal_distribution<double> normal(0, scale);
  for (double& value : x) value = normal(random);
  return x;
}

double max_abs(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

TEST(ButterworthProperties, RandomDesignsFollowTheClosedFormAndAreStable) {
  // Rounding in the coefficients moves poles near z = 1 by ~eps/(1 − r); the
  // closed form then holds to ~1e-12 relative for these ranges (1e-10 allowed).
  Random random(101);
  for (int trial = 0; trial < 300; ++trial) {
    const int order = static_cast<int>(between(random, 1, 10));
    const double fs = std::pow(10.0, uniform(random, 0, 5));
    const double fc = fs * std::pow(10.0, uniform(random, std::log10(1.0 / 200), std::log10(0.45)));
    const ButterworthLowPass filter = design_butterworth_low_pass(fc, fs, order);
    const std::string what = "order " + std::to_string(order) + ", fc/fs = " + show(fc / fs);
    for (const SecondOrderSection& s : filter.sections) {
      const double radius = s.a2 != 0 ? std::sqrt(s.a2) : std::abs(s.a1);
      EXPECT_LT(radius, 1.0) << what << ": a pole at radius " << radius;
    }
    expect_near(std::norm(filter.response(fc)), 0.5, 1e-10, what + ": |H(fc)|²");
    expect_near(std::norm(filter.response(0)), 1.0, 1e-10, what + ": |H(0)|²");
    for (int probe = 0; probe < 5; ++probe) {
      const double f = uniform(random, 0, 0.499 * fs);
      const double expected = 1 / (1 + std::pow(std::tan(pi * f / fs) / std::tan(pi * fc / fs), 2 * order));
      expect_near(std::norm(filter.response(f)), expected, 1e-10 * expected + 1e-14, what + ": |H(" + show(f) + ")|²");
    }
  }
}

TEST(ZeroPhaseFilterProperties, IsLinearKeepsTheLengthAndPassesConstants) {
  // Linearity holds in exact arithmetic (the initial states scale with the
  // padded ends, which are linear in x); rounding: 1e-12 of the inputs' size.
  Random random(202);
  for (int trial = 0; trial < 200; ++trial) {
    const int order = static_cast<int>(between(random, 1, 8));
    const ButterworthLowPass filter = design_butterworth_low_pass(uniform(random, 0.01, 0.45) * 1000, 1000, order);
    const std::size_t n = between(random, filter.edge_padding() + 1, 400);
    const std::vector<double> x = random_signal(random, n, 1.0), y = random_signal(random, n, 3.0);
    const double alpha = uniform(random, -2, 2), beta = uniform(random, -2, 2);
    std::vector<double> mix(n);
    for (std::size_t k = 0; k < n; ++k) mix[k] = alpha * x[k] + beta * y[k];
    const std::vector<double> fx = zero_phase_filter(x, filter), fy = zero_phase_filter(y, filter);
    const std::vector<double> fmix = zero_phase_filter(mix, filter);
    ASSERT_EQ(fmix.size(), n) << "zero_phase_filter returned " << fmix.size() << " samples instead of " << n;
    const double scale = std::abs(alpha) * max_abs(x) + std::abs(beta) * max_abs(y);
    for (std::size_t k = 0; k < n; ++k)
      expect_near(fmix[k], alpha * fx[k] + beta * fy[k], 1e-12 * scale,
                  "order " + std::to_string(order) + ", n = " + std::to_string(n) + ": filtered mix[" + std::to_string(k) + "]");
    const double level = uniform(random, -1e3, 1e3);
    const std::vector<double> constant(n, level);
    const std::vector<double> kept = zero_phase_filter(constant, filter);
    for (std::size_t k = 0; k < n; ++k)
      expect_near(kept[k], level, 1e-12 * std::abs(level), "constant[" + std::to_string(k) + "]");
  }
}

TEST(DerivativeProperties, AreExactOnQuadraticsAndTheAccelerationOnCubics) {
  // Rounding bound as in the exam: the stencils' weight sums (8/(2h), 12/h²)
  // times eps·max|x|, doubled — here times 4 for the cubic's larger range.
  Random random(303);
  for (int trial = 0; trial < 300; ++trial) {
    const double fs = std::pow(10.0, uniform(random, 1, 4)), h = 1 / fs;
    const std::size_t n = between(random, 4, 300);
    const double t0 = uniform(random, -1, 1) * static_cast<double>(n) * h;
    const double c0 = uniform(random, -1, 1), c1 = uniform(random, -1, 1) * fs / 100, c2 = uniform(random, -1, 1) * fs;
    const double c3 = trial % 2 ? uniform(random, -1, 1) * fs : 0.0;  // odd trials: a cubic
    std::vector<double> x(n), v(n), a(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double t = t0 + static_cast<double>(k) * h;
      x[k] = c0 + t * (c1 + t * (c2 + t * c3));
      v[k] = c1 + t * (2 * c2 + 3 * c3 * t);
      a[k] = 2 * c2 + 6 * c3 * t;
    }
    const Derivatives d = derivatives(x, fs);
    const double size = 4 * max_abs(x);
    const std::string what = "trial " + std::to_string(trial) + " (n = " + std::to_string(n) + ")";
    for (std::size_t k = 0; k < n; ++k) {
      expect_near(d.acceleration[k], a[k], 2 * 12 * eps * size / (h * h), what + ": acceleration[" + std::to_string(k) + "]");
      if (c3 == 0) expect_near(d.velocity[k], v[k], 2 * 8 * eps * size / (2 * h), what + ": velocity[" + std::to_string(k) + "]");
    }
  }
}

TEST(WelchProperties, KeepParseval) {
  // Σ_k P_k·fs/N = (1/K)·Σ_segments Σ_j (w_j·(x_j − mean))² / Σw², exactly
  // (one-sided doubling pairs each bin with its mirror); rounding 1e-12.
  Random random(404);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = between(random, 2, 3000);
    const std::size_t segment = between(random, 2, std::min<std::size_t>(n, 700));
    const double fs = std::pow(10.0, uniform(random, 0, 4));
    const std::vector<double> x = random_signal(random, n, uniform(random, 0.1, 10));
    const WelchPsd psd = welch_psd(x, fs, segment);
    const std::size_t step = segment - segment / 2, count = (n - segment / 2) / step;
    ASSERT_EQ(psd.segments, count);
    ASSERT_EQ(psd.density.size(), segment / 2 + 1);
    double energy = 0, window_energy = 0;
    for (std::size_t j = 0; j < segment; ++j) {
      const double w = 0.5 - 0.5 * std::cos(2 * pi * static_cast<double>(j) / static_cast<double>(segment));
      window_energy += w * w;
    }
    for (std::size_t s = 0; s < count; ++s) {
      double mean = 0;
      for (std::size_t j = 0; j < segment; ++j) mean += x[s * step + j];
      mean /= static_cast<double>(segment);
      for (std::size_t j = 0; j < segment; ++j) {
        const double w = 0.5 - 0.5 * std::cos(2 * pi * static_cast<double>(j) / static_cast<double>(segment));
        energy += std::pow(w * (x[s * step + j] - mean), 2);
      }
    }
    const double expected = energy / window_energy / static_cast<double>(count);
    double sum = 0;
    for (double p : psd.density) {
      EXPECT_GE(p, 0.0);
      sum += p * fs / static_cast<double>(segment);
    }
    expect_near(sum, expected, 1e-12 * expected,
                "n = " + std::to_string(n) + ", segment = " + std::to_string(segment) + ": Σ density·Δf");
  }
}

TEST(AutocorrelationProperties, FftEqualsTheDirectSumsAndTauIgnoresOffsetAndScale) {
  Random random(505);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = between(random, 2, 300);
    std::vector<double> r = random_signal(random, n, 1.0);
    const double a = uniform(random, -0.9, 0.95);  // make it correlated
    for (std::size_t k = 1; k < n; ++k) r[k] += a * r[k - 1];
    const std::size_t max_lag = between(random, 0, n + 5);
    const std::vector<double> rho = autocorrelation(r, max_lag);
    ASSERT_EQ(rho.size(), std::min(max_lag, n - 1) + 1);
    double mean = 0;
    for (double value : r) mean += value;
    mean /= static_cast<double>(n);
    double c0 = 0;
    for (double value : r) c0 += (value - mean) * (value - mean);
    for (std::size_t k = 0; k < rho.size(); ++k) {
      double ck = 0;
      for (std::size_t j = 0; j + k < n; ++j) ck += (r[j] - mean) * (r[j + k] - mean);
      expect_near(rho[k], ck / c0, 1e-12, "n = " + std::to_string(n) + ": rho[" + std::to_string(k) + "]");
    }
    const AutocorrelationTime tau = integrated_autocorrelation_time(r);
    const double scale = uniform(random, -1e3, 1e3), offset = uniform(random, -1e4, 1e4);
    std::vector<double> moved(n);
    for (std::size_t k = 0; k < n; ++k) moved[k] = scale * r[k] + offset;
    const AutocorrelationTime tau_moved = integrated_autocorrelation_time(moved);
    expect_near(tau_moved.tau, tau.tau, 1e-9 * std::max(1.0, std::abs(tau.tau)), "n = " + std::to_string(n) + ": τ_int moved");
    EXPECT_EQ(tau_moved.lags, tau.lags) << "n = " << n;
    // τ_int is 1 + 2·Σ ρ_1…ρ_lags.
    double sum = 1;
    for (std::size_t k = 1; k <= tau.lags; ++k) sum += 2 * tau.rho.at(k);
    expect_near(tau.tau, sum, 1e-12 * static_cast<double>(n), "n = " + std::to_string(n) + ": τ_int as the sum");
  }
}

TEST(SamplingProperties, JitterBelowTheToleranceIsAcceptedOneSampleBeyondIsNamed) {
  Random random(606);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = between(random, 3, 2000);
    const double step = std::pow(10.0, uniform(random, -6, 1)), t0 = uniform(random, -100, 100);
    const double tolerance = std::pow(10.0, uniform(random, -5, -1.5));
    std::vector<double> t(n);
    for (std::size_t k = 0; k < n; ++k)
      t[k] = t0 + step * (static_cast<double>(k) + (k == 0 || k + 1 == n ? 0.0 : uniform(random, -0.45, 0.45) * tolerance));
    const double fs = uniform_sample_rate(t, tolerance);
    expect_near(fs * step, 1.0, 1e-9 + 4 * eps * (std::abs(t0) / step), "fs·step, trial " + std::to_string(trial));
    const std::size_t late = between(random, 1, n - 2);
    t[late] = t0 + step * (static_cast<double>(late) + 3 * tolerance);
    const std::string expected_start = "uniform_sample_rate: the record is not uniformly sampled: t[" + std::to_string(late) + "]";
    try {
      uniform_sample_rate(t, tolerance);
      ADD_FAILURE() << "uniform_sample_rate accepted sample " << late << " 3 tolerances off the grid";
    } catch (const std::invalid_argument& error) {
      EXPECT_EQ(std::string(error.what()).rfind(expected_start, 0), 0u)
          << "returned \"" << error.what() << "\" instead of a message starting \"" << expected_start << "\"";
    }
  }
}

}  // namespace
