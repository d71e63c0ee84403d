// Signal processing for inverse dynamics on measured records: Butterworth
// design, forward–backward filtering as SciPy's sosfiltfilt, second-order
// differences, Welch's PSD (Eigen's FFT), the cut-off rule and τ_int.
// The header states every formula; this file follows it line by line.
#include "backlash/measurements/inverse_dynamics_signals.hpp"

#include <fmt/format.h>

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>

namespace backlash::measurements {
namespace {

[[noreturn]] void refuse(std::string_view function, const std::string& problem) {
  throw std::invalid_argument(fmt::format("{}: {}", function, problem));
}

void require_finite(std::string_view function, std::span<const double> x, std::string_view what) {
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k])) refuse(function, fmt::format("{}[{}] is {}, not a finite number", what, k, x[k]));
}

void require_sample_rate(std::string_view function, double sample_rate_hz) {
  if (!std::isfinite(sample_rate_hz) || !(sample_rate_hz > 0))
    refuse(function, fmt::format("the sample rate is {} Hz; it must be a finite number > 0", sample_rate_hz));
}

/// Median of the values (copied: nth_element reorders); for an even count the
/// mean of the middle two, as numpy.median.
double median(std::vector<double> values) {
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle));
  return 0.5 * (lower + upper);
}

/// Steady state of each section's two delays for a unit constant at the
/// cascade's input (scipy.signal.sosfilt_zi): the input of section s is then
/// the DC gain of the sections before it, its output that times its own gain G;
/// in direct form II transposed z0 = y − b0·u, z1 = b2·u − a2·y.
std::vector<std::array<double, 2>> steady_state(const std::vector<SecondOrderSection>& sections) {
  std::vector<std::array<double, 2>> state;
  state.reserve(sections.size());
  double input = 1.0;
  for (const SecondOrderSection& s : sections) {
    const double gain = (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
    const double output = gain * input;
    state.push_back({output - s.b0 * input, s.b2 * input - s.a2 * output});
    input = output;
  }
  return state;
}

/// Runs the cascade over x in place (direct form II transposed, as
/// scipy.signal.sosfilt), each section starting from `state` scaled by `scale`.
void run_cascade(std::vector<double>& x, const std::vector<SecondOrderSection>& sections,
                 const std::vector<std::array<double, 2>>& state, double scale) {
  std::vector<std::array<double, 2>> z(state.size());
  for (std::size_t s = 0; s < state.size(); ++s) z[s] = {state[s][0] * scale, state[s][1] * scale};
  for (double& sample : x) {
    double value = sample;
    for (std::size_t s = 0; s < sections.size(); ++s) {
      const SecondOrderSection& c = sections[s];
      const double output = c.b0 * value + z[s][0];
      z[s][0] = c.b1 * value - c.a1 * output + z[s][1];
      z[s][1] = c.b2 * value - c.a2 * output;
      value = output;
    }
    sample = value;
  }
}

std::size_t next_power_of_two(std::size_t n) {
  std::size_t power = 1;
  while (power < n) power *= 2;
  return power;
}

}  // namespace

// ---------------------------------------------------------------- sampling

double uniform_sample_rate(std::span<const double> t, double tolerance) {
  constexpr std::string_view function = "uniform_sample_rate";
  if (!(tolerance > 0 && tolerance < 0.5))
    refuse(function, fmt::format("the tolerance is {} steps; it must lie in (0, 0.5)", tolerance));
  if (t.size() < 2) refuse(function, fmt::format("the time vector has {} samples; it needs at least 2", t.size()));
  require_finite(function, t, "t");
  for (std::size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1]))
      refuse(function, fmt::format("t is not strictly increasing: t[{}] = {} s follows t[{}] = {} s", k, t[k], k - 1,
                                   t[k - 1]));
  const std::size_t n = t.size();
  const double step = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  std::size_t first_off = n, worst = 0;
  double worst_steps = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double off_steps = std::abs(t[k] - (t[0] + static_cast<double>(k) * step)) / step;
    if (off_steps > tolerance && first_off == n) first_off = k;
    if (off_steps > worst_steps) worst_steps = off_steps, worst = k;
  }
  if (first_off < n) {
    const double first_steps = std::abs(t[first_off] - (t[0] + static_cast<double>(first_off) * step)) / step;
    refuse(function,
           fmt::format("the record is not uniformly sampled: t[{}] = {} s lies {:.3g} steps off the uniform grid of "
                       "step {} s (tolerance {} steps; worst: t[{}], {:.3g} steps); filtering and differencing need "
                       "uniform sampling — resample the record first",
                       first_off, t[first_off], first_steps, step, tolerance, worst, worst_steps));
  }
  return 1.0 / step;
}

// ---------------------------------------------------------------- Butterworth low-pass

std::complex<double> ButterworthLowPass::response(double frequency_hz) const {
  const double omega = 2 * std::numbers::pi * frequency_hz / sample_rate_hz;
  const std::complex<double> z1 = std::polar(1.0, -omega), z2 = std::polar(1.0, -2 * omega);
  std::complex<double> h = 1.0;
  for (const SecondOrderSection& s : sections) h *= (s.b0 + s.b1 * z1 + s.b2 * z2) / (1.0 + s.a1 * z1 + s.a2 * z2);
  return h;
}

std::size_t ButterworthLowPass::edge_padding() const {
  std::size_t taps = 2 * sections.size() + 1;
  for (const SecondOrderSection& s : sections)
    if (s.b2 == 0 && s.a2 == 0) --taps;
  return 3 * taps;
}

ButterworthLowPass design_butterworth_low_pass(double cutoff_hz, double sample_rate_hz, int order) {
  constexpr std::string_view function = "design_butterworth_low_pass";
  require_sample_rate(function, sample_rate_hz);
  if (order < 1 || order > 20) refuse(function, fmt::format("the order is {}; it must lie in 1 … 20", order));
  if (!std::isfinite(cutoff_hz) || !(cutoff_hz > 0) || !(cutoff_hz < sample_rate_hz / 2))
    refuse(function, fmt::format("the cut-off is {} Hz; it must lie strictly between 0 and fs/2 = {} Hz "
                                 "(fs = {} Hz)",
                                 cutoff_hz, sample_rate_hz / 2, sample_rate_hz));

  ButterworthLowPass filter;
  filter.order = order;
  filter.cutoff_hz = cutoff_hz;
  filter.sample_rate_hz = sample_rate_hz;

  const double two_fs = 2 * sample_rate_hz;
  const double warped = two_fs * std::tan(std::numbers::pi * cutoff_hz / sample_rate_hz);  // Ω_c [rad/s]
  const auto digital_pole = [&](int k) {
    const double angle = std::numbers::pi * static_cast<double>(2 * k - order + 1) / static_cast<double>(2 * order);
    const std::complex<double> s = -warped * std::polar(1.0, angle);
    return (two_fs + s) / (two_fs - s);
  };
  // p_k and p_{n−1−k} are conjugate: one biquad per k < n/2, plus the real pole.
  for (int k = 0; k < order / 2; ++k) {
    const std::complex<double> pole = digital_pole(k);
    SecondOrderSection section;
    section.a1 = -2 * pole.real();
    section.a2 = std::norm(pole);
    const double gain = (1 + section.a1 + section.a2) / 4;  // zeros at z = −1: numerator gain·(1 + z⁻¹)², 4·gain at DC
    section.b0 = gain, section.b1 = 2 * gain, section.b2 = gain;
    filter.sections.push_back(section);
  }
  if (order % 2 == 1) {
    const double pole = digital_pole((order - 1) / 2).real();
    SecondOrderSection section;
    section.a1 = -pole;
    const double gain = (1 + section.a1) / 2;
    section.b0 = gain, section.b1 = gain;
    filter.sections.push_back(section);
  }
  std::stable_sort(filter.sections.begin(), filter.sections.end(),
                   [](const SecondOrderSection& a, const SecondOrderSection& b) {
                     // pole radius: sqrt(a2) for a pair, |a1| for a real pole
                     const auto radius = [](const SecondOrderSection& s) {
                       return s.a2 != 0 ? std::sqrt(s.a2) : std::abs(s.a1);
                     };
                     return radius(a) < radius(b);
                   });
  return filter;
}

std::vector<double> zero_phase_filter(std::span<const double> x, const ButterworthLowPass& filter) {
  constexpr std::string_view function = "zero_phase_filter";
  if (filter.sections.empty()) refuse(function, "the filter has no sections (not designed)");
  const std::size_t padding = filter.edge_padding();
  const std::size_t n = x.size();
  if (n <= padding)
    refuse(function, fmt::format("the signal has {} samples; the odd extension at its ends needs more than {} "
                                 "(3·(order + 1) for order {})",
                                 n, padding, filter.order));
  require_finite(function, x, "x");

  std::vector<double> extended;
  extended.reserve(n + 2 * padding);
  for (std::size_t j = padding; j >= 1; --j) extended.push_back(2 * x[0] - x[j]);
  extended.insert(extended.end(), x.begin(), x.end());
  for (std::size_t j = 1; j <= padding; ++j) extended.push_back(2 * x[n - 1] - x[n - 1 - j]);

  const auto state = steady_state(filter.sections);
  run_cascade(extended, filter.sections, state, extended.front());
  std::reverse(extended.begin(), extended.end());
  run_cascade(extended, filter.sections, state, extended.front());
  std::reverse(extended.begin(), extended.end());
  return {extended.begin() + static_cast<std::ptrdiff_t>(padding),
          extended.end() - static_cast<std::ptrdiff_t>(padding)};
}

// ---------------------------------------------------------------- derivatives

Derivatives derivatives(std::span<const double> x, double sample_rate_hz) {
  constexpr std::string_view function = "derivatives";
  require_sample_rate(function, sample_rate_hz);
  const std::size_t n = x.size();
  if (n < 4) refuse(function, fmt::format("the signal has {} samples; it needs at least 4", n));
  const double h = 1.0 / sample_rate_hz;
  Derivatives result;
  result.velocity.resize(n);
  result.acceleration.resize(n);
  auto& v = result.velocity;
  auto& a = result.acceleration;
  for (std::size_t k = 1; k + 1 < n; ++k) {
    v[k] = (x[k + 1] - x[k - 1]) / (2 * h);
    a[k] = (x[k + 1] - 2 * x[k] + x[k - 1]) / (h * h);
  }
  v[0] = (-3 * x[0] + 4 * x[1] - x[2]) / (2 * h);
  v[n - 1] = (3 * x[n - 1] - 4 * x[n - 2] + x[n - 3]) / (2 * h);
  a[0] = (2 * x[0] - 5 * x[1] + 4 * x[2] - x[3]) / (h * h);
  a[n - 1] = (2 * x[n - 1] - 5 * x[n - 2] + 4 * x[n - 3] - x[n - 4]) / (h * h);
  return result;
}

// ---------------------------------------------------------------- spectrum

WelchPsd welch_psd(std::span<const double> x, double sample_rate_hz, std::size_t segment) {
  constexpr std::string_view function = "welch_psd";
  require_sample_rate(function, sample_rate_hz);
  if (segment < 2 || segment > x.size())
    refuse(function, fmt::format("the segment is {} samples; it must lie in 2 … {} (the signal's length)", segment,
                                 x.size()));
  require_finite(function, x, "x");

  const std::size_t overlap = segment / 2;
  const std::size_t step = segment - overlap;
  const std::size_t count = (x.size() - overlap) / step;
  const std::size_t bins = segment / 2 + 1;

  std::vector<double> window(segment);
  double window_energy = 0;
  for (std::size_t j = 0; j < segment; ++j) {
    window[j] = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(segment));
    window_energy += window[j] * window[j];
  }
  const double scale = 1.0 / (sample_rate_hz * window_energy);

  WelchPsd psd;
  psd.segment = segment;
  psd.segments = count;
  psd.frequency_hz.resize(bins);
  psd.density.assign(bins, 0.0);
  for (std::size_t k = 0; k < bins; ++k)
    psd.frequency_hz[k] = static_cast<double>(k) * sample_rate_hz / static_cast<double>(segment);

  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> windowed(segment);
  std::vector<std::complex<double>> spectrum;
  for (std::size_t s = 0; s < count; ++s) {
    const double* begin = x.data() + s * step;
    double mean = 0;
    for (std::size_t j = 0; j < segment; ++j) mean += begin[j];
    mean /= static_cast<double>(segment);
    for (std::size_t j = 0; j < segment; ++j) windowed[j] = window[j] * (begin[j] - mean);
    fft.fwd(spectrum, windowed);
    for (std::size_t k = 0; k < bins; ++k) psd.density[k] += std::norm(spectrum[k]);
  }
  for (std::size_t k = 0; k < bins; ++k) {
    const bool single = k == 0 || (segment % 2 == 0 && k == bins - 1);
    psd.density[k] *= (single ? 1.0 : 2.0) * scale / static_cast<double>(count);
  }
  return psd;
}

// ---------------------------------------------------------------- cut-off from the spectrum

CutoffDecision cutoff_from_spectrum(std::span<const double> position, double sample_rate_hz) {
  constexpr std::string_view function = "cutoff_from_spectrum";
  require_sample_rate(function, sample_rate_hz);
  if (position.size() < 64)
    refuse(function, fmt::format("the record has {} samples; the noise floor needs at least 64", position.size()));
  const double fs = sample_rate_hz;

  CutoffDecision decision;
  decision.psd = welch_psd(position, fs, std::min<std::size_t>(2048, position.size()));
  const WelchPsd& psd = decision.psd;
  const std::size_t segment = psd.segment, bins = psd.density.size();

  // The floor: bins k with fs/4 ≤ k·fs/segment ≤ fs/2, i.e. 4k ≥ segment (exact in integers).
  std::vector<double> upper;
  for (std::size_t k = 0; k < bins; ++k)
    if (4 * k >= segment) upper.push_back(psd.density[k]);
  decision.floor_from_hz = fs / 4;
  decision.floor_to_hz = fs / 2;
  decision.noise_floor = median(std::move(upper));
  if (!(decision.noise_floor > 0))
    refuse(function, "the position's spectrum has a zero noise floor above fs/4 (a constant or exactly periodic "
                     "record?): there is no noise to set the cut-off against — give the cut-off explicitly");
  decision.threshold = cutoff_threshold_factor * decision.noise_floor;

  const std::size_t half = cutoff_median_bins / 2;
  decision.smoothed.resize(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    const std::size_t from = k >= half ? k - half : 0, to = std::min(bins - 1, k + half);
    decision.smoothed[k] = median(std::vector<double>(psd.density.begin() + static_cast<std::ptrdiff_t>(from),
                                                      psd.density.begin() + static_cast<std::ptrdiff_t>(to + 1)));
  }
  for (std::size_t k = bins; k-- > 0;)
    if (decision.smoothed[k] > decision.threshold) {
      decision.band_edge_hz = psd.frequency_hz[k];
      break;
    }
  for (std::size_t k = bins; k-- > 0;)
    if (psd.density[k] > decision.threshold) {
      decision.highest_line_hz = psd.frequency_hz[k];
      break;
    }

  decision.lowest_allowed_hz = fs / 100;
  decision.highest_allowed_hz = 0.4 * fs;
  decision.clamped = decision.band_edge_hz < decision.lowest_allowed_hz ||
                     decision.band_edge_hz > decision.highest_allowed_hz;
  decision.cutoff_hz = std::clamp(decision.band_edge_hz, decision.lowest_allowed_hz, decision.highest_allowed_hz);
  return decision;
}

// ---------------------------------------------------------------- correlated residuals

std::vector<double> autocorrelation(std::span<const double> r, std::size_t max_lag) {
  constexpr std::string_view function = "autocorrelation";
  const std::size_t n = r.size();
  if (n < 2) refuse(function, fmt::format("the series has {} samples; it needs at least 2", n));
  require_finite(function, r, "r");
  double mean = 0;
  for (double value : r) mean += value;
  mean /= static_cast<double>(n);

  const std::size_t size = next_power_of_two(2 * n);
  std::vector<double> padded(size, 0.0);
  double energy = 0;
  for (std::size_t j = 0; j < n; ++j) {
    padded[j] = r[j] - mean;
    energy += padded[j] * padded[j];
  }
  if (!(energy > 0))
    refuse(function, fmt::format("all {} samples are equal ({}): the autocorrelation is undefined", n, r[0]));

  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, padded);
  for (auto& value : spectrum) value = std::norm(value);
  std::vector<double> covariance(size);
  fft.inv(covariance.data(), spectrum.data(), static_cast<Eigen::Index>(size));

  const std::size_t last = std::min(max_lag, n - 1);
  std::vector<double> rho(last + 1);
  for (std::size_t k = 0; k <= last; ++k) rho[k] = covariance[k] / covariance[0];
  rho[0] = 1.0;
  return rho;
}

AutocorrelationTime integrated_autocorrelation_time(std::span<const double> r) {
  const std::vector<double> rho = autocorrelation(r, r.size() - (r.empty() ? 0 : 1));
  const std::size_t n = rho.size();  // = r.size()
  AutocorrelationTime result;
  double pairs = 0;
  std::size_t m = 0;
  for (; 2 * m + 1 < n; ++m) {
    const double pair = rho[2 * m] + rho[2 * m + 1];
    if (m >= 1 && !(pair > 0)) break;
    pairs += pair;
  }
  // m pairs (ρ_0 … ρ_{2m−1}) were summed; for n = 1 … never: autocorrelation needs n ≥ 2, so m ≥ 1.
  result.tau = -1 + 2 * pairs;
  result.lags = 2 * m - 1;
  result.rho.assign(rho.begin(), rho.begin() + static_cast<std::ptrdiff_t>(std::min(n, result.lags + 3)));
  return result;
}

// ---------------------------------------------------------------- the whole step

InverseDynamicsSignals inverse_dynamics_signals(std::span<const double> t, std::span<const double> position,
                                                std::span<const double> drive, std::optional<double> cutoff_hz,
                                                int order) {
  constexpr std::string_view function = "inverse_dynamics_signals";
  if (position.size() != t.size() || drive.size() != t.size())
    refuse(function, fmt::format("the columns differ in length: t {}, position {}, drive {}", t.size(),
                                 position.size(), drive.size()));
  InverseDynamicsSignals signals;
  signals.sample_rate_hz = uniform_sample_rate(t);
  if (!cutoff_hz) {
    signals.decision = cutoff_from_spectrum(position, signals.sample_rate_hz);
    cutoff_hz = signals.decision->cutoff_hz;
  }
  signals.filter = design_butterworth_low_pass(*cutoff_hz, signals.sample_rate_hz, order);
  signals.position = zero_phase_filter(position, signals.filter);
  signals.drive = zero_phase_filter(drive, signals.filter);
  Derivatives rates = derivatives(signals.position, signals.sample_rate_hz);
  signals.velocity = std::move(rates.velocity);
  signals.acceleration = std::move(rates.acceleration);
  return signals;
}

}  // namespace backlash::measurements
