// numeric/hybrid/gap_events.hpp (internal) — the first gap event of a free flight,
// shared by the dividing-line tracer and the hybrid simulator.
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

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
/// `opposite_face_change` (±b) or returns to 0 (certified departure first).
std::optional<GapEvent> first_gap_event(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                        std::function<double(double)> gap_change, double opposite_face_change,
                                        double horizon, double position_scale, double time_unit = 1);

/// The same on the free mode's gap witness built once (`gap_mode`: e = θL − θm on the free
/// segment), `sample(t)` giving x(t) and Δx(t) from one closed-form evaluation.
std::optional<GapEvent> first_gap_event(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                        double opposite_face_change, double horizon, double position_scale);

/// A free flight that starts strictly inside the backlash, at the gap x(0) = `start_gap`
/// (|x(0)| < b/2 = `half`): the first arrival of x at a face — Δx = σ b/2 − x(0) (FaceLeft: the
/// face σ = `face`) or −σ b/2 − x(0) (OppositeFace) — by the certified search of both levels,
/// the earlier kept (an arrival at both at once is impossible: the levels differ by b).
std::optional<GapEvent> first_gap_event_inside(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                               double start_gap, int face, double half, double horizon);

/// The gap witness's mode: e = θL − θm on the free segment.
WitnessMode gap_witness_mode(const LinearSegment& free_segment, double time_unit);

}  // namespace backlash::numeric::detail
