#include "hybrid/gap_events.hpp"

#include <algorithm>

namespace backlash::numeric::detail {

LinearWitness gap_change_witness(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                 std::function<double(double)> gap_change, double level, double time_unit) {
  LinearWitness w;
  w.time_unit = time_unit;
  w.A = free_segment.A;
  w.c = free_segment.c;
  w.e = SmallRow::Zero(4);
  w.e(0) = -1;
  w.e(2) = 1;
  w.state = std::move(state);
  w.value = std::move(gap_change);
  w.level = level;
  return w;
}

WitnessMode gap_witness_mode(const LinearSegment& free_segment, double time_unit) {
  SmallRow e = SmallRow::Zero(4);
  e(0) = -1;
  e(2) = 1;
  return WitnessMode(free_segment.A, free_segment.c, e, time_unit);
}

std::optional<GapEvent> first_gap_event(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                        double opposite_face_change, double horizon, double position_scale) {
  // x(0): the first search's first point and the departure's start, evaluated once.
  const WitnessSample start = sample(0);
  const auto from_start = [&sample, &start](double t) { return t == 0 ? start : sample(t); };
  const std::optional<Crossing> opposite = first_crossing(gap_mode, from_start, opposite_face_change, 0, horizon);
  // Return to the face left: Δx starts as O(t²) or O(t³), below rounding noise at first.
  std::optional<Crossing> back;
  const double noise = 1e-10 * std::max(1.0, position_scale);
  const SmallVector& x0 = start.x;
  const std::optional<double> t0 = certified_departure(gap_mode, x0, noise);
  // The return search samples its horizon, the opposite face's crossing: kept as the event's state.
  const double until = opposite ? opposite->t : horizon;
  SmallVector at_until;
  const auto keeping = [&sample, &at_until, until](double t) {
    WitnessSample s = sample(t);
    if (t == until) at_until = s.x;
    return s;
  };
  if (t0)
    back = first_crossing_after_departure(gap_mode, keeping, *t0, certified_clearance(gap_mode, x0, *t0, noise), until);
  if (back && (!opposite || back->t < opposite->t)) return GapEvent{GapEventKind::FaceLeft, *back, *t0, false, {}};
  if (opposite) return GapEvent{GapEventKind::OppositeFace, *opposite, 0, false, at_until};
  return std::nullopt;
}

std::optional<GapEvent> first_gap_event_inside(const WitnessMode& gap_mode, FunctionRef<WitnessSample(double)> sample,
                                               double start_gap, int face, double half, double horizon) {
  const std::optional<Crossing> same = first_crossing(gap_mode, sample, face * half - start_gap, 0, horizon);
  const std::optional<Crossing> opposite =
      first_crossing(gap_mode, sample, -face * half - start_gap, 0, same ? same->t : horizon);
  if (opposite && (!same || opposite->t < same->t)) return GapEvent{GapEventKind::OppositeFace, *opposite, 0, true, {}};
  if (same) return GapEvent{GapEventKind::FaceLeft, *same, 0, true, {}};
  return std::nullopt;
}

std::optional<GapEvent> first_gap_event(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                        std::function<double(double)> gap_change, double opposite_face_change,
                                        double horizon, double position_scale, double time_unit) {
  const auto sample = [&state, &gap_change](double t) { return WitnessSample{state(t), gap_change(t)}; };
  return first_gap_event(gap_witness_mode(free_segment, time_unit), sample, opposite_face_change, horizon, position_scale);
}

}  // namespace backlash::numeric::detail
