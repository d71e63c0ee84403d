// settle.cpp — the settle time of a step response (settle.hpp; docs/design.md, "Design-space maps").
#include "backlash/numeric/settle.hpp"

#include <vector>

namespace backlash::numeric {

namespace {

// The one place this file reads a cycle's status text.
bool has_cycle(const LimitCycle& cycle) { return cycle.status == CycleStatus::LimitCycle; }

SimulationOptions sampled(const SettleOptions& o, std::vector<double>& theta_o) {
  SimulationOptions s;
  s.t_end = o.t_end;
  s.sample_interval = o.t_end / o.samples;
  theta_o.reserve(static_cast<std::size_t>(o.samples) + 2);
  s.sample_sink = [&theta_o](const TrajectorySample& x) { theta_o.push_back(x.theta_o); };
  return s;
}

// The band (settle.hpp) and the first sample time after which every sample stays in it.
Settle judge(const SimulationResult& run, const std::vector<double>& theta_o, const Parameters& p,
             const LimitCycle& cycle, const SettleOptions& o) {
  Settle s;
  if (stopped_early(run.status)) {
    s.status = to_string(run.status);
    return s;
  }
  const double tol = o.fraction * std::fabs(o.step);
  if (run.status == SimulationStatus::Rest) {
    s.band_low = run.theta_o_final - tol, s.band_high = run.theta_o_final + tol;
  } else if (has_cycle(cycle)) {
    s.band_low = cycle.theta_o_min - tol, s.band_high = cycle.theta_o_max + tol;
  } else {
    s.band_low = p.theta_R - tol, s.band_high = p.theta_R + tol;
  }
  // After rest the state is frozen at θ∞: the samples the simulator did not record lie in the band.
  auto inside = [&](double x) { return x >= s.band_low && x <= s.band_high; };
  if (run.status != SimulationStatus::Rest && (theta_o.empty() || !inside(theta_o.back()))) {
    s.status = "not_settled";
    return s;
  }
  std::size_t k = theta_o.size();
  while (k > 0 && inside(theta_o[k - 1])) --k;
  s.status = "settled";
  s.time = static_cast<double>(k) * o.t_end / o.samples;
  return s;
}

}  // namespace

Settle settle_time(const ValidatedEffectModel& model, const LimitCycle& cycle, const SettleOptions& options) {
  if (options.step == 0 || options.samples < 1 || !(options.t_end > 0)) return {};
  std::vector<double> theta_o;
  const SimulationResult run = simulate_effects_step(model, options.step, sampled(options, theta_o));
  return judge(run, theta_o, model.parameters(), cycle, options);
}

Settle settle_time(const ValidatedEvaluator& evaluator, const LimitCycle& cycle, const SettleOptions& options) {
  if (options.step == 0 || options.samples < 1 || !(options.t_end > 0)) return {};
  std::vector<double> theta_o;
  const SimulationResult run = simulate_step(evaluator, options.step, sampled(options, theta_o));
  return judge(run, theta_o, evaluator.parameters(), cycle, options);
}

}  // namespace backlash::numeric
