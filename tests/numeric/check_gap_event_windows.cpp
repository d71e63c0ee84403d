// Issue 20, slider drags at ≥ 30 fps: a flight's two gap levels (the opposite face, the return to
// the face left — or, from inside the backlash, the two faces) searched window by window together
// (numeric/hybrid/gap_events.cpp, docs/design.md "The event loop").  Each answer must be the one of
// the two searches one after the other (the code before: the first level over the whole horizon,
// then the second up to its crossing), bit for bit, on random flights of the thesis's cases II–IV
// with a nearly frictionless load (FL = 1e-2, 1e-4: horizons of 60·JL/FL = 3000, 3·10⁵ s), where the return
// comes first (case II) and where the opposite face does (cases III, IV); and its cost — closed-form
// samples counted — must be set by the event, not by the horizon: the same with the horizon a
// hundred times longer (the sequential searches certified the whole horizon first: their cost grew
// with it).  The soak's grazing separation (check_soak.cpp, set 970), where a search sharing one
// tree between the levels once found a false return, keeps the odeint reference's story.
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/odeint_simulation.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "backlash/numeric/validated_family.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/linear_flight.hpp"
#include "sequential_gap_event.hpp"
#include "thesis_cases_two_to_four.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>

namespace {

using namespace backlash;
using namespace backlash::numeric;
using detail::GapEvent;
using detail::GapEventKind;

// The thesis's cases II–IV with the load's friction FL (θR = 1, as the case files).
Parameters thesis_case(int number, double FL) { return backlash::testing::thesis_case_two_to_four(number, FL, 1); }

using backlash::testing::CountedFlight;
using backlash::testing::sequential_event;

// The same from inside the backlash: the face σ over the whole horizon, then the other face up to it.
std::optional<GapEvent> sequential_event_inside(const WitnessMode& mode, FunctionRef<WitnessSample(double)> sample,
                                                double start_gap, int face, double half, double horizon) {
  const std::optional<Crossing> same = first_crossing(mode, sample, face * half - start_gap, 0, horizon);
  const std::optional<Crossing> opposite = first_crossing(mode, sample, -face * half - start_gap, 0, same ? same->t : horizon);
  if (opposite && (!same || opposite->t < same->t)) return GapEvent{GapEventKind::OppositeFace, *opposite, 0, true, {}};
  if (same) return GapEvent{GapEventKind::FaceLeft, *same, 0, true, {}};
  return std::nullopt;
}

std::string describe(const std::optional<GapEvent>& e) {
  if (!e) return "none";
  char text[160];
  std::snprintf(text, sizeof text, "%s at t = %.17g%s (departure %.17g)",
                e->kind == GapEventKind::FaceLeft ? "face left" : "opposite face", e->crossing.t,
                e->crossing.grazing ? " grazing" : "", e->departure);
  return text;
}

void expect_same(const std::optional<GapEvent>& windowed, const std::optional<GapEvent>& sequential, const std::string& label) {
  ASSERT_EQ(windowed.has_value(), sequential.has_value()) << label << ": " << describe(windowed) << " vs " << describe(sequential);
  if (!windowed) return;
  EXPECT_EQ(windowed->kind, sequential->kind) << label << ": " << describe(windowed) << " vs " << describe(sequential);
  EXPECT_EQ(windowed->crossing.t, sequential->crossing.t) << label << ": " << describe(windowed) << " vs " << describe(sequential);
  EXPECT_EQ(windowed->crossing.grazing, sequential->crossing.grazing) << label;
  EXPECT_EQ(windowed->departure, sequential->departure) << label;
  EXPECT_EQ(windowed->from_inside, sequential->from_inside) << label;
}

// A flight leaving the face σ after a bounce (flight_leaving_face).  Near θR (`near`: within
// 0.2 rad, at most 0.3 rad/s) the motor's swing is below b and the gap mostly returns to the
// face; further out it mostly reaches the other.
std::optional<SmallVector> flight_after_bounce(const Parameters& p, std::mt19937_64& random, int& face, bool near = false) {
  return backlash::testing::flight_leaving_face(p, random, face, near ? 0.2 : 2, near ? 0.3 : 1.5);
}

// The load's friction of the comparisons with the sequential searches: a horizon of 60·JL/FL =
// 3000 s on case II, still a thousand times the flights' returns (the sequential searches' cost
// over 3·10⁵ s at FL = 1e-4 would make this test too slow).
constexpr double kFrictionCompared = 1e-2;

double position_scale(const SmallVector& x) { return std::max({1.0, std::fabs(x(0)), std::fabs(x(2))}); }

TEST(GapEventWindows, item20_flights_after_a_bounce_give_the_sequential_searches_events_bit_for_bit) {
  std::mt19937_64 random(2020);
  long returns = 0, opposite = 0;
  for (int number : {2, 3, 4}) {
    const Parameters p = thesis_case(number, kFrictionCompared);
    const double horizon = 60 * slowest_time_scale(p);
    const WitnessMode mode = detail::gap_witness_mode(free_mode_segment(p), servo_time_unit(p));
    for (int i = 0; i < (number == 2 ? 120 : 25); ++i) {
      int face = 0;
      const std::optional<SmallVector> x0 = flight_after_bounce(p, random, face, i % 2 == 0);
      if (!x0) continue;
      const CountedFlight flight{LinearFlight(free_mode_segment(p), *x0)};
      const auto sample = [&flight](double t) { return flight(t); };
      const auto windowed = detail::first_gap_event(mode, sample, -face * p.backlash, horizon, position_scale(*x0));
      const auto sequential = sequential_event(mode, sample, -face * p.backlash, horizon, position_scale(*x0));
      expect_same(windowed, sequential, "case " + std::to_string(number) + ", flight " + std::to_string(i));
      if (windowed) (windowed->kind == GapEventKind::FaceLeft ? returns : opposite) += 1;
    }
  }
  std::printf("flights after a bounce: %ld returns to the face left, %ld arrivals at the opposite face\n", returns, opposite);
  EXPECT_GE(returns, 10);  // both orders are exercised
  EXPECT_GE(opposite, 10);
}

TEST(GapEventWindows, item20_flights_from_inside_the_backlash_give_the_sequential_searches_events_bit_for_bit) {
  std::mt19937_64 random(2021);
  std::uniform_real_distribution<double> angle(-1, 3), speed(-1.5, 1.5), inside(-0.95, 0.95);
  long events = 0;
  for (int number : {2, 3, 4}) {
    const Parameters p = thesis_case(number, kFrictionCompared);
    const double horizon = 60 * slowest_time_scale(p), half = p.backlash / 2;
    const WitnessMode mode = detail::gap_witness_mode(free_mode_segment(p), servo_time_unit(p));
    for (int i = 0; i < 30; ++i) {
      SmallVector x0(4);
      x0 << angle(random), speed(random), 0, speed(random);
      const double start_gap = inside(random) * half;
      x0(2) = x0(0) + start_gap;
      const int face = random() % 2 ? 1 : -1;
      const CountedFlight flight{LinearFlight(free_mode_segment(p), x0)};
      const auto sample = [&flight](double t) { return flight(t); };
      const auto windowed = detail::first_gap_event_inside(mode, sample, start_gap, face, half, horizon);
      expect_same(windowed, sequential_event_inside(mode, sample, start_gap, face, half, horizon),
                  "case " + std::to_string(number) + ", flight " + std::to_string(i));
      events += windowed.has_value();
    }
  }
  EXPECT_GT(events, 45);
}

// Case II at FL = 1e-4, flights that return to the face left: the search's samples are the same
// with the horizon 60·JL/FL and a hundred times that (the sequential searches' grew with it).
TEST(GapEventWindows, item20_a_return_to_the_face_left_costs_the_same_whatever_the_horizon) {
  const Parameters p = thesis_case(2, 1e-4);
  const double horizon = 60 * slowest_time_scale(p);
  const WitnessMode mode = detail::gap_witness_mode(free_mode_segment(p), servo_time_unit(p));
  std::mt19937_64 random(2022);
  int checked = 0;
  for (int i = 0; i < 200 && checked < 10; ++i) {
    int face = 0;
    const std::optional<SmallVector> x0 = flight_after_bounce(p, random, face, true);
    if (!x0) continue;
    const CountedFlight flight{LinearFlight(free_mode_segment(p), *x0)};
    const auto sample = [&flight](double t) { return flight(t); };
    const auto event = detail::first_gap_event(mode, sample, -face * p.backlash, horizon, position_scale(*x0));
    if (!event || event->kind != GapEventKind::FaceLeft) continue;
    const long cost = flight.samples;
    flight.samples = 0;
    const auto longer = detail::first_gap_event(mode, sample, -face * p.backlash, 100 * horizon, position_scale(*x0));
    ASSERT_TRUE(longer.has_value());
    EXPECT_EQ(longer->crossing.t, event->crossing.t);
    EXPECT_EQ(flight.samples, cost) << "flight " << i << ": the return at t = " << event->crossing.t << " s cost " << cost
                                    << " samples with the horizon " << horizon << " s, " << flight.samples << " with 100 times it";
    ++checked;
  }
  EXPECT_EQ(checked, 10);
}

// From inside the backlash, a flight whose face σ is never reached (the load coasting away from
// it): the arrival at the other face costs the same whatever the horizon.
TEST(GapEventWindows, item20_an_arrival_from_inside_costs_the_same_whatever_the_horizon) {
  const Parameters p = thesis_case(2, 1e-4);
  const double horizon = 60 * slowest_time_scale(p), half = p.backlash / 2;
  const WitnessMode mode = detail::gap_witness_mode(free_mode_segment(p), servo_time_unit(p));
  SmallVector x0(4);
  x0 << 1, 0, 1, 0.5;  // the motor at θR, the load moving away: the gap grows to +b/2
  const CountedFlight flight{LinearFlight(free_mode_segment(p), x0)};
  const auto sample = [&flight](double t) { return flight(t); };
  const auto event = detail::first_gap_event_inside(mode, sample, 0, -1, half, horizon);
  ASSERT_TRUE(event.has_value());
  EXPECT_EQ(event->kind, GapEventKind::OppositeFace);
  const long cost = flight.samples;
  flight.samples = 0;
  const auto longer = detail::first_gap_event_inside(mode, sample, 0, -1, half, 100 * horizon);
  ASSERT_TRUE(longer.has_value());
  EXPECT_EQ(longer->crossing.t, event->crossing.t);
  EXPECT_EQ(flight.samples, cost) << "the arrival at t = " << event->crossing.t << " s";
}

// check_soak.cpp's set 970 (near critical contact): a grazing separation; the closed-form run
// tells the odeint reference's story (status, events, times within the soak's 1e-7).
TEST(GapEventWindows, item20_the_soaks_grazing_separation_keeps_the_reference_story) {
  Parameters p;
  p.Jm = 0.21637774422251502, p.Fm = 0.66673850470062734, p.JL = 0.26653858595811997, p.FL = 0.23393447741270076;
  p.K = 0.41995464328454291, p.backlash = 0.97070473836282412, p.theta_R = -1.9868459060461028;
  p.measured_at = model::MeasuredAt::Load;
  const double step = -0.61270279815489748;
  ValidatedParametricFamily family;
  const std::optional<ValidatedEvaluator> evaluator = family.at(p);
  ASSERT_TRUE(evaluator.has_value());
  SimulationOptions o;
  o.t_end = 20;
  o.max_events = 400;
  const SimulationResult closed = simulate_step(*evaluator, step, o);
  const SimulationResult odeint = simulate_step_with_odeint(p, step, o);
  EXPECT_EQ(std::string(to_string(closed.status)), to_string(odeint.status));
  ASSERT_EQ(closed.events.size(), odeint.events.size());
  for (size_t i = 0; i < closed.events.size(); ++i) {
    EXPECT_EQ(closed.events[i].kind, odeint.events[i].kind) << "event " << i;
    EXPECT_NEAR(closed.events[i].t, odeint.events[i].t, 1e-7) << "event " << i;
  }
}

}  // namespace
