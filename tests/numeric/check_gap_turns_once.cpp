// Issue 19, the event loop at the limit: a flight whose gap turns at most once
// (gap_events.hpp, gap_rate_turns_at_most_once and no_return_before_opposite_face; docs/design.md
// "The event loop") does not search the return to the face it left before the opposite face's
// crossing.  On random parameter sets with that property (output at the load; output at the
// motor with an over-damped motor) and random flights leaving a face, the event must be the one of
// the two searches one after the other (the opposite face, then the return up to it), bit for bit,
// and a dense scan of the exact gap change between the departure and the crossing must find no
// return; the scan of the gap rate finds at most one turn.  The same shortcut forced on flights of
// under-damped motors (where the property is denied) misses returns — so the comparison can fail —,
// and with the property it costs fewer samples.
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "gap_turns_once_parameters.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/linear_flight.hpp"
#include "sequential_gap_event.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

namespace {

using namespace backlash;
using namespace backlash::numeric;
using detail::GapEvent;
using detail::GapEventKind;

using backlash::testing::random_gap_parameters;

// A flight leaving the face σ at one velocity for both bodies, its relative acceleration toward the
// opposite face; nothing when the draw presses into the face.
// Under-damped motors (`near`) start near θR and slowly: small swings, which return.
std::optional<SmallVector> leaving_flight(const Parameters& p, std::mt19937_64& random, int& face, bool near) {
  const double spread = near ? 0.1 : 1.5, speed = near ? 0.2 : 1.0;
  std::uniform_real_distribution<double> offset(-spread, spread), velocity(-speed, speed);
  face = random() % 2 ? 1 : -1;
  const double v = velocity(random), theta_m = p.theta_R + offset(random);
  SmallVector x(4);
  x << theta_m, v, theta_m + face * p.backlash / 2, v;
  const LinearSegment free = free_mode_segment(p);
  const SmallVector rate = free.A * x + free.c;
  if (!(face * (rate(3) - rate(1)) < 0)) return std::nullopt;
  return x;
}

using backlash::testing::CountedFlight;
using backlash::testing::sequential_event;

bool same_event(const std::optional<GapEvent>& a, const std::optional<GapEvent>& b) {
  if (a.has_value() != b.has_value()) return false;
  return !a || (a->kind == b->kind && a->crossing.t == b->crossing.t && a->crossing.grazing == b->crossing.grazing);
}

// Sign changes of Δx (beyond `noise`, against the departure's side) on a dense grid of (0, t]: a
// return the scan sees; and the turns of Δx' there.
struct Scan {
  int returns = 0, turns = 0;
};

Scan dense_scan(const LinearFlight& flight, double t, double level, double noise) {
  constexpr int kPoints = 4000;
  Scan scan;
  double last_rate = 0;
  for (int k = 1; k < kPoints; ++k) {
    const double s = t * k / kPoints;
    const SmallVector change = flight.change(s);
    const double gap = change(2) - change(0);
    if (gap * level < 0 && std::fabs(gap) > noise) ++scan.returns;
    const SmallVector x = flight.state(s);
    const double rate = x(3) - x(1);
    if (std::fabs(rate) > 1e-12 && last_rate != 0 && (rate > 0) != (last_rate > 0)) ++scan.turns;
    if (std::fabs(rate) > 1e-12) last_rate = rate;
  }
  return scan;
}

struct Tally {
  long flights = 0, differ = 0, returns = 0, samples_once = 0, samples_reference = 0, opposite = 0;
};

void run_flights(int kind, bool forced, int sets, Tally& tally) {
  std::mt19937_64 random(1900 + kind);
  for (int set = 0; set < sets; ++set) {
    const Parameters p = random_gap_parameters(random, kind);
    ASSERT_EQ(detail::gap_rate_turns_at_most_once(p), kind != 2);
    const double horizon = 20 * slowest_time_scale(p);
    const WitnessMode mode = detail::gap_witness_mode(free_mode_segment(p), servo_time_unit(p));
    for (int i = 0; i < 12; ++i) {
      int face = 0;
      const std::optional<SmallVector> x0 = leaving_flight(p, random, face, kind == 2);
      if (!x0) continue;
      const double level = -face * p.backlash;
      const double scale = std::max({1.0, std::fabs((*x0)(0)), std::fabs((*x0)(2))});
      const CountedFlight reference_sample{LinearFlight(free_mode_segment(p), *x0)};
      const auto reference = sequential_event(mode, reference_sample, level, horizon, scale);
      const CountedFlight sample{LinearFlight(free_mode_segment(p), *x0)};
      const auto event = detail::first_gap_event_with(mode, sample, level, horizon, scale, kind != 2 || forced);
      ++tally.flights;
      tally.samples_once += sample.samples;
      tally.samples_reference += reference_sample.samples;
      if (!same_event(event, reference)) ++tally.differ;
      if (!event || event->kind != GapEventKind::OppositeFace) continue;
      ++tally.opposite;
      const Scan scan = dense_scan(sample.flight, event->crossing.t, level, 1e-12 * scale);
      tally.returns += scan.returns > 0;
      if (kind != 2) {
        EXPECT_LE(scan.turns, 1) << "set " << set << " flight " << i;
      }
    }
  }
}

TEST(GapTurnsOnce, item19_a_gap_that_turns_at_most_once_gives_the_sequential_searches_events_with_no_return_missed) {
  for (int kind : {0, 1}) {
    Tally tally;
    run_flights(kind, false, 40, tally);
    EXPECT_GT(tally.opposite, 60) << "kind " << kind;  // the shortcut is exercised
    EXPECT_EQ(tally.differ, 0) << "kind " << kind << ": events not the sequential searches' of " << tally.flights;
    EXPECT_EQ(tally.returns, 0) << "kind " << kind << ": a return to the face left before the opposite face";
    EXPECT_LT(tally.samples_once, tally.samples_reference) << "kind " << kind;
  }
}

TEST(GapTurnsOnce, item19_forced_on_under_damped_motors_the_shortcut_misses_returns) {
  Tally tally;
  run_flights(2, true, 40, tally);
  EXPECT_GT(tally.differ, 0) << "of " << tally.flights << " flights";
  EXPECT_GT(tally.returns, 0) << "of " << tally.flights << " flights";
}

}  // namespace
