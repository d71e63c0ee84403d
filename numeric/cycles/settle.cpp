// settle.cpp — the settle time of a step response (settle.hpp; docs/design.md, "Design-space maps").
#include "backlash/numeric/settle.hpp"

#include <cmath>
#include <optional>
#include <vector>

namespace backlash::numeric {

namespace {

// The one place this file reads a cycle's status text.
bool has_cycle(const LimitCycle& cycle) { return cycle.status == CycleStatus::LimitCycle; }

// θo at the sample k·h (h = t_end / samples) the simulator computed.
struct Sample {
  long long k;
  double theta_o;
};

// The band of a run that did not stop at rest (settle.hpp): the cycle's extremes, or θR, ± tol.
SimulationOptions::SampleBand moving_band(const Parameters& p, const LimitCycle& cycle, double tol) {
  if (has_cycle(cycle)) return {cycle.theta_o_min - tol, cycle.theta_o_max + tol};
  return {p.theta_R - tol, p.theta_R + tol};
}

// The samples, all of them or (`band`) those the last one outside the band needs
// (SimulationOptions::sample_band).
SimulationOptions sampled(const SettleOptions& o, std::vector<Sample>& theta_o,
                          std::optional<SimulationOptions::SampleBand> band) {
  SimulationOptions s;
  s.t_end = o.t_end;
  s.sample_interval = o.t_end / o.samples;
  s.sample_band = band;
  theta_o.reserve(static_cast<std::size_t>(o.samples) + 2);
  s.sample_sink = [&theta_o, h = s.sample_interval](const TrajectorySample& x) {
    theta_o.push_back({std::llround(x.t / h), x.theta_o});  // t = k·h exactly (TrajectoryRecorder)
  };
  return s;
}

// The index of the last sample of a run to t_end: the largest k with k·h ≤ t_end + 1e-12, as the
// recorder takes them (hybrid_simulation.hpp).
long long last_sample(const SettleOptions& o) {
  const double h = o.t_end / o.samples;
  long long k = o.samples;
  while (static_cast<double>(k) * h > o.t_end + 1e-12) --k;
  while (static_cast<double>(k + 1) * h <= o.t_end + 1e-12) ++k;
  return k;
}

// The band (settle.hpp) and the first sample time after which every sample stays in it.  A run
// with samples left out (SimulationOptions::sample_band) recorded the last one outside the band and
// every one near its edges: the others lie inside, or before a later one outside.
Settle judge(const SimulationResult& run, const std::vector<Sample>& theta_o, const Parameters& p,
             const LimitCycle& cycle, const SettleOptions& o) {
  Settle s;
  if (stopped_early(run.status)) {
    s.status = to_string(run.status);
    return s;
  }
  const double tol = o.fraction * std::fabs(o.step);
  const SimulationOptions::SampleBand band = run.status == SimulationStatus::Rest
                                                 ? SimulationOptions::SampleBand{run.theta_o_final - tol, run.theta_o_final + tol}
                                                 : moving_band(p, cycle, tol);
  s.band_low = band.low, s.band_high = band.high;
  // After rest the state is frozen at θ∞: the samples the simulator did not record lie in the band.
  auto inside = [&](double x) { return x >= s.band_low && x <= s.band_high; };
  std::size_t n = theta_o.size();  // one past the last sample outside
  while (n > 0 && inside(theta_o[n - 1].theta_o)) --n;
  const bool thinned = run.samples_left_out > 0;
  const bool last_outside = thinned ? n > 0 && n == theta_o.size() && theta_o.back().k == last_sample(o)
                                    : theta_o.empty() || n == theta_o.size();
  if (run.status != SimulationStatus::Rest && last_outside) {
    s.status = "not_settled";
    return s;
  }
  s.status = "settled";
  s.time = static_cast<double>(n == 0 ? 0 : theta_o[n - 1].k + 1) * o.t_end / o.samples;
  return s;
}

// The settle time from `simulate(options)`: with samples left out by the moving band, again with
// all of them when that run stopped at rest after leaving some out (its band is θ∞'s).
template <class Simulate>
Settle settled(const Simulate& simulate, const Parameters& p, const LimitCycle& cycle, const SettleOptions& o) {
  std::vector<Sample> theta_o;
  SimulationResult run = simulate(sampled(o, theta_o, moving_band(p, cycle, o.fraction * std::fabs(o.step))));
  if (run.status == SimulationStatus::Rest && run.samples_left_out > 0) {
    theta_o.clear();
    run = simulate(sampled(o, theta_o, std::nullopt));
  }
  return judge(run, theta_o, p, cycle, o);
}

}  // namespace

Settle settle_time(const ValidatedEffectModel& model, const LimitCycle& cycle, const SettleOptions& options) {
  if (options.step == 0 || options.samples < 1 || !(options.t_end > 0)) return {};
  const auto simulate = [&](const SimulationOptions& o) { return simulate_effects_step(model, options.step, o); };
  return settled(simulate, model.parameters(), cycle, options);
}

Settle settle_time(const ValidatedEvaluator& evaluator, const LimitCycle& cycle, const SettleOptions& options) {
  if (options.step == 0 || options.samples < 1 || !(options.t_end > 0)) return {};
  const auto simulate = [&](const SimulationOptions& o) { return simulate_step(evaluator, options.step, o); };
  return settled(simulate, evaluator.parameters(), cycle, options);
}

}  // namespace backlash::numeric
