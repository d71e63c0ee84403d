// Issue 19, the event loop at the limit: a flight's quiet tail (numeric/hybrid/quiet_tail.hpp,
// quiet_gap_from; docs/design.md "The event loop").  With the output at the motor and an
// under-damped motor (cases I, II) a flight that never reaches a face — the decaying swings to rest
// inside the backlash, 44 of case I's 60 s — was searched to the horizon; the searches now stop
// where the tail's bound proves that neither level is crossed before it.  On random parameter sets
// of that kind and random flights: (1) a dense scan of the exact gap (the flight's exponential)
// finds no crossing of either level, nor a touch, after the tail's start; (2) every event is the
// sequential searches' over the whole horizon (the reference, without the tail) bit for bit;
// (3) the tail is found for most flights that end inside the backlash, and it saves samples.
// The scan's own power: a tail claimed from the flight's start (Δx(0) = 0, on a level) is caught;
// and a bound made wrong on purpose (the motor's envelope halved, or the load's move taken at the
// horizon alone) fails (1) here — tried when this test was written.
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/linear_flight.hpp"
#include "hybrid/quiet_tail.hpp"
#include "sequential_gap_event.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>

namespace {

using namespace backlash;
using namespace backlash::numeric;
using backlash::testing::CountedFlight;
using backlash::testing::sequential_event;

// A random drive of cases I/II's kind: output at the motor, K = 1, θR = 1, the motor
// under-damped (Fm² < 4 K Jm, by a margin), the load's friction from none (case II) up.
Parameters random_drive(std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0, 1);
  Parameters p;
  p.measured_at = model::MeasuredAt::Motor;
  p.K = 1;
  p.theta_R = 1;
  p.Jm = 0.2 + unit(random);
  p.JL = 0.2 + unit(random);
  p.Fm = (0.05 + 0.9 * unit(random)) * 2 * std::sqrt(p.K * p.Jm);
  p.FL = unit(random) < 0.2 ? 0 : 0.05 + unit(random);
  p.backlash = 0.05 + 0.3 * unit(random);
  return p;
}

// A flight leaving the face σ (flight_leaving_face); `near`: within b/2 of θR at b/2 per time
// unit at most (the swings that mostly end inside the backlash), else within 0.3 rad at 0.3 rad/s
// (mostly a face).
std::optional<SmallVector> flight_from_face(const Parameters& p, std::mt19937_64& random, int& face, bool near) {
  const double spread = near ? p.backlash / 2 : 0.3, max_speed = near ? p.backlash / 2 * std::sqrt(p.K / p.Jm) : 0.3;
  return backlash::testing::flight_leaving_face(p, random, face, spread, max_speed);
}

// The first scan point on [from, horizon] (n + 1 points, both ends) where the exact gap change is
// not strictly between the levels; NAN when none.
double scan_for_a_touch(const LinearFlight& flight, double low, double high, double from, double horizon, int n) {
  for (int i = 0; i <= n; ++i) {
    const double t = from + (horizon - from) * i / n;
    const SmallVector d = flight.change(t);
    const double gap = d(2) - d(0);
    if (!(gap > low && gap < high)) return t;
  }
  return NAN;
}

double position_scale(const SmallVector& x) { return std::max({1.0, std::fabs(x(0)), std::fabs(x(2))}); }

TEST(GapQuietTail, item19_the_tail_hides_no_crossing_and_leaves_every_event_bit_for_bit) {
  std::mt19937_64 random(1919);
  long flights = 0, tails = 0, none = 0, none_with_tail = 0, events = 0, saved = 0;
  for (int set = 0; set < 60; ++set) {
    const Parameters p = random_drive(random);
    const LinearSegment free = free_mode_segment(p);
    const WitnessMode mode = detail::gap_witness_mode(free, servo_time_unit(p));
    const double horizon = 20 + 80 * std::uniform_real_distribution<double>(0, 1)(random);
    for (int i = 0; i < 8; ++i) {
      int face = 0;
      const std::optional<SmallVector> x0 = flight_from_face(p, random, face, i % 2 == 0);
      if (!x0) continue;
      ++flights;
      const LinearFlight exact(free, *x0);
      const double opposite = -face * p.backlash;
      const double low = std::min(0.0, opposite), high = std::max(0.0, opposite);
      const double tail = detail::quiet_gap_from(free.A, free.c, *x0, opposite, 0, horizon, mode.first_window);
      const std::string label = "set " + std::to_string(set) + ", flight " + std::to_string(i);
      if (tail < horizon) {
        ++tails;
        EXPECT_TRUE(std::isnan(scan_for_a_touch(exact, low, high, tail, horizon, 20000)))
            << label << ": the exact gap touches a level after the tail's start " << tail << " s";
        // The scan's power: a tail claimed from the start is caught (Δx(0) = 0 is on a level).
        EXPECT_FALSE(std::isnan(scan_for_a_touch(exact, low, high, 0, horizon, 20000))) << label;
      }
      const CountedFlight flight{exact};
      const auto sample = [&flight](double t) { return flight(t); };
      const auto windowed = detail::first_gap_event(mode, sample, opposite, horizon, position_scale(*x0));
      const long cost = flight.samples;
      flight.samples = 0;
      const auto reference = sequential_event(mode, sample, opposite, horizon, position_scale(*x0));
      ASSERT_EQ(windowed.has_value(), reference.has_value()) << label;
      if (windowed) {
        ++events;
        EXPECT_EQ(windowed->kind, reference->kind) << label;
        EXPECT_EQ(windowed->crossing.t, reference->crossing.t) << label;
        EXPECT_EQ(windowed->crossing.grazing, reference->crossing.grazing) << label;
        EXPECT_EQ(windowed->departure, reference->departure) << label;
      } else {
        ++none;
        none_with_tail += tail < horizon;
        saved += flight.samples - cost;
      }
    }
  }
  std::printf("%ld flights: %ld events, %ld to the horizon (%ld of them with a quiet tail), %ld tails; "
              "%ld samples saved against the sequential searches\n", flights, events, none, none_with_tail, tails, saved);
  EXPECT_GE(events, 50);            // both kinds of flight are exercised
  EXPECT_GE(none, 50);
  EXPECT_GE(none_with_tail * 10, none * 9);  // the tail found for nearly every flight that stays inside
  EXPECT_GT(saved, 0);
}

// The bound with both faces as levels (a flight from inside the backlash; the event loop does not
// take the tail there, where a run starts, so its events are the windowed searches' as before):
// no crossing after the tail's start in a dense scan of the exact gap.
TEST(GapQuietTail, item19_from_inside_the_backlash_the_tail_hides_no_crossing) {
  std::mt19937_64 random(1920);
  std::uniform_real_distribution<double> unit(0, 1);
  long tails = 0;
  for (int set = 0; set < 40; ++set) {
    const Parameters p = random_drive(random);
    const LinearSegment free = free_mode_segment(p);
    const WitnessMode mode = detail::gap_witness_mode(free, servo_time_unit(p));
    const double half = p.backlash / 2, horizon = 60;
    SmallVector x0(4);
    const double start_gap = (2 * unit(random) - 1) * 0.9 * half;
    x0 << p.theta_R + 0.2 * (2 * unit(random) - 1), 0.2 * (2 * unit(random) - 1), 0, 0.05 * (2 * unit(random) - 1);
    x0(2) = x0(0) + start_gap;
    const int face = random() % 2 ? 1 : -1;
    const double a = face * half - start_gap, b = -face * half - start_gap;
    const LinearFlight exact(free, x0);
    const double tail = detail::quiet_gap_from(free.A, free.c, x0, a, b, horizon, mode.first_window);
    if (tail < horizon) {
      ++tails;
      EXPECT_TRUE(std::isnan(scan_for_a_touch(exact, std::min(a, b), std::max(a, b), tail, horizon, 20000)))
          << "set " << set << ": tail from " << tail << " s";
    }
    const CountedFlight flight{exact};
    const auto sample = [&flight](double t) { return flight(t); };
    const auto windowed = detail::first_gap_event_inside(mode, sample, start_gap, face, half, horizon);
    const std::optional<Crossing> same = first_crossing(mode, sample, a, 0, horizon);
    const std::optional<Crossing> other = first_crossing(mode, sample, b, 0, same ? same->t : horizon);
    const std::optional<Crossing> first = other && (!same || other->t < same->t) ? other : same;
    ASSERT_EQ(windowed.has_value(), first.has_value()) << "set " << set;
    if (windowed) {
      EXPECT_EQ(windowed->crossing.t, first->t) << "set " << set;
    }
  }
  EXPECT_GE(tails, 10);
}

}  // namespace
