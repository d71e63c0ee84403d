// numeric/hybrid/gap_events.hpp (internal) — the first gap event of a free flight,
// shared by the dividing-line tracer and the hybrid simulator.
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/certified_search.hpp"
#include "hybrid/quiet_tail.hpp"

#include <algorithm>
#include <functional>
#include <optional>

namespace backlash::numeric::detail {

enum class GapEventKind { OppositeFace, FaceLeft };

struct GapEvent {
  GapEventKind kind;
  Crossing crossing;
  double departure = 0;  ///< FaceLeft: the certified departure t0, w ≠ 0 on (0, t0], the search's start
  bool from_inside = false;  ///< the flight started strictly inside the backlash (no face left, no departure)
  SmallVector x;  ///< x at the crossing when a search sampled it there (the event's state, not evaluated again); else empty
};

/// The witness of the gap change Δx = θL − θm − Δx(0) − level of a free flight.
LinearWitness gap_change_witness(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                 std::function<double(double)> gap_change, double level, double time_unit = 1);

/// A free flight whose gap change Δx(t) = x(t) − x(0) starts at 0 with zero
/// relative velocity.  `state` gives x(t) = (θm, θ̇m, θL, θ̇L) (any frame),
/// `gap_change` gives Δx(t) directly.  The first time Δx reaches
/// `opposite_face_change` (±b) or returns to 0 (certified departure first).  `turns_once` as
/// first_gap_event_with's.
std::optional<GapEvent> first_gap_event(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                        std::function<double(double)> gap_change, double opposite_face_change,
                                        double horizon, double position_scale, double time_unit = 1,
                                        bool turns_once = false);

/// The same on the free mode's gap witness built once (`gap_mode`: e = θL − θm on the free
/// segment), `sample(t)` giving x(t) and Δx(t) from one closed-form evaluation.
std::optional<GapEvent> first_gap_event(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                        double opposite_face_change, double horizon, double position_scale,
                                        bool turns_once = false);

/// A free flight that starts strictly inside the backlash, at the gap x(0) = `start_gap`
/// (|x(0)| < b/2 = `half`): the first arrival of x at a face — Δx = σ b/2 − x(0) (FaceLeft: the
/// face σ = `face`) or −σ b/2 − x(0) (OppositeFace) — by the certified search of both levels,
/// the earlier kept (an arrival at both at once is impossible: the levels differ by b).
std::optional<GapEvent> first_gap_event_inside(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                               double start_gap, int face, double half, double horizon);

/// A witness's rates at a start x0: ‖D x'(0)‖∞ (‖D x'(t)‖∞ ≤ e^{μ t} of it), w''(0) = eA x'(0),
/// w'''(0) = eA² x'(0) and ‖x0‖∞, with x'(0) = A x0 + c: what certified_departure,
/// certified_clearance and departure_sign read of x0, computed once per flight.
struct StartRates {
  double z0, second, third, x_size;
};
StartRates start_rates(const WitnessMode& mode, const SmallVector& x0);

/// certified_departure and certified_clearance (first_crossing.hpp) from the start's rates.
std::optional<double> certified_departure(const WitnessMode& mode, const StartRates& rates, double noise);
double certified_clearance(const WitnessMode& mode, const StartRates& rates, double t0, double noise);

/// The sign of w near the start (its leading term's, w''(0) or w'''(0), on (0, t0]) when
/// certified_clearance judges that term resolved from rounding and noise (first_crossing.hpp);
/// 0 when it does not.
int departure_sign(const WitnessMode& mode, const StartRates& rates, double t0, double noise);

/// WitnessMode(A, c, e, time_unit), kept by the exact bits of its inputs (this thread's last
/// four): the same inputs give the same bits, so a kept mode is the one building it again would
/// give.  A map's points share their contact segment where they keep Jm + JL, Fm + FL and K
/// (docs/design.md, "Design-space maps"): its velocity's and θo's witnesses repeat there.
WitnessMode kept_witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e, double time_unit);

/// The gap witness's mode: e = θL − θm on the free segment.
WitnessMode gap_witness_mode(const LinearSegment& free_segment, double time_unit);

// The two gap levels of a flight (gap_events.cpp): each level's certified search over a span,
// the earlier crossing of the two kept.
using SpanSearch = FunctionRef<std::optional<Crossing>(double, double)>;

struct Level {
  SpanSearch search;  ///< the certified first crossing in (lo, hi]; search(start(), T) is the level's whole search
  /// no crossing on (0, start()] (a departure certified clear up to there): asked only when the
  /// level is searched (a clearance is not computed for a level that need not be)
  FunctionRef<double()> start;
};

struct LevelEvent {
  bool second;  ///< the second level crossed first
  Crossing crossing;
};

/// The first crossing of either level within `horizon`, as the two searches one after the other
/// find it (the first level over the horizon, the second up to its crossing), window by window
/// when the mode has a time scale (`first_window`); `samples` counts the samples taken so far.
/// `first_settles`: the second level is known not to cross before a crossing of the first that is
/// not grazing (a flight whose gap turns at most once, gap_rate_turns_at_most_once), so such a
/// crossing is the event without the second level's search up to it.  `quiet_from`: neither
/// level is crossed on [quiet_from, horizon] (quiet_gap_from), so no window goes past it; the
/// event found, or none, is the same.
std::optional<LevelEvent> first_of_two_levels(const Level& first, const Level& second, double horizon,
                                              double first_window, const long& samples, bool first_settles = false,
                                              double quiet_from = INFINITY);

/// Whether the gap rate Δx' = θ̇L − θ̇m of every free flight of `p` has at most two real zeros
/// (counted with multiplicity): it then solves a third-order linear ODE with real characteristic
/// roots (docs/design.md, "The event loop": the load's velocity decays by itself, θ̇L'' = −(FL/JL)θ̇L';
/// with the output at the load the motor's velocity solves D(D + FL/JL)(D + Fm/Jm)θ̇m = 0, with it
/// at the motor (D² + (Fm/Jm)D + K/Jm)θ̇m = 0 — real roots only for a motor damped at least
/// critically).  A flight leaving a face has Δx'(0) = 0, so its gap turns at most once after t = 0.
bool gap_rate_turns_at_most_once(const Parameters& p);

/// Whether a flight whose gap turns at most once after t = 0 (gap_rate_turns_at_most_once, Δx'(0)
/// = 0), leaving with Δx of sign `departure_sign` on (0, t1] (certified_clearance), can return to
/// the face left (Δx = 0) before its first crossing of the opposite face's level Δx = L only when
/// it leaves away from L: Δx is strictly monotone up to its turn t* (Δx' has at most one zero on
/// (0, ∞), a simple one: two zeros there and the one at 0 would be three) and strictly monotone
/// the other way after it.  Leaving toward L, it is nonzero on (0, t*]; after t* it moves back
/// toward 0, so it can reach L after t* only from beyond L — already crossed before t*.  Hence
/// a first crossing of L (not grazing) at t_c has t_c ≤ t* and Δx ≠ 0 on (0, t_c]: no return.
inline bool no_return_before_opposite_face(int departure_sign, double opposite_face_change) {
  return departure_sign != 0 && (departure_sign > 0) == (opposite_face_change > 0) && opposite_face_change != 0;
}

/// first_gap_event on the gap mode with `sample` any callable (double) → WitnessSample: the
/// event loop's own flight, called directly by the certified search (certified_search.hpp).
/// `turns_once`: the flight's exact gap change has Δx(0) = Δx'(0) = 0 and turns at most once
/// after t = 0 (gap_rate_turns_at_most_once, and the flight starts with equal velocities): then
/// the return to the face left is not searched before the opposite face's crossing (no_return_before).
template <class F>
std::optional<GapEvent> first_gap_event_with(const WitnessMode& gap_mode, const F& sample, double opposite_face_change,
                                             double horizon, double position_scale, bool turns_once = false) {
  // x(0): the searches' first point and the departure's start, evaluated once.  The return search
  // samples its horizon, the opposite face's crossing when it is searched up to one: that sample
  // is kept as the event's state (`watch`: the horizon of the return search last started).
  const WitnessSample start = sample(0);
  long samples = 0;
  double watch = -1;
  SmallVector at_watch;
  const auto counted = [&sample, &samples, &start, &watch, &at_watch](double t) {
    ++samples;
    WitnessSample s = t == 0 ? start : sample(t);  // (one object: no copy of the sample on return)
    if (t == watch) at_watch = s.x;
    return s;
  };
  const auto opposite = [&](double lo, double hi) { return certified_first_crossing(gap_mode, counted, opposite_face_change, lo, hi); };
  // Return to the face left: Δx starts as O(t²) or O(t³), below rounding noise at first.
  const double noise = 1e-10 * std::max(1.0, position_scale);
  const SmallVector& x0 = start.x;
  const StartRates rates = start_rates(gap_mode, x0);
  const std::optional<double> t0 = certified_departure(gap_mode, rates, noise);
  if (!t0) {
    const std::optional<Crossing> only = certified_first_crossing(gap_mode, counted, opposite_face_change, 0, horizon);
    if (only) return GapEvent{GapEventKind::OppositeFace, *only, 0, false, {}};
    return std::nullopt;
  }
  double clear = NAN;  // certified_clearance, computed when the return is searched
  const auto cleared = [&] {
    if (std::isnan(clear)) clear = certified_clearance(gap_mode, rates, *t0, noise);
    return clear;
  };
  const auto back = [&](double lo, double hi) {
    watch = hi;
    at_watch.resize(0);
    return certified_crossing_after_departure(gap_mode, counted, *t0, std::max(cleared(), lo), hi);
  };
  const auto zero = [] { return 0.0; };
  const auto back_start = [&] { return cleared() > *t0 ? std::min(clear, horizon) : *t0; };
  const Level first{opposite, zero}, second{back, back_start};
  const bool first_settles =
      turns_once && no_return_before_opposite_face(departure_sign(gap_mode, rates, *t0, noise), opposite_face_change);
  // A quiet tail needs the motor free of the load (A(1, 2) = 0, the output at the motor): for the
  // output at the load (cases III–VIII) the call is not made at all.
  const bool motor_free = gap_mode.A.rows() == 4 && gap_mode.A(1, 2) == 0;
  const double quiet_from =
      motor_free ? quiet_gap_from(gap_mode.A, gap_mode.c, x0, opposite_face_change, 0, horizon, gap_mode.first_window)
                 : INFINITY;
  const std::optional<LevelEvent> event =
      first_of_two_levels(first, second, horizon, gap_mode.first_window, samples, first_settles, quiet_from);
  if (!event) return std::nullopt;
  if (event->second) return GapEvent{GapEventKind::FaceLeft, event->crossing, *t0, false, {}};
  const bool sampled_there = watch == event->crossing.t && at_watch.size() > 0;
  return GapEvent{GapEventKind::OppositeFace, event->crossing, 0, false, sampled_there ? at_watch : SmallVector{}};
}

/// first_gap_event_inside with `sample` any callable (double) → WitnessSample.
template <class F>
std::optional<GapEvent> first_gap_event_inside_with(const WitnessMode& gap_mode, const F& sample, double start_gap,
                                                    int face, double half, double horizon) {
  long samples = 0;
  const auto counted = [&sample, &samples](double t) {
    ++samples;
    return sample(t);
  };
  const auto same = [&](double lo, double hi) { return certified_first_crossing(gap_mode, counted, face * half - start_gap, lo, hi); };
  const auto opposite = [&](double lo, double hi) {
    return certified_first_crossing(gap_mode, counted, -face * half - start_gap, lo, hi);
  };
  const auto zero = [] { return 0.0; };
  const Level first{same, zero}, second{opposite, zero};
  const std::optional<LevelEvent> event = first_of_two_levels(first, second, horizon, gap_mode.first_window, samples);
  if (!event) return std::nullopt;
  if (event->second) return GapEvent{GapEventKind::OppositeFace, event->crossing, 0, true, {}};
  return GapEvent{GapEventKind::FaceLeft, event->crossing, 0, true, {}};
}

}  // namespace backlash::numeric::detail
