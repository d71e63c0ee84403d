// tests/numeric/sequential_gap_event.hpp — for the tests of a flight's gap events
// (numeric/hybrid/gap_events.hpp): a flight after a bounce in closed form with its samples counted,
// and the reference the event loop's answers are compared with bit for bit — the two searches one
// after the other (the opposite face over the whole horizon, then the return to the face left up
// to it: gap_events.cpp at main before the windows).
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/linear_flight.hpp"

#include <algorithm>
#include <optional>
#include <random>

namespace backlash::testing {

/// A free flight from x0 in closed form (LinearFlight, the flight after a bounce), its samples counted.
struct CountedFlight {
  numeric::LinearFlight flight;
  mutable long samples = 0;
  numeric::WitnessSample operator()(double t) const {
    ++samples;
    const numeric::SmallVector change = flight.change(t);
    return {flight.state(t), change(2) - change(0)};
  }
};

/// The opposite face over the whole horizon, then the return to the face left up to it.
inline std::optional<numeric::detail::GapEvent> sequential_event(const numeric::WitnessMode& mode,
                                                                 numeric::FunctionRef<numeric::WitnessSample(double)> sample,
                                                                 double opposite_face_change, double horizon,
                                                                 double position_scale) {
  using numeric::detail::GapEvent;
  using numeric::detail::GapEventKind;
  const std::optional<numeric::Crossing> opposite = numeric::first_crossing(mode, sample, opposite_face_change, 0, horizon);
  std::optional<numeric::Crossing> back;
  const double noise = 1e-10 * std::max(1.0, position_scale);
  const numeric::SmallVector x0 = sample(0).x;
  const std::optional<double> t0 = numeric::certified_departure(mode, x0, noise);
  if (t0)
    back = numeric::first_crossing_after_departure(mode, sample, *t0, numeric::certified_clearance(mode, x0, *t0, noise),
                                                   opposite ? opposite->t : horizon);
  if (back && (!opposite || back->t < opposite->t)) return GapEvent{GapEventKind::FaceLeft, *back, *t0, false, {}};
  if (opposite) return GapEvent{GapEventKind::OppositeFace, *opposite, 0, false, {}};
  return std::nullopt;
}

/// A flight leaving the face σ after a bounce (σ drawn): both bodies at one velocity, drawn within
/// ±`max_speed`, θm within ±`spread` of θR, the gap at σ b/2, its relative acceleration away from
/// the face (toward the opposite one).  Nothing when the draw would press into the face.
inline std::optional<numeric::SmallVector> flight_leaving_face(const numeric::Parameters& p, std::mt19937_64& random,
                                                               int& face, double spread, double max_speed) {
  std::uniform_real_distribution<double> angle(p.theta_R - spread, p.theta_R + spread), speed(-max_speed, max_speed);
  face = random() % 2 ? 1 : -1;
  numeric::SmallVector x(4);
  const double v = speed(random);
  x << angle(random), v, 0, v;
  x(2) = x(0) + face * p.backlash / 2;
  const numeric::LinearSegment free = numeric::free_mode_segment(p);
  const numeric::SmallVector rate = free.A * x + free.c;
  const double relative_acceleration = rate(3) - rate(1);  // Δx''(0): away from σ b/2 means sign −σ
  if (!(relative_acceleration * face < 0)) return std::nullopt;
  return x;
}

}  // namespace backlash::testing
