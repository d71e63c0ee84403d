// backlash/measurements/inverse_dynamics_signals.hpp — velocity, acceleration
// and the filtered drive of a measured record, for inverse dynamics.
//
// The discrepancy workflow on a real servo record compares the measured drive
// u(t) with the drive the model needs along the measured motion,
// J·q'' + F·q' + ...  The measured position q is quantised (EMPS: an encoder
// quantum of 5e-8 m at 1 kHz), so q' and q'' are taken from a low-pass
// filtered q, and u is filtered with the SAME filter (parallel filtering):
// both sides of u ≈ J·q'' + F·q' + ... then see the same band, and a linear
// model fitted on the filtered signals has the parameters of the unfiltered one.
//
// The steps, each a function below:
//   uniform_sample_rate      t → fs, refusing a record that is not uniformly sampled
//   cutoff_from_spectrum     q → fc, from where q's spectrum meets the encoder's noise
//   design_butterworth_low_pass  (fc, fs, order) → second-order sections
//   zero_phase_filter        forward–backward filtering, as SciPy's sosfiltfilt
//   derivatives              filtered q → q', q'' by second-order differences
//   welch_psd                the spectrum cutoff_from_spectrum reads
//   integrated_autocorrelation_time   τ_int of the fit's residuals: n_eff = n/τ_int
// and inverse_dynamics_signals() runs the first five in that order.
//
// Every function is pure and thread-safe.  Bad arguments (too few samples, a
// cut-off outside (0, fs/2), a non-finite sample, a time vector that is not
// uniform) throw std::invalid_argument whose what() is one line naming the
// function, the offending quantity and its allowed range.
//
// Pinned against SciPy 1.10 (scipy.signal.butter/sosfiltfilt/welch,
// numpy.gradient) by tests/measurements/exam_inverse_dynamics_signals.cpp with
// the reference written by tests/measurements/reference/make_filter_reference.py.
#pragma once

#include <complex>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace backlash::measurements {

// ---------------------------------------------------------------- sampling

/// Default tolerance of uniform_sample_rate, in sampling steps.
inline constexpr double default_sampling_tolerance = 1e-3;

/// The sample rate fs [Hz] of a uniformly sampled record.
///
/// With h = (t[n−1] − t[0])/(n − 1) (the mean step), every sample must lie on
/// the uniform grid within `tolerance` steps:  |t[k] − (t[0] + k·h)| ≤ tolerance·h.
/// Checking the grid rather than each step also catches a slow drift of the
/// step, which would shift late samples by many steps while every single step
/// looks fine.  Returns fs = 1/h.
///
/// The default, 1e-3 of a step, accepts the EMPS records (their time stamps lie
/// within 3.2e-5 steps of the 1 ms grid: individual steps 1 ms ± 2.4e-8 s) and
/// refuses any real jitter: treating a sample taken δ late as on the grid is an
/// error of q'·δ, at most 1e-3·h·q' — under a thousandth of what the sample
/// moved in a step.
/// Errors (std::invalid_argument): fewer than 2 samples, a non-finite time,
/// t not strictly increasing, tolerance not in (0, 0.5), and a sample off the
/// grid — the message names the first such sample, its time, how many steps it
/// lies off the grid, and the worst deviation in the record.
double uniform_sample_rate(std::span<const double> t, double tolerance = default_sampling_tolerance);

// ---------------------------------------------------------------- Butterworth low-pass

/// One biquad, a0 = 1:  H(z) = (b0 + b1·z⁻¹ + b2·z⁻²)/(1 + a1·z⁻¹ + a2·z⁻²).
/// A first-order section has b2 = a2 = 0.
struct SecondOrderSection {
  double b0 = 0, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
};

/// A digital Butterworth low-pass of order n as a cascade of ⌈n/2⌉ sections.
///
/// Design (as scipy.signal.butter(n, fc, fs=fs, output='sos') does): the
/// analogue prototype's poles p_k = −exp(iπ(2k − n + 1)/(2n)), k = 0 … n−1
/// (unit circle, left half-plane), scaled by the prewarped cut-off
/// Ω_c = 2·fs·tan(π·fc/fs) [rad/s], mapped by the bilinear transform
/// z = (2fs + s)/(2fs − s); the n zeros at s = ∞ go to z = −1.  Conjugate pole
/// pairs make biquads, the real pole of an odd order a first-order section;
/// sections in order of increasing pole radius (the most damped first, as
/// SciPy orders them).  Each is scaled to unit gain at DC, so the cascade is too.
///
/// One pass, exactly (prewarping maps fc onto Ω_c):
///   |H(f)|² = 1 / (1 + (tan(π·f/fs) / tan(π·fc/fs))^(2n)),   0 ≤ f ≤ fs/2,
/// so |H(0)| = 1, |H(fc)| = 1/√2 (−3.01 dB), falling monotonically to 0 at fs/2.
/// The sections differ from SciPy's in how the gain is spread (SciPy puts it
/// all in the first); the product H(z) is the same.
struct ButterworthLowPass {
  int order = 0;
  double cutoff_hz = 0;       ///< fc: the −3 dB point of one pass
  double sample_rate_hz = 0;  ///< fs
  std::vector<SecondOrderSection> sections;

  /// H(exp(2πi·f/fs)) of one pass: the product of the sections' responses.
  std::complex<double> response(double frequency_hz) const;

  /// Samples of odd extension zero_phase_filter adds at each end:
  /// 3·(order + 1), SciPy's sosfiltfilt default padlen for these sections
  /// (3·(2·sections + 1) less one per first-order section).  15 for order 4.
  std::size_t edge_padding() const;
};

/// Designs the filter.  Errors (std::invalid_argument): fs not finite or ≤ 0,
/// fc not finite, fc ≤ 0, fc ≥ fs/2 (the Nyquist frequency), order not in 1 … 20.
ButterworthLowPass design_butterworth_low_pass(double cutoff_hz, double sample_rate_hz, int order = 4);

/// The filter run forward–backward (scipy.signal.sosfiltfilt with its defaults):
///  1. x is extended at each end by P = filter.edge_padding() samples of odd
///     extension: x_ext[−j] = 2·x[0] − x[j], x_ext[n−1+j] = 2·x[n−1] − x[n−1−j];
///  2. the cascade runs forward over x_ext (direct form II transposed), each
///     section starting from its steady state for a constant input
///     (scipy.signal.sosfilt_zi) scaled by x_ext's first sample;
///  3. it runs backward over that output, starting from the steady state
///     scaled by that output's last sample;
///  4. the P samples at each end are dropped.
/// In the steady state (away from the ends) the result is x filtered by the
/// zero-phase |H(f)|²: a sinusoid comes out in phase with gain |H(f)|²,
/// −6.02 dB at fc, and a constant comes out unchanged (also at the ends).
/// The end transients are those of SciPy's sosfiltfilt: the same algorithm,
/// so the two agree to rounding (about 1e-13 relative, the test allows 1e-10).
/// Errors (std::invalid_argument): a non-finite sample, and x.size() ≤ P
/// ("needs more than P samples", as SciPy refuses).
std::vector<double> zero_phase_filter(std::span<const double> x, const ButterworthLowPass& filter);

// ---------------------------------------------------------------- derivatives

struct Derivatives {
  std::vector<double> velocity;      ///< x' [unit of x per s]
  std::vector<double> acceleration;  ///< x'' [unit of x per s²]
};

/// First and second derivatives of a uniformly sampled x (h = 1/fs), both
/// second-order accurate at every sample:
///   velocity:      (x[k+1] − x[k−1])/(2h) inside; at the ends
///                  (−3x[0] + 4x[1] − x[2])/(2h) and (3x[n−1] − 4x[n−2] + x[n−3])/(2h)
///                  — exactly numpy.gradient(x, h, edge_order=2);
///                  error +(h²/6)·x''' inside, −(h²/3)·x''' at the ends (leading terms).
///   acceleration:  (x[k+1] − 2x[k] + x[k−1])/h² inside; at the ends
///                  (2x[0] − 5x[1] + 4x[2] − x[3])/h² and the mirror image
///                  (the one-sided four-point second-order stencil);
///                  error +(h²/12)·x'''' inside, −(11/12)·h²·x'''' at the ends.
/// Both are exact for quadratics, the acceleration also for cubics.
/// NOT numpy.gradient applied twice: that has the wide stencil
/// (x[k+2] − 2x[k] + x[k−2])/(4h²) inside (error (h²/3)·x'''', four times
/// larger), and only first-order accuracy at the two samples at each end.
/// Errors (std::invalid_argument): fewer than 4 samples, fs not finite or ≤ 0.
Derivatives derivatives(std::span<const double> x, double sample_rate_hz);

// ---------------------------------------------------------------- spectrum

/// A one-sided power spectral density.
struct WelchPsd {
  std::vector<double> frequency_hz;  ///< k·fs/segment, k = 0 … segment/2 (integer division)
  std::vector<double> density;       ///< [unit of x² per Hz]
  std::size_t segment = 0;           ///< samples per segment
  std::size_t segments = 0;          ///< segments averaged
};

/// Welch's estimate, as scipy.signal.welch(x, fs, nperseg=segment) with its
/// defaults: segments of `segment` samples starting every segment − ⌊segment/2⌋
/// samples (50 % overlap; (n − ⌊segment/2⌋) div that step segments, samples
/// after the last one unused), each with its mean removed, multiplied by the
/// periodic Hann window w[j] = ½ − ½·cos(2πj/segment), transformed (Eigen's FFT);
/// then P_k = c_k·|X_k|² / (fs·Σw²) with c_k = 2 except at DC and, for an even
/// segment, at fs/2 (c = 1), averaged over the segments.
/// Scaled so that Σ_k P_k·fs/segment is the windowed mean square Σ(w·x)²/Σw²
/// (Parseval): white noise of variance σ² gives the level σ²/(fs/2), a sinusoid
/// of amplitude A on bin k0 gives A²·segment/(3·fs) at k0 and a quarter of that
/// at k0 ± 1, together A²/2 times the bin width.
/// Errors (std::invalid_argument): segment < 2 or > x.size(), a non-finite
/// sample, fs not finite or ≤ 0.
WelchPsd welch_psd(std::span<const double> x, double sample_rate_hz, std::size_t segment);

// ---------------------------------------------------------------- cut-off from the spectrum

/// Why cutoff_from_spectrum chose its cut-off: everything a page needs to show
/// the decision (plot psd and smoothed against frequency, the floor and the
/// threshold as horizontal lines, the cut-off as a vertical one).
struct CutoffDecision {
  double cutoff_hz = 0;           ///< fc to design the filter with (after clamping)
  double noise_floor = 0;         ///< median of psd.density over [floor_from_hz, floor_to_hz]
  double floor_from_hz = 0;       ///< fs/4
  double floor_to_hz = 0;         ///< fs/2
  double threshold = 0;           ///< threshold_factor · noise_floor
  double band_edge_hz = 0;        ///< highest frequency whose smoothed PSD exceeds the threshold (0: none)
  double highest_line_hz = 0;     ///< highest frequency whose raw PSD exceeds it (0: none) — may be a narrow line
  double lowest_allowed_hz = 0;   ///< fs/100
  double highest_allowed_hz = 0;  ///< 0.4·fs
  bool clamped = false;           ///< band_edge_hz was outside [lowest, highest] allowed
  WelchPsd psd;                   ///< the position's spectrum
  std::vector<double> smoothed;   ///< psd.density after the running median
};

/// Factor by which the motion must stand above the noise floor: 100 (20 dB).
inline constexpr double cutoff_threshold_factor = 100.0;
/// Width of the running median, in frequency bins.
inline constexpr std::size_t cutoff_median_bins = 9;

/// The cut-off the workflow uses unless the user sets one: the band in which
/// the measured motion stands 20 dB above the encoder's noise.
///  1. psd = welch_psd(position, fs, min(2048, n));
///  2. noise floor = median of psd over fs/4 ≤ f ≤ fs/2 (the upper half of the
///     band, where a servo's motion has long died out and only quantisation
///     and sensor noise remain; for an even count the mean of the middle two);
///  3. smoothed = running median of psd over `cutoff_median_bins` = 9 bins
///     (the window truncated at the ends of the spectrum);
///  4. band edge = the highest frequency at which smoothed > 100·floor;
///  5. fc = band edge clamped to [fs/100, 0.4·fs] (fs/100 when nothing exceeds).
/// Step 3 is why narrow spectral lines do not set the cut-off: a sinusoid's
/// power lies in the Hann window's main lobe, 4 bins wide, fewer than the 5
/// of 9 a running median needs, so the median removes the line (unless its
/// side lobes, 31 dB down and falling, stand above the threshold themselves),
/// while a band of motion wider than 5 bins (2.4 Hz at 2048 samples and
/// fs = 1 kHz) keeps its edge.  On the
/// EMPS estimation record the raw rule ("highest frequency above 100·floor")
/// would stop at a narrow line at 99.1–100.1 Hz (likely 2 × 50 Hz ripple, about
/// 0.4 encoder quanta in amplitude, 8 × above its neighbours); the smoothed
/// one finds the edge of the motion at 84.96 Hz (floor 5.587e-19 m²/Hz,
/// SciPy's welch gives the same).  highest_line_hz keeps the raw answer so a
/// page can say what was passed over.
/// Errors (std::invalid_argument): fewer than 64 samples (the floor is then a
/// median of at least 17 bins), a non-finite sample, fs not finite or ≤ 0,
/// a zero floor (a constant or exactly periodic record: no noise to measure).
CutoffDecision cutoff_from_spectrum(std::span<const double> position, double sample_rate_hz);

// ---------------------------------------------------------------- correlated residuals

/// ρ_k = c_k/c_0 for k = 0 … max_lag, with c_k = (1/n)·Σ_{j<n−k} (r_j − r̄)(r_{j+k} − r̄)
/// (the biased estimator, so ρ is positive semi-definite), computed by FFT:
/// zero-padded to a power of two ≥ 2n, hence no circular wrap-around; the
/// cost is O(n log n) whatever max_lag.  max_lag is clamped to n − 1.
/// Errors (std::invalid_argument): fewer than 2 samples, a non-finite sample,
/// all samples equal (c_0 = 0).
std::vector<double> autocorrelation(std::span<const double> r, std::size_t max_lag);

struct AutocorrelationTime {
  double tau = 1;        ///< τ_int [samples]
  std::size_t lags = 0;  ///< ρ_1 … ρ_lags were summed
  std::vector<double> rho;  ///< ρ_0 … ρ_{lags+2} (as far as the record goes): what was read, for a page
};

/// The integrated autocorrelation time τ_int = 1 + 2·Σ_{k≥1} ρ_k, so that the
/// mean of n correlated samples varies like that of n_eff = n/τ_int
/// independent ones (the workflow's n for BIC and its covariance inflation).
/// The sum is truncated by Geyer's initial positive sequence (Geyer 1992): with
/// Γ_m = ρ_{2m} + ρ_{2m+1}, sum Γ_0, Γ_1, … up to but excluding the first
/// m ≥ 1 with Γ_m ≤ 0, and τ_int = −1 + 2·Σ Γ_m (= 1 + 2·Σ_{k=1}^{lags} ρ_k,
/// lags = 2M − 1 for M pairs).  Pairs rather than single ρ_k, so an
/// alternating, negatively correlated series is summed correctly instead of
/// stopping at ρ_1 < 0.  AR(1) with coefficient a: τ_int = (1 + a)/(1 − a).
/// Statistical error (Sokal): sd(τ) ≈ τ·sqrt(2·(2·lags + 1)/n).
/// τ_int may come out below 1 (anti-correlated residuals: n_eff > n) and, for
/// strongly anti-correlated ones (ρ_1 near −½), near 0; a caller reducing n
/// for BIC should use max(τ_int, 1).  Errors: as autocorrelation().
AutocorrelationTime integrated_autocorrelation_time(std::span<const double> r);

// ---------------------------------------------------------------- the whole step

/// What inverse dynamics on a measured record needs, all of length n.
struct InverseDynamicsSignals {
  double sample_rate_hz = 0;
  ButterworthLowPass filter;
  std::optional<CutoffDecision> decision;  ///< set when the cut-off came from the spectrum
  std::vector<double> position;      ///< zero_phase_filter(position)
  std::vector<double> velocity;      ///< derivatives(filtered position)
  std::vector<double> acceleration;
  std::vector<double> drive;         ///< zero_phase_filter(drive), the same filter
};

/// uniform_sample_rate(t); the cut-off `cutoff_hz` if given, else
/// cutoff_from_spectrum(position); design_butterworth_low_pass(fc, fs, order);
/// position and drive filtered by zero_phase_filter; derivatives of the
/// filtered position.  Errors: those of the steps, and columns of other
/// lengths than t.
InverseDynamicsSignals inverse_dynamics_signals(std::span<const double> t, std::span<const double> position,
                                                std::span<const double> drive,
                                                std::optional<double> cutoff_hz = std::nullopt, int order = 4);

}  // namespace backlash::measurements
