// discrepancy/src/drive_internal.hpp (internal) — what the measured-drive workflow's two models
// share: the band (drive_workflow.cpp) that the rigid drive and the drive with a gap
// (two_body_drive.cpp) are compared in.
#pragma once

#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/measurements/inverse_dynamics_signals.hpp"

#include <cmath>
#include <cstddef>
#include <vector>

namespace backlash::discrepancy::detail {

/// The zero-phase low-pass the torque domain is compared through, its effective length and the
/// speed below which a sample is at rest.
struct DriveBand {
  measurements::ButterworthLowPass filter;
  double cutoff = 0, floor = NAN;
  bool from_spectrum = true;
  double rest_speed = 0;
  std::size_t edge = 0;  ///< samples left out at each end of a record
};

/// The band of a record with position q and drive torque u (the cut-off the user's or from q's
/// spectrum); fills the result's band and noise fields.
DriveBand drive_band(const std::vector<double>& q, const std::vector<double>& u, double fs, const DriveOptions& options,
                     DriveDiscrepancyResult& result);

/// The filter's effective length [samples] (its impulse response outside ±m holds at most 10⁻⁴
/// of its absolute sum), plus two for the difference stencils.
std::size_t drive_filter_edge(const measurements::ButterworthLowPass& filter);

/// The sums of squares of the impulse responses of the operators a torque residual applies to
/// white noise: the held drive (the hold's weights at `delay_samples`, then the filter), the
/// filter then the first and second differences (velocity, acceleration; `fs` the sampling
/// rate), and the filter's complement δ − h (the band above the cut-off).
struct NoiseGains {
  double hold = 0, velocity = 0, acceleration = 0, high = 0;
};
NoiseGains noise_gains(const measurements::ButterworthLowPass& filter, double fs, double delay_samples);

}  // namespace backlash::discrepancy::detail
