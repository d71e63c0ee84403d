#include "generator.hpp"

#include "backlash/numeric/odeint_effects_simulation.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

namespace backlash::generated_data {

measurements::MeasuredRecord generate_record(const RecordSpec& spec) {
  numeric::SimulationOptions o;
  o.t_end = spec.duration;
  for (double t = 0; t <= spec.duration + 1e-9; t += 1 / spec.rate) o.sample_times.push_back(t);
  o.t_end = o.sample_times.back() + 1e-9;
  numeric::OdeintSimulationOptions tight;
  tight.tolerance = 1e-12;
  const numeric::SimulationResult r =
      numeric::simulate_effects_step_with_odeint(spec.parameters, spec.effects, spec.step, o, tight);
  if (r.status != numeric::SimulationStatus::Completed && r.status != numeric::SimulationStatus::Rest)
    throw std::runtime_error(std::string("generator: the simulation ended ") + numeric::to_string(r.status));
  std::mt19937_64 random(spec.seed);
  std::normal_distribution<double> gaussian(0, spec.noise * std::fabs(spec.step));
  auto measure = [&](double value) {
    const double noisy = value + gaussian(random);
    return spec.quantum > 0 ? spec.quantum * std::round(noisy / spec.quantum) : noisy;
  };
  measurements::MeasuredRecord record;
  std::vector<double> motor, load;
  for (const numeric::TrajectorySample& s : r.samples) {
    record.t.push_back(s.t);
    record.theta_out.push_back(measure(s.theta_o));
    motor.push_back(measure(s.theta_m));
    load.push_back(measure(s.theta_L));
  }
  if (spec.motor_column) record.theta_motor = motor;
  if (spec.load_column) record.theta_load = load;
  record.source = "generated";
  return record;
}

}  // namespace backlash::generated_data
