// exam_inverse_dynamics_signals — the signals inverse dynamics needs from a
// measured record, known answers.
//
//  * The Butterworth design: one pass has |H(0)| = 1, |H(fc)| = 1/√2 and the
//    closed form |H(f)|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))^(2n)).
//  * Forward–backward filtering: a sinusoid in the pass band comes out in phase
//    with gain |H|², one far above attenuated by |H|² as predicted.
//  * Differences: exact on quadratics (to a rounding bound derived below), on a
//    sinusoid within the Taylor bounds and converging as h².
//  * Welch: white noise gives the level σ²/(fs/2) within a derived statistical
//    tolerance, an on-bin sinusoid puts A²·N/(3fs) in its bin, a quarter of
//    that in each neighbour, nothing elsewhere.
//  * τ_int of AR(1) is (1 + a)/(1 − a) within Sokal's error.
//  * SciPy 1.10 as an independent reference: tests/measurements/reference/*.csv
//    written by make_filter_reference.py (sosfiltfilt, welch, numpy.gradient,
//    and the whole EMPS decision and fit).
//  * Bad input: one-line std::invalid_argument messages.
// Fixed seeds: every run checks the same inputs.
#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/inverse_dynamics_signals.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace backlash::measurements;

constexpr double pi = std::numbers::pi;
constexpr double eps = std::numeric_limits<double>::epsilon();

const std::string reference_dir = BACKLASH_REFERENCE_DIR;
const std::string emps_dir = BACKLASH_EMPS_DATA_DIR;

std::string show(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

/// EXPECTs |actual − expected| ≤ tolerance, printing "returned X instead of Y".
void expect_near(double actual, double expected, double tolerance, const std::string& what) {
  EXPECT_LE(std::abs(actual - expected), tolerance)
      << what << " returned " << show(actual) << " instead of " << show(expected) << " (± " << show(tolerance) << ")";
}

/// The worst |actual[k] − expected[k]| over k in [from, to), with the index.
struct Worst {
  double difference = 0;
  std::size_t index = 0;
};
Worst worst_difference(const std::vector<double>& actual, const std::vector<double>& expected, std::size_t from,
                       std::size_t to) {
  Worst worst;
  for (std::size_t k = from; k < to; ++k)
    if (std::abs(actual[k] - expected[k]) > worst.difference) worst = {std::abs(actual[k] - expected[k]), k};
  return worst;
}

/// EXPECTs every |actual[k] − expected[k]| ≤ tolerance on [from, to).
void expect_close(const std::vector<double>& actual, const std::vector<double>& expected, double tolerance,
                  const std::string& what, std::size_t from = 0, std::size_t to = std::string::npos) {
  ASSERT_EQ(actual.size(), expected.size()) << what << " returned " << actual.size() << " values instead of "
                                            << expected.size();
  to = std::min(to, actual.size());
  const Worst worst = worst_difference(actual, expected, from, to);
  EXPECT_LE(worst.difference, tolerance) << what << "[" << worst.index << "] returned " << show(actual[worst.index])
                                         << " instead of " << show(expected[worst.index]) << " (tolerance "
                                         << show(tolerance) << ")";
}

double max_abs(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

template <class Action>
std::string message_of(Action&& action) {
  try {
    action();
  } catch (const std::invalid_argument& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("<not std::invalid_argument: ") + error.what() + ">";
  }
  return "<no error>";
}

void expect_message(const std::string& actual, const std::string& expected) {
  EXPECT_EQ(actual, expected) << "returned \"" << actual << "\" instead of \"" << expected << "\"";
}

/// A reference CSV: comment lines "# name = value ..." become `values`, the
/// header row names the columns.
struct ReferenceCsv {
  std::map<std::string, std::vector<double>> columns;
  std::map<std::string, double> values;
};

double parse_number(const std::string& text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) throw std::runtime_error("not a number: " + text);
  return value;
}

ReferenceCsv read_reference(const std::string& name) {
  std::ifstream in(reference_dir + "/" + name);
  if (!in) throw std::runtime_error("cannot read " + reference_dir + "/" + name);
  ReferenceCsv csv;
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      std::istringstream words(line.substr(1));
      std::string key, equals, value;
      if (words >> key >> equals >> value && equals == "=") try {
          csv.values[key] = parse_number(value);
        } catch (const std::runtime_error&) {
        }
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (names.empty()) {
      names = cells;
      continue;
    }
    if (cells.size() != names.size()) throw std::runtime_error(name + ": a row of the wrong width");
    for (std::size_t c = 0; c < cells.size(); ++c) csv.columns[names[c]].push_back(parse_number(cells[c]));
  }
  return csv;
}

std::vector<double> sampled(std::size_t n, double fs, auto function) {
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = function(static_cast<double>(k) / fs);
  return x;
}

/// A·cos(2π·f·t + φ) at t = k/fs for whole f and fs, the phase reduced exactly
/// ((f·k) mod fs in integers) so that the samples carry rounding of 1 ulp, not
/// of the growing argument (which would add broadband noise of ~1e-13 that the
/// low-pass lets through).
std::vector<double> exact_sinusoid(std::size_t n, long fs, long f, double amplitude, double phase) {
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k)
    x[k] = amplitude * std::cos(2 * pi * static_cast<double>((f * static_cast<long>(k)) % fs) / static_cast<double>(fs) + phase);
  return x;
}

/// Tolerance for one bin of two Welch estimates of the same signal computed
/// with different FFTs.  An FFT of N points computes each X_k with an error up
/// to about eps·log2(N)·||w·x||₁ ≤ eps·log2(N)·√N·||w·x||₂; in density units
/// (P_k ∝ |X_k|²) that is δP_k ≤ 2·√(P_k)·eps·log2(N)·√N·√(2·MS/fs), MS = Σ P·Δf
/// the windowed mean square, and both FFTs err: twice that, plus 1e-12·P_k.
/// Relative to P_k this is large only in bins far below the signal's power
/// (EMPS: 5e-19 m²/Hz at the top against 7e-4 m² in all; SciPy and Eigen there
/// agree to 3e-9, 211·eps·√(2·MS/fs) in these units, the bound allows 2·500).
double welch_bin_tolerance(double density, double mean_square, double fs, std::size_t segment) {
  const double n = static_cast<double>(segment);
  return 1e-12 * density + 2 * 2 * std::sqrt(density * 2 * mean_square / fs) * eps * std::log2(n) * std::sqrt(n);
}

double mean_square(const WelchPsd& psd, double fs) {
  double sum = 0;
  for (double p : psd.density) sum += p * fs / static_cast<double>(psd.segment);
  return sum;
}

/// The closed form of one pass: |H(f)|² of the bilinear Butterworth.
double butterworth_power(double f, double fc, double fs, int order) {
  return 1 / (1 + std::pow(std::tan(pi * f / fs) / std::tan(pi * fc / fs), 2 * order));
}

/// Largest pole radius of the cascade (how slowly its transients decay).
double largest_pole_radius(const ButterworthLowPass& filter) {
  double radius = 0;
  for (const SecondOrderSection& s : filter.sections)
    radius = std::max(radius, s.a2 != 0 ? std::sqrt(s.a2) : std::abs(s.a1));
  return radius;
}

// ------------------------------------------------------------------ design

TEST(ButterworthDesign, OnePassIsOneAtDcAndOneOverRootTwoAtTheCutoff) {
  // The design follows the closed form exactly; what is left is rounding in
  // the coefficients, amplified near z = 1 by poles crowding there (order 8 at
  // fc = fs/100): 1e-11 leaves room for that and catches any design error.
  for (int order = 1; order <= 8; ++order)
    for (double ratio : {0.01, 0.088, 0.25, 0.45}) {
      const double fs = 1000, fc = ratio * fs;
      const ButterworthLowPass filter = design_butterworth_low_pass(fc, fs, order);
      const std::string what = "order " + std::to_string(order) + ", fc = " + show(fc) + ": ";
      EXPECT_EQ(filter.sections.size(), static_cast<std::size_t>((order + 1) / 2)) << what << "sections";
      expect_near(std::abs(filter.response(0)), 1.0, 1e-11, what + "|H(0)|");
      expect_near(std::abs(filter.response(fc)), 1 / std::sqrt(2.0), 1e-11, what + "|H(fc)|");
      for (double f : {0.1 * fc, 0.5 * fc, 0.9 * fc, std::min(1.5 * fc, 0.49 * fs), 0.49 * fs})
        expect_near(std::norm(filter.response(f)), butterworth_power(f, fc, fs, order),
                    1e-11 * butterworth_power(f, fc, fs, order) + 1e-15, what + "|H(" + show(f) + ")|²");
      EXPECT_LT(largest_pole_radius(filter), 1.0) << what << "a pole outside the unit circle";
      EXPECT_EQ(filter.edge_padding(), static_cast<std::size_t>(3 * (order + 1))) << what << "edge padding";
    }
}

TEST(ButterworthDesign, SectionsAreScipysFourthOrderAt88Hz) {
  // scipy.signal.butter(4, 88, fs=1000, output='sos') has the poles
  // 0.5730 ± 0.1353i and 0.7086 ± 0.4040i (|z| = 0.5887, 0.8157): the same
  // denominators (to rounding), in SciPy's order (the more damped section first).
  const ButterworthLowPass filter = design_butterworth_low_pass(88, 1000);
  ASSERT_EQ(filter.sections.size(), 2u);
  EXPECT_EQ(filter.edge_padding(), 15u);
  const double scipy_a[2][2] = {{-1.1459676478160254, 0.3466217141611239}, {-1.4171719401259881, 0.6653127258090615}};
  for (int s = 0; s < 2; ++s) {
    expect_near(filter.sections[s].a1, scipy_a[s][0], 1e-14, "section " + std::to_string(s) + " a1");
    expect_near(filter.sections[s].a2, scipy_a[s][1], 1e-14, "section " + std::to_string(s) + " a2");
  }
}

// ------------------------------------------------------------------ zero-phase filtering

TEST(ZeroPhaseFilter, PassesASinusoidInTheBandInPhaseWithGainHSquared) {
  const double fs = 1000, fc = 88, f = 10, amplitude = 0.3, phase = 0.7;
  const ButterworthLowPass filter = design_butterworth_low_pass(fc, fs);
  const auto x = exact_sinusoid(3000, 1000, 10, amplitude, phase);
  const std::vector<double> y = zero_phase_filter(x, filter);
  const double gain = std::norm(filter.response(f));  // |H(f)|², two passes, no phase
  // The end transients decay as r^k (r the largest pole radius); skip until
  // r^k < 1e-13.  What remains is rounding: 1e-12·amplitude.
  const auto skip = static_cast<std::size_t>(std::ceil(std::log(1e-13) / std::log(largest_pole_radius(filter))));
  std::vector<double> expected(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) expected[k] = gain * x[k];
  expect_close(y, expected, 1e-12 * amplitude, "in band: zero_phase_filter", skip, x.size() - skip);
  EXPECT_GT(gain, 0.999) << "|H(10 Hz)|² returned " << gain << " instead of nearly 1";
  // A constant passes exactly, ends included (steady-state initial conditions).
  const std::vector<double> constant(100, -2.5);
  expect_close(zero_phase_filter(constant, filter), constant, 4 * eps * 2.5, "constant: zero_phase_filter");
}

TEST(ZeroPhaseFilter, AttenuatesASinusoidFarAboveTheCutoffAsPredicted) {
  const double fs = 1000, fc = 88, f = 400, amplitude = 1.0;
  const ButterworthLowPass filter = design_butterworth_low_pass(fc, fs);
  const auto x = exact_sinusoid(3000, 1000, 400, amplitude, 0.0);
  const std::vector<double> y = zero_phase_filter(x, filter);
  const double gain = butterworth_power(f, fc, fs, 4);  // 5.2e-9: −166 dB after both passes
  // The end transients start at the size of x (the odd extension's offset
  // 2·x[n−1] passes the filter) and decay as r^k: skip until r^k < 1e-20.
  const auto skip = static_cast<std::size_t>(std::ceil(std::log(1e-20) / std::log(largest_pole_radius(filter))));
  std::vector<double> expected(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) expected[k] = gain * x[k];
  // Rounding in the cascade leaves ~1e-16·amplitude, 2e-8 of the attenuated
  // amplitude; 1e-6 of it is the tolerance.
  expect_close(y, expected, 1e-6 * gain * amplitude, "far above: zero_phase_filter", skip, x.size() - skip);
  EXPECT_NEAR(gain, 5.2e-9, 0.1e-9) << "the predicted attenuation";
}

// ------------------------------------------------------------------ derivatives

TEST(Derivatives, AreExactOnAQuadratic) {
  // x = c0 + c1·t + c2·t², t = t0 + k·h.  The stencils are exact; rounding in
  // x (|δx| ≤ eps·max|x| per sample) enters through the weights: Σ|w| = 8 for
  // the velocity stencil (÷2h), 12 for the acceleration one (÷h²), doubled for
  // the rounding of the arithmetic itself.
  const double fs = 1000, h = 1 / fs, t0 = 0.37, c0 = 0.25, c1 = -1.5, c2 = 3.25;
  const auto x = sampled(500, fs, [&](double t) { t += t0; return c0 + c1 * t + c2 * t * t; });
  const Derivatives d = derivatives(x, fs);
  std::vector<double> v(x.size()), a(x.size(), 2 * c2);
  for (std::size_t k = 0; k < x.size(); ++k) v[k] = c1 + 2 * c2 * (t0 + static_cast<double>(k) * h);
  expect_close(d.velocity, v, 2 * 8 * eps * max_abs(x) / (2 * h), "velocity");
  expect_close(d.acceleration, a, 2 * 12 * eps * max_abs(x) / (h * h), "acceleration");
}

TEST(Derivatives, OfASinusoidAreWithinTheTaylorBoundsAndConvergeAsHSquared) {
  // x = A·sin(ωt + φ).  Inside, the central difference gives exactly
  // A·ω·cos(·)·sin(ωh)/(ωh), error ≤ A·ω·(ωh)²/6; the second difference
  // −A·ω²·sin(·)·(sin(ωh/2)/(ωh/2))², error ≤ A·ω²·(ωh)²/12.  At the ends,
  // with Lagrange remainders: velocity |error| ≤ h²·max|x'''| = h²·A·ω³
  // (weights 4·1/6 + 1·8/6 over 2h), acceleration ≤ (5 + 4·16 + 81)/24·h²·max|x''''|
  // = 6.25·h²·A·ω⁴.  Halving h divides the interior errors by 4 (to O(h⁴)).
  const double amplitude = 0.02, f = 5, omega = 2 * pi * f, phase = 0.4;
  double previous_v = 0, previous_a = 0;
  for (double fs : {1000.0, 2000.0}) {
    const double h = 1 / fs;
    const auto x = sampled(static_cast<std::size_t>(fs), fs, [&](double t) { return amplitude * std::sin(omega * t + phase); });
    const auto v = sampled(x.size(), fs, [&](double t) { return amplitude * omega * std::cos(omega * t + phase); });
    const auto a = sampled(x.size(), fs, [&](double t) { return -amplitude * omega * omega * std::sin(omega * t + phase); });
    const Derivatives d = derivatives(x, fs);
    const double wh = omega * h;
    const double rounding_v = 16 * eps * amplitude / (2 * h), rounding_a = 24 * eps * amplitude / (h * h);
    const double bound_v = amplitude * omega * wh * wh / 6, bound_a = amplitude * omega * omega * wh * wh / 12;
    expect_close(d.velocity, v, bound_v + rounding_v, "velocity inside at fs = " + show(fs), 1, x.size() - 1);
    expect_close(d.acceleration, a, bound_a + rounding_a, "acceleration inside at fs = " + show(fs), 1, x.size() - 1);
    for (std::size_t k : {std::size_t{0}, x.size() - 1}) {
      expect_near(d.velocity[k], v[k], h * h * amplitude * std::pow(omega, 3) + rounding_v,
                  "velocity[" + std::to_string(k) + "] at fs = " + show(fs));
      expect_near(d.acceleration[k], a[k], 6.25 * h * h * amplitude * std::pow(omega, 4) + rounding_a,
                  "acceleration[" + std::to_string(k) + "] at fs = " + show(fs));
    }
    // The bound is attained over a full period (1 s holds 5): at least 99 % of it.
    const double error_v = worst_difference(d.velocity, v, 1, x.size() - 1).difference;
    const double error_a = worst_difference(d.acceleration, a, 1, x.size() - 1).difference;
    EXPECT_GT(error_v, 0.99 * bound_v) << "velocity error returned " << error_v << " instead of about " << bound_v;
    EXPECT_GT(error_a, 0.99 * bound_a) << "acceleration error returned " << error_a << " instead of about " << bound_a;
    if (previous_v > 0) {
      expect_near(previous_v / error_v, 4.0, 0.01, "velocity error ratio for h → h/2");
      expect_near(previous_a / error_a, 4.0, 0.01, "acceleration error ratio for h → h/2");
    }
    previous_v = error_v, previous_a = error_a;
  }
}

// ------------------------------------------------------------------ Welch

TEST(WelchPsd, OfWhiteNoiseIsSigmaSquaredOverHalfTheSampleRate) {
  // n = 2^18 samples of N(0, σ²), segments of N = 1024: K = 511 segments,
  // bins 2 … 511 (B = 510; DC, bin 1 — touched by removing each segment's
  // mean — and fs/2 left out).  Each bin of one periodogram is level·χ²₂/2
  // (relative variance 1); the mean over K segments and B bins has relative
  // variance c_s·c_b/(K·B), where
  //   c_s = 1 + 2·(1/3)² = 1.222: 50 % overlapping Hann segments, the window
  //         correlation Σw[j]w[j+N/2]/Σw² = ∫sin²cos²/∫sin⁴ = 1/3, squared for powers;
  //   c_b = 1 + 2·(2/3)² + 2·(1/6)² = 1.944: the Hann window correlates a bin's
  //         Fourier coefficient with its neighbours' by Σw²e^{∓2πij/N}/Σw² = −2/3
  //         (next) and 1/6 (next but one).
  // Relative sd 0.0030: the tolerance is 5 sd = 1.5 %.
  const double fs = 1000, sigma = 0.7;
  std::mt19937_64 random(20240611);
  std::normal_distribution<double> normal(0, sigma);
  std::vector<double> x(std::size_t{1} << 18);
  for (double& value : x) value = normal(random);
  const WelchPsd psd = welch_psd(x, fs, 1024);
  EXPECT_EQ(psd.segments, 511u);
  ASSERT_EQ(psd.density.size(), 513u);
  expect_near(psd.frequency_hz[512], fs / 2, 0, "frequency_hz[512]");
  double mean = 0;
  for (std::size_t k = 2; k < 512; ++k) mean += psd.density[k];
  mean /= 510;
  const double level = sigma * sigma / (fs / 2);
  const double relative_sd = std::sqrt((1 + 2.0 / 9) * (1 + 2 * 4.0 / 9 + 2.0 / 36) / (511.0 * 510.0));
  expect_near(mean, level, 5 * relative_sd * level, "the mean level over bins 2…511");
}

TEST(WelchPsd, PutsAnOnBinSinusoidsPowerInItsBin) {
  // A·sin on bin k0 = 37 of N = 256 (f0 = 37·fs/N): each Hann-windowed segment
  // holds whole periods, so X[k0] = A·(N/2)/(2i)·e^{iφ}, X[k0±1] = −X[k0]/2, and
  // nothing else: P[k0] = A²·N/(3fs), P[k0±1] = A²·N/(12fs), together A²/2 per
  // bin width.  Rounding only: 1e-12 relative, 1e-12·P[k0] elsewhere.
  const double fs = 1000, amplitude = 2.5;
  const std::size_t segment = 256, k0 = 37;
  const double f0 = static_cast<double>(k0) * fs / static_cast<double>(segment);
  const auto x = sampled(4000, fs, [&](double t) { return amplitude * std::sin(2 * pi * f0 * t + 0.3); });
  const WelchPsd psd = welch_psd(x, fs, segment);
  const double peak = amplitude * amplitude * static_cast<double>(segment) / (3 * fs);
  EXPECT_EQ(psd.segments, (4000u - 128u) / 128u);
  expect_near(psd.frequency_hz[k0], f0, 0, "frequency_hz[k0]");
  for (std::size_t k = 0; k < psd.density.size(); ++k) {
    const double expected = k == k0 ? peak : (k + 1 == k0 || k == k0 + 1) ? peak / 4 : 0.0;
    expect_near(psd.density[k], expected, 1e-12 * peak, "density[" + std::to_string(k) + "]");
  }
  double power = 0;
  for (double p : psd.density) power += p * fs / static_cast<double>(segment);
  expect_near(power, amplitude * amplitude / 2, 1e-12, "Σ density·Δf");
}

// ------------------------------------------------------------------ τ_int

TEST(IntegratedAutocorrelationTime, OfAnAr1IsOnePlusAOverOneMinusA) {
  // x_k = a·x_{k−1} + e_k, started in its stationary law: ρ_k = a^k,
  // τ_int = (1 + a)/(1 − a).  Statistical sd (Sokal): τ·sqrt(2·(2L + 1)/n) with
  // L the lags summed, derived for τ ≥ 1 — max(τ, 1) in its place keeps it
  // conservative for a < 0.  Truncation bias 2·Σ_{k>L} a^k, added.
  // Tolerance 5 sd + |bias|.
  const std::size_t n = std::size_t{1} << 20;
  for (double a : {0.0, 0.5, 0.9, -0.5}) {
    std::mt19937_64 random(7 + static_cast<unsigned>(std::lround(10 * (a + 1))));
    std::normal_distribution<double> normal(0, 1);
    std::vector<double> x(n);
    x[0] = normal(random) / std::sqrt(1 - a * a);
    for (std::size_t k = 1; k < n; ++k) x[k] = a * x[k - 1] + normal(random);
    const AutocorrelationTime result = integrated_autocorrelation_time(x);
    const double tau = (1 + a) / (1 - a);
    const double lags = static_cast<double>(result.lags);
    const double sd = std::max(tau, 1.0) * std::sqrt(2 * (2 * lags + 1) / static_cast<double>(n));
    const double bias = 2 * std::abs(std::pow(a, lags + 1) / (1 - a));
    expect_near(result.tau, tau, 5 * sd + bias, "τ_int of AR(1), a = " + show(a));
    EXPECT_EQ(result.rho.size(), std::min<std::size_t>(n, result.lags + 3)) << "rho for a = " << a;
    EXPECT_EQ(result.rho.at(0), 1.0);
  }
}

// ------------------------------------------------------------------ SciPy reference

TEST(ScipyReference, ZeroPhaseFilterMatchesSosfiltfiltIncludingTheEnds) {
  // The same algorithm (odd extension by 3·(order + 1), steady-state initial
  // conditions, direct form II transposed): only the rounding differs, and the
  // sections' (SciPy spreads the gain differently).  Tolerance 1e-10·max|y|
  // at every sample, ends included (seen: 1.4e-14 for order 3 at 20 Hz, the
  // poles nearest z = 1).
  const ReferenceCsv csv = read_reference("filter_reference.csv");
  const auto& t = csv.columns.at("t");
  const auto& x = csv.columns.at("x");
  const double fs = uniform_sample_rate(t);
  expect_near(fs, 1000, 1e-9, "uniform_sample_rate of the reference's t");
  for (const auto& [column, order, fc] :
       {std::tuple{"y4", 4, 88.0}, std::tuple{"y3", 3, 20.0}, std::tuple{"y1", 1, 150.0}}) {
    const auto& expected = csv.columns.at(column);
    const std::vector<double> y = zero_phase_filter(x, design_butterworth_low_pass(fc, 1000, order));
    expect_close(y, expected, 1e-10 * max_abs(expected), std::string(column) + ": zero_phase_filter");
  }
}

TEST(ScipyReference, DerivativesMatchNumpyGradientAndTheTaylorStencils) {
  // On SciPy's own y4, so only the differences are compared: the same
  // stencils, so rounding only — 64·eps·max|y|/h for the velocity, /h² for the
  // acceleration (the stencils' weight sums, 8 and 12, with room for rounding).
  const ReferenceCsv csv = read_reference("filter_reference.csv");
  const auto& y = csv.columns.at("y4");
  const double h = 1e-3;
  const Derivatives d = derivatives(y, 1000);
  expect_close(d.velocity, csv.columns.at("v4"), 64 * eps * max_abs(y) / h, "velocity");
  expect_close(d.acceleration, csv.columns.at("a4"), 64 * eps * max_abs(y) / (h * h), "acceleration");
}

TEST(ScipyReference, WelchPsdMatchesScipyWelch) {
  // The same algorithm; the FFTs (pocketfft, kissfft) differ in rounding:
  // welch_bin_tolerance per bin.
  const ReferenceCsv filter_csv = read_reference("filter_reference.csv");
  const ReferenceCsv csv = read_reference("welch_reference.csv");
  const WelchPsd psd = welch_psd(filter_csv.columns.at("x"), 1000, 256);
  const auto& expected = csv.columns.at("psd");
  ASSERT_EQ(psd.density.size(), expected.size());
  EXPECT_EQ(psd.segments, (2000u - 128u) / 128u);
  const double ms = mean_square(psd, 1000);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    expect_near(psd.frequency_hz[k], csv.columns.at("f")[k], 0, "frequency_hz[" + std::to_string(k) + "]");
    expect_near(psd.density[k], expected[k], welch_bin_tolerance(expected[k], ms, 1000, 256),
                "density[" + std::to_string(k) + "]");
  }
}

TEST(ScipyReference, EmpsCutoffFitAndCorrelationTimeMatchScipy) {
  // The whole chain on the EMPS estimation record: Welch PSD (welch_bin_tolerance
  // per bin), the floor (a median of those bins: the tolerance at the floor),
  // the band edge and the highest raw line (bin frequencies: exact — the
  // smoothed PSD at the edge is 1.003 × the threshold, the line 4.2 ×, margins
  // far beyond rounding), then at that cut-off the filtered
  // signals' least-squares fit drive ≈ M·a + Fv·v + Fc·sign(v) + c and τ_int
  // of its residual (the same lags): 1e-10 relative, rounding through
  // sosfiltfilt, two least-squares solvers and two FFTs (seen: 1.4e-12, 3.5e-12).
  const ReferenceCsv csv = read_reference("emps_welch_reference.csv");
  const MeasuredRecord record = to_measured_record(read_emps(emps_dir + "/DATA_EMPS.mat"));
  const InverseDynamicsSignals signals = inverse_dynamics_signals(record.t, record.theta_out, *record.drive);
  ASSERT_TRUE(signals.decision.has_value());
  const CutoffDecision& decision = *signals.decision;
  const auto& expected = csv.columns.at("psd");
  ASSERT_EQ(decision.psd.density.size(), expected.size());
  const double ms = mean_square(decision.psd, 1000);
  for (std::size_t k = 0; k < expected.size(); ++k)
    expect_near(decision.psd.density[k], expected[k], welch_bin_tolerance(expected[k], ms, 1000, 2048),
                "EMPS density[" + std::to_string(k) + "]");
  expect_near(decision.noise_floor, csv.values.at("noise_floor"),
              welch_bin_tolerance(csv.values.at("noise_floor"), ms, 1000, 2048), "noise floor");
  expect_near(decision.band_edge_hz, csv.values.at("band_edge_hz"), 0, "band edge");
  expect_near(decision.highest_line_hz, csv.values.at("highest_line_hz"), 0, "highest raw line");
  expect_near(decision.cutoff_hz, csv.values.at("cutoff_hz"), 0, "cut-off");
  EXPECT_FALSE(decision.clamped);
  expect_near(signals.sample_rate_hz, 1000, 1e-6, "sample rate");

  const auto n = static_cast<Eigen::Index>(record.size());
  Eigen::MatrixXd regressors(n, 4);
  Eigen::VectorXd drive(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double v = signals.velocity[i];
    regressors.row(k) << signals.acceleration[i], v, v > 0 ? 1.0 : v < 0 ? -1.0 : 0.0, 1.0;
    drive(k) = signals.drive[i];
  }
  const Eigen::VectorXd theta = regressors.colPivHouseholderQr().solve(drive);
  const char* names[] = {"M", "Fv", "Fc", "c"};
  for (int p = 0; p < 4; ++p)
    expect_near(theta(p), csv.values.at(names[p]), 1e-10 * std::abs(csv.values.at(names[p])), names[p]);
  const Eigen::VectorXd residual = drive - regressors * theta;
  expect_near(std::sqrt(residual.squaredNorm() / static_cast<double>(n)), csv.values.at("rms"),
              1e-10 * csv.values.at("rms"), "rms");
  const std::vector<double> r(residual.data(), residual.data() + n);
  const AutocorrelationTime tau = integrated_autocorrelation_time(r);
  expect_near(tau.tau, csv.values.at("tau_int"), 1e-10 * csv.values.at("tau_int"), "τ_int");
  expect_near(static_cast<double>(tau.lags), csv.values.at("tau_lags"), 0, "τ_int lags");
}

// ------------------------------------------------------------------ bad input

TEST(BadInput, NonUniformTimeIsRefusedWithTheSampleNamed) {
  std::vector<double> t(100);
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = 0.001 * static_cast<double>(k);
  t[40] += 0.0002;  // 0.2 steps late
  expect_message(message_of([&] { uniform_sample_rate(t); }),
                 "uniform_sample_rate: the record is not uniformly sampled: t[40] = 0.0402 s lies 0.2 steps off the "
                 "uniform grid of step 0.001 s (tolerance 0.001 steps; worst: t[40], 0.2 steps); filtering and "
                 "differencing need uniform sampling — resample the record first");
  // A slow drift: every step within 0.1 %, the grid missed by 1.2 steps.
  std::vector<double> drift(2000);
  for (std::size_t k = 1; k < drift.size(); ++k)
    drift[k] = drift[k - 1] + 0.001 * (k < 1000 ? 0.9988 : 1.0012);
  EXPECT_NE(message_of([&] { uniform_sample_rate(drift); }).find("not uniformly sampled"), std::string::npos);
  // Jitter of 1e-4 steps is accepted, and so is the EMPS time vector.
  std::vector<double> jitter(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) jitter[k] = 0.001 * (static_cast<double>(k) + (k % 2 ? 1e-4 : -1e-4));
  expect_near(uniform_sample_rate(jitter), 1000 * 99 / (99 + 2e-4), 1e-9, "fs of a jittered grid");
  expect_message(message_of([&] { uniform_sample_rate(std::vector<double>{0, 1, 1}); }),
                 "uniform_sample_rate: t is not strictly increasing: t[2] = 1 s follows t[1] = 1 s");
  expect_message(message_of([&] { uniform_sample_rate(std::vector<double>{0}); }),
                 "uniform_sample_rate: the time vector has 1 samples; it needs at least 2");
}

TEST(BadInput, CutoffsOutsideTheOpenBandAndBadOrdersAreRefused) {
  const std::string band = "design_butterworth_low_pass: the cut-off is {} Hz; it must lie strictly between 0 and "
                           "fs/2 = 500 Hz (fs = 1000 Hz)";
  const auto expected = [&](const std::string& value) {
    std::string text = band;
    return text.replace(text.find("{}"), 2, value);
  };
  expect_message(message_of([] { design_butterworth_low_pass(500, 1000); }), expected("500"));
  expect_message(message_of([] { design_butterworth_low_pass(600, 1000); }), expected("600"));
  expect_message(message_of([] { design_butterworth_low_pass(0, 1000); }), expected("0"));
  expect_message(message_of([] { design_butterworth_low_pass(-5, 1000); }), expected("-5"));
  expect_message(message_of([] { design_butterworth_low_pass(std::nan(""), 1000); }), expected("nan"));
  expect_message(message_of([] { design_butterworth_low_pass(50, 1000, 0); }),
                 "design_butterworth_low_pass: the order is 0; it must lie in 1 … 20");
  expect_message(message_of([] { design_butterworth_low_pass(50, 0); }),
                 "design_butterworth_low_pass: the sample rate is 0 Hz; it must be a finite number > 0");
}

TEST(BadInput, RecordsTooShortForThePaddingOrTheStencilsAreRefused) {
  const ButterworthLowPass filter = design_butterworth_low_pass(88, 1000);
  expect_message(message_of([&] { zero_phase_filter(std::vector<double>(15, 1.0), filter); }),
                 "zero_phase_filter: the signal has 15 samples; the odd extension at its ends needs more than 15 "
                 "(3·(order + 1) for order 4)");
  EXPECT_EQ(zero_phase_filter(std::vector<double>(16, 1.0), filter).size(), 16u);
  std::vector<double> with_nan(100, 0.0);
  with_nan[7] = std::nan("");
  expect_message(message_of([&] { zero_phase_filter(with_nan, filter); }),
                 "zero_phase_filter: x[7] is nan, not a finite number");
  expect_message(message_of([] { derivatives(std::vector<double>(3, 0.0), 1000); }),
                 "derivatives: the signal has 3 samples; it needs at least 4");
  expect_message(message_of([] { welch_psd(std::vector<double>(100, 0.0), 1000, 101); }),
                 "welch_psd: the segment is 101 samples; it must lie in 2 … 100 (the signal's length)");
  expect_message(message_of([] { cutoff_from_spectrum(std::vector<double>(63, 0.0), 1000); }),
                 "cutoff_from_spectrum: the record has 63 samples; the noise floor needs at least 64");
  expect_message(message_of([] { cutoff_from_spectrum(std::vector<double>(100, 1.0), 1000); }),
                 "cutoff_from_spectrum: the position's spectrum has a zero noise floor above fs/4 (a constant or "
                 "exactly periodic record?): there is no noise to set the cut-off against — give the cut-off "
                 "explicitly");
  expect_message(message_of([] { integrated_autocorrelation_time(std::vector<double>(10, 3.0)); }),
                 "autocorrelation: all 10 samples are equal (3): the autocorrelation is undefined");
  expect_message(message_of([] {
                   inverse_dynamics_signals(std::vector<double>(100), std::vector<double>(100), std::vector<double>(99));
                 }),
                 "inverse_dynamics_signals: the columns differ in length: t 100, position 100, drive 99");
}

TEST(CutoffFromSpectrum, ClampsToTheAllowedRange) {
  // Pure white noise: no bin stands 100× above the floor → fs/100, clamped.
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal(0, 1);
  std::vector<double> noise(8192);
  for (double& value : noise) value = normal(random);
  const CutoffDecision quiet = cutoff_from_spectrum(noise, 1000);
  expect_near(quiet.cutoff_hz, 10, 0, "cut-off of white noise");
  EXPECT_TRUE(quiet.clamped);
  expect_near(quiet.band_edge_hz, 0, 0, "band edge of white noise");
  // Motion in a band 400 … 470 Hz (low-pass 470 Hz minus low-pass 400 Hz of
  // other noise), 30 dB above the noise: it covers less than half of the
  // floor's band 250 … 500 Hz, so the floor stays the noise's, and the edge,
  // near 470 Hz, lies above 0.4·fs → 400 Hz, clamped.
  std::vector<double> other(noise.size());
  for (double& value : other) value = normal(random);
  const std::vector<double> below470 = zero_phase_filter(other, design_butterworth_low_pass(470, 1000, 8));
  const std::vector<double> below400 = zero_phase_filter(other, design_butterworth_low_pass(400, 1000, 8));
  std::vector<double> wide(noise.size());
  for (std::size_t k = 0; k < wide.size(); ++k) wide[k] = 30 * (below470[k] - below400[k]) + noise[k];
  const CutoffDecision busy = cutoff_from_spectrum(wide, 1000);
  expect_near(busy.cutoff_hz, 400, 0, "cut-off of broadband motion");
  EXPECT_TRUE(busy.clamped);
  EXPECT_GT(busy.band_edge_hz, 450) << "band edge of the 400 … 470 Hz band";
  // A lone line at 300 Hz on white noise is passed over by the running median.
  std::vector<double> line = noise;
  for (std::size_t k = 0; k < line.size(); ++k) line[k] += 5 * std::sin(2 * pi * 300.0 * static_cast<double>(k) / 1000);
  const CutoffDecision lone = cutoff_from_spectrum(line, 1000);
  expect_near(lone.cutoff_hz, 10, 0, "cut-off of noise with one line");
  EXPECT_NEAR(lone.highest_line_hz, 300, 1) << "the raw rule's answer";
}

}  // namespace
