// backlash/numeric/settle.hpp — the time a step response takes to settle: onto its limit
// cycle, or to rest (the `map` command's settle_time; docs/design.md, "Design-space maps").
//
// The step experiment of docs/physics.md: rest in contact, θo = θR − A at t = 0.  θo is
// sampled at t_k = k·h, h = t_end / samples (k = 0 … samples, the recorder's exact grid),
// and the band it must end in is
//   - rest:  |θo − θ∞| ≤ tol, θ∞ the value at which the motion stopped (status rest: the
//            simulator proved no further event), or θR when it did not stop by t_end and the
//            point has no limit cycle (the only equilibrium of the loop without Coulomb
//            friction; with Coulomb friction a sticking rest is reached as "rest");
//   - cycle: θo ∈ [θo_min − tol, θo_max + tol], the cycle's exact extremes
//            (limit_cycle.hpp), when the point has a limit cycle and the motion did not stop;
// with tol = fraction·|A| (2 % by default: the classic settling band).  The settle time is the
// first sample time t_k after which every sample lies in the band (0 when all do) — exact up
// to the sampling step h, which is part of the definition (t_end = 60 s, 2000 samples:
// h = 0.03 s).  Not settled: the sample at t_end is outside the band (status "not_settled",
// time NaN).  A simulation that stopped early (chattering, event_limit, ... :
// hybrid_simulation.hpp) gives that status and NaN — never a guess.
//
// Stopped on the cycle (nominal model, a stable symmetric cycle without bounces): the
// separations of the step response lie on the separation line, so from one with speed u the
// motion is the half-cycle map g's (limit_cycle.hpp), and the later speeds are g(u), g(g(u)), ….
// The response is stopped at the first separation whose speed u lies in an interval
// I = [v* − r, v* + r] around the cycle's v* (r = |u − v*|) that g maps into itself (checked at
// I's ends: same events, one recombination and a separation, and g(ends) in I, in the order of
// g'(v*)'s sign) and whose ends' half cycles keep θo (and its mirror image about θR) inside the
// band by the sample band's margin.  When g'(v*) > 0 (Newton's cycle: the speeds approach v* from
// u's side, without alternating) I is the one-sided [v*, u'] (or [u', v*]), u' = v* ± r on u's
// side: its end v* is the cycle itself (its extremes inside the band by the margin), so one half
// cycle is simulated, from u', and g(u') must lie in I.  g, and θo's extremes over a half cycle, are ASSUMED monotone
// on I (they are smooth there, with |g'(v*)| < 1; the checks at I's ends and at v* agree with
// it, but nothing proves it between them): this stop is a check, not a certificate.  Under that
// assumption every later sample lies inside the band, so the settle time and the status are
// those of the run to t_end — as they were on every point checked against that run
// (tests/numeric/check_settle_certified.cpp; stop_on_cycle = false runs to t_end).
#pragma once

#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <cmath>
#include <string>

namespace backlash::numeric {

struct SettleOptions {
  double step = 0;         ///< A [rad] (0: nothing is computed, status "no_step")
  double t_end = 60;       ///< [s]
  int samples = 2000;      ///< h = t_end / samples
  double fraction = 0.02;  ///< tol = fraction·|A|
  /// Nominal runs toward a stable cycle: stop the step response at the separation from which
  /// every later θo stays inside the band by the check below ("Stopped on the cycle": a check
  /// under a stated assumption, not a proof); false: run it to t_end.
  bool stop_on_cycle = true;
  /// > 0: the separation (1, 2, …) at which the stop on the cycle is expected — a map's neighbour's
  /// Settle::stopped_separation (continuation): the simulator ends the run there instead of the
  /// event sink asking it to stop there.  A hint only: the answer is the same for any value.
  long expected_separation = 0;
};

struct Settle {
  std::string status = "no_step";  ///< "settled" | "not_settled" | "no_step" | a simulation status
  double time = NAN;               ///< [s]; NaN unless settled
  double band_low = NAN, band_high = NAN;  ///< the band [rad], absolute (θR included)
  double stopped_at = NAN;  ///< [s] the separation at which the step response was stopped on
                            ///< its cycle; NaN when it ran to t_end or to rest
  long stopped_separation = 0;  ///< that separation's number (1, 2, …); 0 when not stopped
};

/// The settle time of `model`'s step response; `cycle` is the point's limit-cycle search
/// result (its status decides the band), its angles in the model's own coordinates.
Settle settle_time(const ValidatedEffectModel& model, const LimitCycle& cycle, const SettleOptions& options);
/// The same for the nominal model (no effects): simulate_step on `evaluator`.
Settle settle_time(const ValidatedEvaluator& evaluator, const LimitCycle& cycle, const SettleOptions& options);

}  // namespace backlash::numeric
