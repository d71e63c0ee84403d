#include "hybrid/gap_events.hpp"

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

std::optional<GapEvent> first_gap_event(const LinearSegment& free_segment, std::function<SmallVector(double)> state,
                                        std::function<double(double)> gap_change, double opposite_face_change,
                                        double horizon, double position_scale, double time_unit) {
  LinearWitness w =
      gap_change_witness(free_segment, std::move(state), std::move(gap_change), opposite_face_change, time_unit);
  const std::optional<Crossing> opposite = first_crossing(w, 0, horizon);
  // Return to the face left: Δx starts as O(t²) or O(t³), below rounding noise at first.
  w.level = 0;
  std::optional<Crossing> back;
  const std::optional<double> t0 = certified_departure(w, 1e-10 * std::max(1.0, position_scale));
  if (t0) back = first_crossing(w, *t0, opposite ? opposite->t : horizon);
  if (back && (!opposite || back->t < opposite->t)) return GapEvent{GapEventKind::FaceLeft, *back, *t0};
  if (opposite) return GapEvent{GapEventKind::OppositeFace, *opposite};
  return std::nullopt;
}

}  // namespace backlash::numeric::detail
