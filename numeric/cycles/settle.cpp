// settle.cpp — the settle time of a step response (settle.hpp; docs/design.md, "Design-space maps").
#include "backlash/numeric/settle.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
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
// `certified`: the run was stopped once every later θo was certified inside the moving band
// (CycleCertificate): the sample at t_end is inside, and every sample the run did not reach.
Settle judge(const SimulationResult& run, const std::vector<Sample>& theta_o, const Parameters& p,
             const LimitCycle& cycle, const SettleOptions& o, bool certified = false) {
  Settle s;
  if (!certified && stopped_early(run.status)) {
    s.status = to_string(run.status);
    return s;
  }
  const double tol = o.fraction * std::fabs(o.step);
  const SimulationOptions::SampleBand band = !certified && run.status == SimulationStatus::Rest
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
  if (!certified && run.status != SimulationStatus::Rest && last_outside) {
    s.status = "not_settled";
    return s;
  }
  s.status = "settled";
  s.time = static_cast<double>(n == 0 ? 0 : theta_o[n - 1].k + 1) * o.t_end / o.samples;
  return s;
}

// The certificate that a nominal step response has reached its stable symmetric cycle for good
// (settle.hpp, "Certified on the cycle"): at a separation with speed u, the interval
// I = [v* − r, v* + r], r = |u − v*|, mapped into itself by the half-cycle map g and with its ends'
// half cycles inside the band by the sample band's margin (hybrid_simulation.hpp); by the odd
// symmetry g(−v) = −g(v) one sign of the speed checks both faces.
class CycleCertificate {
 public:
  /// A stable period-1 cycle without bounces: the one the half-cycle map describes.
  static bool applies(const LimitCycle& c) {
    return c.status == CycleStatus::LimitCycle && c.stable && c.period_count == 1 && !c.bounced &&
           c.separation_velocity > 0 && std::fabs(c.half_map_derivative) < 1;
  }
  CycleCertificate(const ValidatedEvaluator& evaluator, const LimitCycle& cycle, SimulationOptions::SampleBand band)
      : evaluator_(evaluator), cycle_(cycle), band_(band) {
    const double R = evaluator.parameters().theta_R;
    margin_ = 4 * evaluator.report().tolerance * std::max({1.0, std::fabs(band.low), std::fabs(band.high)});
    // The first try: where the cycle's swing, grown in proportion to the speed, still fits the band.
    const double swing = std::max(cycle.theta_o_max - R, R - cycle.theta_o_min);
    const double room = std::min(band.high - R, R - band.low) - swing;
    next_try_ = swing > 0 && room > 0 ? 0.9 * cycle.separation_velocity * room / swing : 0;
  }
  /// At a separation of the run: true when the motion from it is certified inside the band.
  bool holds_after(const SimulationEvent& e) {
    if (e.kind != EventKind::Separation || e.dtheta_o == 0) return false;
    const double v = cycle_.separation_velocity, u = std::fabs(e.dtheta_o), d = std::fabs(u - v);
    if (d > next_try_ || e.after.face != (e.dtheta_o > 0 ? -1 : +1)) return false;
    next_try_ = d / 2;  // a failed try waits for the motion to come twice as close
    // r: |u − v*| and a few ulps more, so that I holds u whatever the rounding of v* ± r.
    const double sign = e.dtheta_o > 0 ? 1.0 : -1.0, r = d * (1 + 1e-9) + 8 * std::numeric_limits<double>::epsilon() * v;
    return one_sided_ ? holds_one_sided(sign, u > v ? r : -r) : holds(sign, r);
  }

 private:
  bool holds(double sign, double r) const {
    const double v = cycle_.separation_velocity;
    const HalfCycle low = half_cycle(evaluator_, sign * (v - r), true), high = half_cycle(evaluator_, sign * (v + r), true);
    if (!plain(low) || !plain(high) || low.events.size() != high.events.size()) return false;
    const double g_low = sign * low.v_out, g_high = sign * high.v_out;
    if (std::fabs(g_low - v) > r || std::fabs(g_high - v) > r) return false;
    if ((g_high - g_low) * cycle_.half_map_derivative < 0) return false;
    return inside(low.extremes) && inside(high.extremes);
  }
  // g'(v*) > 0 (settle.hpp): I = [v*, v* + r] or [v* − r, v*] (`signed_r`'s sign: u's side of v*),
  // whose end v* is the cycle itself (Newton's half cycle: one recombination that holds, then the
  // separation); only the other end is simulated, and g of it must lie in I.
  bool holds_one_sided(double sign, double signed_r) const {
    const double v = cycle_.separation_velocity;
    const HalfCycle end = half_cycle(evaluator_, sign * (v + signed_r), true);
    if (!plain(end)) return false;
    const double moved = sign * end.v_out - v;  // g(end) − v*: toward v* (same sign as signed_r), no farther than r
    if (moved * signed_r < 0 || std::fabs(moved) > std::fabs(signed_r)) return false;
    return inside(end.extremes) && inside(Extremes{cycle_.theta_o_min, cycle_.theta_o_max});
  }
  // One recombination that holds, then the separation.
  static bool plain(const HalfCycle& h) {
    if (!h.valid || h.bounced || h.events.size() != 2) return false;
    for (const SimulationEvent& e : h.events)
      if (e.grazing || e.bounce) return false;
    return h.events[0].kind == EventKind::Recombination && h.events[1].kind == EventKind::Separation;
  }
  // θo's extremes and their mirror images about θR inside the band by the margin.
  bool inside(const Extremes& x) const {
    const double R = evaluator_.parameters().theta_R;
    const double high = std::max(x.theta_o_max, 2 * R - x.theta_o_min), low = std::min(x.theta_o_min, 2 * R - x.theta_o_max);
    return std::isfinite(high) && std::isfinite(low) && high <= band_.high - margin_ && low >= band_.low + margin_;
  }
  const ValidatedEvaluator& evaluator_;
  const LimitCycle& cycle_;
  // Newton's cycle (its half cycle is plain) with g'(v*) > 0: the motion approaches v* from one side.
  const bool one_sided_ = !cycle_.survey_fallback && cycle_.half_map_derivative > 0;
  const SimulationOptions::SampleBand band_;
  double margin_ = 0;
  double next_try_ = 0;  // |u − v*| at which the next try is made
};

using Certificate = std::function<bool(const SimulationEvent&)>;

// The settle time from `simulate(options)`: with samples left out by the moving band, again with
// all of them when that run stopped at rest after leaving some out (its band is θ∞'s).  With a
// `certificate` (nominal runs toward a stable cycle), the first run stops at the separation from
// which the rest of the motion is certified inside the band (CycleCertificate): at the
// `expected` one (SettleOptions::expected_separation) the simulator ends it there
// (stop_after_separations), at any other the event sink asks it to (stop_requested: its samples
// so far are those of the whole run up to that time).  A run that reached the
// expected separation uncertified is run again from the start, its certificate skipping the
// separations it has already judged: the same tries, the same answer.
template <class Simulate>
Settle settled(const Simulate& simulate, const Parameters& p, const LimitCycle& cycle, const SettleOptions& o,
               const Certificate& certificate = {}, long expected = 0) {
  std::vector<Sample> theta_o;
  SimulationOptions first = sampled(o, theta_o, moving_band(p, cycle, o.fraction * std::fabs(o.step)));
  double stopped = NAN;
  long separations = 0;
  bool inside_from_here = false;
  if (certificate) {
    first.stop_after_separations = expected;
    first.stop_requested = &inside_from_here;
    first.event_sink = [&certificate, &stopped, &separations, &inside_from_here](const SimulationEvent& e) {
      separations += e.kind == EventKind::Separation;
      if (!certificate(e)) return;
      stopped = e.t;
      inside_from_here = true;
    };
  }
  SimulationResult run = simulate(first);
  if (!std::isnan(stopped)) {
    Settle s = judge(run, theta_o, p, cycle, o, true);
    s.stopped_at = stopped;
    s.stopped_separation = separations;
    return s;
  }
  if (expected > 0 && separations == expected && run.status == SimulationStatus::Completed && run.t_final < o.t_end) {
    long seen = 0;
    const Certificate later = [&certificate, &seen, expected](const SimulationEvent& e) {
      return (e.kind == EventKind::Separation && ++seen <= expected) ? false : certificate(e);
    };
    return settled(simulate, p, cycle, o, later);
  }
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
  if (!options.stop_on_cycle || !CycleCertificate::applies(cycle)) return settled(simulate, evaluator.parameters(), cycle, options);
  CycleCertificate certificate(evaluator, cycle, moving_band(evaluator.parameters(), cycle, options.fraction * std::fabs(options.step)));
  return settled(simulate, evaluator.parameters(), cycle, options,
                 [&certificate](const SimulationEvent& e) { return certificate.holds_after(e); },
                 std::max(0L, options.expected_separation));
}

}  // namespace backlash::numeric
