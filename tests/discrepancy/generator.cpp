#include "generator.hpp"

#include "backlash/numeric/odeint_effects_simulation.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

namespace backlash::generated_data {

measurements::MeasuredRecord generate_record(const RecordSpec& spec) {
  numeric::SimulationOptions o;
  o.t_end = spec.duration;
  std::mt19937_64 clock_random(spec.seed + 7919);
  std::uniform_real_distribution<double> jitter(-spec.jitter, spec.jitter);
  for (double t = 0; t <= spec.duration + 1e-9; t += 1 / spec.rate)
    if (t >= spec.start) o.sample_times.push_back(spec.jitter > 0 && t > 0 ? t + jitter(clock_random) / spec.rate : t);
  o.t_end = o.sample_times.back() + 1e-9;
  numeric::OdeintSimulationOptions tight;
  tight.tolerance = 1e-12;
  const numeric::SimulationResult r =
      numeric::simulate_effects_step_with_odeint(spec.parameters, spec.effects, spec.step, o, tight);
  if (r.status != numeric::SimulationStatus::Completed && r.status != numeric::SimulationStatus::Rest)
    throw std::runtime_error(std::string("generator: the simulation ended ") + numeric::to_string(r.status));
  std::mt19937_64 random(spec.seed);
  std::normal_distribution<double> gaussian(0, spec.noise * std::fabs(spec.step));
  // AR(1) noise of the same stationary σ per column: e ← a·e + √(1 − a²)·w.
  const double a = spec.noise_correlation > 0 ? std::exp(-1 / spec.noise_correlation) : 0;
  double state[3] = {0, 0, 0};
  bool started = false;
  std::mt19937_64 spike_random(spec.seed + 104729);
  std::uniform_real_distribution<double> unit(0, 1);
  int column = 0;
  auto measure = [&](double value) {
    double e = gaussian(random);
    if (a > 0) e = state[column] = started ? a * state[column] + std::sqrt(1 - a * a) * e : e;
    column = (column + 1) % 3;
    if (column == 0) started = true;
    const double noisy = value + e;
    return spec.quantum > 0 ? spec.quantum * std::round(noisy / spec.quantum) : noisy;
  };
  measurements::MeasuredRecord record;
  std::vector<double> motor, load;
  for (const numeric::TrajectorySample& s : r.samples) {
    record.t.push_back(s.t);
    const double drift = spec.drift * s.t + spec.hum * std::sin(2 * M_PI * spec.hum_frequency * s.t);
    record.theta_out.push_back(measure(s.theta_o + drift));
    motor.push_back(measure(s.theta_m + drift));
    load.push_back(measure(s.theta_L + drift));
    if (spec.spike_fraction > 0 && unit(spike_random) < spec.spike_fraction) {
      const double spike = (unit(spike_random) < 0.5 ? -1 : 1) * spec.spike_size * spec.noise * std::fabs(spec.step);
      record.theta_out.back() += spike, motor.back() += spike, load.back() += spike;
    }
  }
  if (spec.motor_column) record.theta_motor = motor;
  if (spec.load_column) record.theta_load = load;
  record.source = "generated";
  return record;
}

}  // namespace backlash::generated_data
