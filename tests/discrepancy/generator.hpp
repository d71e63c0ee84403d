// tests/discrepancy/generator.hpp — measured records in which an effect is hidden.
//
// The record comes from the INDEPENDENT Boost.Odeint simulator with effects
// (odeint_effects_simulation.hpp), never from the closed-form code path the
// discrepancy workflow fits with.  Sampled at a chosen rate, Gaussian noise of a
// chosen level (a fraction of the step) added, optionally quantised like an
// encoder, with or without the theta_motor / theta_load columns.
#pragma once

#include "backlash/measurements/measured_record.hpp"
#include "backlash/numeric/effects.hpp"

#include <cstdint>
#include <string>

namespace backlash::generated_data {

struct RecordSpec {
  numeric::Parameters parameters;
  numeric::Effects effects;       ///< the hidden effect(s)
  double step = 1;
  double duration = 30;           ///< [s]
  double rate = 100;              ///< samples per second
  double noise = 0.001;           ///< σ as a fraction of |step|
  double quantum = 0;             ///< encoder resolution [rad] (0: none)
  bool motor_column = false, load_column = false;
  std::uint64_t seed = 1;
  // Measurement as real machines make it (all off by default: the records above are unchanged).
  double noise_correlation = 0;   ///< AR(1) noise, correlation length in samples (a = e^(−1/ℓ)); 0: white
  double spike_fraction = 0;      ///< this fraction of samples gets a spike of ±spike_size σ
  double spike_size = 20;
  double jitter = 0;              ///< each time stamp moved by up to ±jitter sample intervals (uniform)
  double start = 0;               ///< samples before this time are dropped (a record started late)
  double drift = 0;               ///< a sensor drift [rad/s] added to every column (outside the vocabulary)
  double hum = 0, hum_frequency = 0;  ///< a sinusoidal pickup hum·sin(2π·f·t) [rad] on every column (outside the vocabulary)
};

/// The record, or throws std::runtime_error when the simulation does not end normally.
measurements::MeasuredRecord generate_record(const RecordSpec& spec);

}  // namespace backlash::generated_data
