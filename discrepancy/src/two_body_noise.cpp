// The torque residual's noise level on a drive with a gap (docs/discrepancy.md, "Measured drive
// with a gap", "Noise level"): the encoders' quantisation and the logged drive's own noise,
// propagated through the zero-phase filter, the differences and the summed equation.
#include "two_body_signals.hpp"

#include "drive_internal.hpp"
#include "internal.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace backlash::discrepancy::two_body {

namespace {

// σ of an encoder's error: its step/√12 when the record is whole counts of a step
// (detail::quantum_of), else the Δ⁴ estimate of the position as the rigid workflow's.
double encoder_sigma(const std::vector<double>& q, double& step) {
  step = detail::quantum_of(q);
  return step > 0 ? step / std::sqrt(12.0) : estimate_noise(q);
}

// σ of the logged drive's own noise.  Not Δ⁴ of the drive: a digital position loop reacts to
// every change of the encoders' counts with a step of its command (a real torque, logged and
// applied), which the Δ⁴ rule counts as noise (on the generator's records 15× the true σ).  So
// the drive's band above the cut-off (x − filter(x)) less its least-squares fit on the same band
// of both encoders' counts at lags 0–3 (a linear controller's reaction to them: proportional,
// differences, a short filter); σ is the robust scale (1.4826·median |e|) of what remains, over
// the white noise's share of that band (Σ(δ − h)²).  A controller acting on more than the
// encoders' last four counts leaves part of its reaction in: an upper bound then.
double drive_sigma(const Signals& s, const detail::NoiseGains& g) {
  constexpr std::size_t lags = 4;
  auto high = [&](const std::vector<double>& x) {
    std::vector<double> out = measurements::zero_phase_filter(x, s.filter);
    for (std::size_t k = 0; k < x.size(); ++k) out[k] = x[k] - out[k];
    return out;
  };
  std::vector<std::vector<double>> encoders{high(s.qm)};
  if (s.load_logged()) encoders.push_back(high(s.qL));
  const std::vector<double> u = high(s.u);
  const std::size_t first = std::max(s.begin, lags - 1), rows = s.end > first ? s.end - first : 0;
  if (rows < 50) return estimate_noise(s.u);
  Eigen::MatrixXd A(rows, static_cast<Eigen::Index>(encoders.size() * lags + 1));
  Eigen::VectorXd y(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    const std::size_t k = first + i;
    Eigen::Index c = 0;
    A(i, c++) = 1;
    for (const std::vector<double>& e : encoders)
      for (std::size_t j = 0; j < lags; ++j) A(i, c++) = e[k - j];
    y(i) = u[k];
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(y);
  std::vector<double> e(rows);
  for (std::size_t i = 0; i < rows; ++i) e[i] = std::fabs(y(i) - A.row(i).dot(x));
  std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(rows / 2), e.end());
  return 1.4826 * e[rows / 2] / std::sqrt(std::max(g.high, 1e-12));
}

}  // namespace

TwoBodyNoise noise_level(const Signals& s, const Theta& m) {
  // No delay on a drive with a gap: the hold's weights ½, ½ on the sample and the one before.
  const detail::NoiseGains g = detail::noise_gains(s.filter, s.fs, 0);
  TwoBodyNoise n;
  n.sigma_motor = encoder_sigma(s.qm, n.step_motor);
  n.sigma_drive = drive_sigma(s, g);
  n.drive = n.sigma_drive * std::sqrt(g.hold);
  // Both encoders: each body's inverse dynamics on its own encoder.  The motor encoder alone: the
  // observed load rides on the motor's counts in contact, so the motor's error is carried with
  // the two bodies' inertia and viscous friction.
  const double J = s.load_logged() ? m[kJm] : m[kJm] + m[kJL], F = s.load_logged() ? m[kFm] : m[kFm] + m[kFL];
  n.motor = n.sigma_motor * std::sqrt(J * J * g.acceleration + F * F * g.velocity);
  if (s.load_logged()) {
    n.sigma_load = encoder_sigma(s.qL, n.step_load);
    n.load = n.sigma_load * std::sqrt(m[kJL] * m[kJL] * g.acceleration + m[kFL] * m[kFL] * g.velocity);
  }
  n.level = std::sqrt(n.drive * n.drive + n.motor * n.motor + n.load * n.load);
  return n;
}

}  // namespace backlash::discrepancy::two_body
