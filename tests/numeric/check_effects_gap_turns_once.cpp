// Issue 19, the effects engine per event: a free flight whose added torques are constant over its
// segment (the offset, a clipped drive, Coulomb friction while the slip holds) and whose gap rate
// has at most two real zeros (effects_engine.hpp, free_gap_turns_once; docs/effects.md, "A flight
// whose gap turns at most once") does not search the return to the face it left where that search
// is proved to find nothing: in the window of the opposite face's crossing, and in a window at
// whose end the gap still moves away from the face left.  On random parameter sets (output at the load; at the motor with an
// over-damped motor) and random flights leaving a face at one velocity for both bodies, with each
// constant-torque effect, the segment's exit must be the one of the searches without the shortcut,
// bit for bit, and a dense scan of the exact gap up to an opposite face's crossing must find no
// return.  The shortcut forced onto flights the proof excludes (an under-damped motor at the
// output, a slipping load's Coulomb torque with a linear drive) misses returns — so the
// comparison can fail (the under-damped motor's, asserted).
#include "effects/effects_engine.hpp"
#include "gap_turns_once_parameters.hpp"

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>

namespace {

using namespace backlash;
using namespace backlash::numeric;
using detail::Guard;
using detail::OneTurn;

enum class Effect { TorqueOffset, Saturation, CoulombMotor, CoulombLoad };

using backlash::testing::random_gap_parameters;

Effects random_effects(std::mt19937_64& random, Effect effect) {
  std::uniform_real_distribution<double> small(0.005, 0.1), limit(0.2, 1.0), offset(-0.1, 0.1);
  Effects e;
  switch (effect) {
    case Effect::TorqueOffset: e.torque_offset = offset(random); break;
    case Effect::Saturation: e.saturation = limit(random); break;
    case Effect::CoulombMotor: e.coulomb_motor = small(random); break;
    case Effect::CoulombLoad: e.coulomb_load = small(random); break;
  }
  return e;
}

struct Flight {
  HybridState start;
  Mode mode;
};

// A flight leaving face σ at one velocity v for both bodies, in the mode its state is in, its
// relative acceleration toward the opposite face; nothing when the draw presses into the face.
std::optional<Flight> leaving_flight(const Parameters& p, const Effects& e, std::mt19937_64& random, bool near) {
  const double spread = near ? 0.1 : 1.5, speed = near ? 0.2 : 1.0;
  std::uniform_real_distribution<double> offset(-spread, spread), velocity(-speed, speed);
  Flight f;
  const int face = random() % 2 ? 1 : -1;
  const double v = velocity(random);
  f.start.theta_m = p.theta_R + offset(random);
  f.start.theta_L = f.start.theta_m + face * p.backlash / 2;
  f.start.dtheta_m = f.start.dtheta_L = v;
  f.start.in_contact = false;
  f.start.face = face;
  const double theta_o = p.measured_at == model::MeasuredAt::Load ? f.start.theta_L : f.start.theta_m;
  const double demand = p.K * (p.theta_R - theta_o);
  const int regime = e.saturating() && demand > e.saturation ? 1 : e.saturating() && demand < -e.saturation ? -1 : 0;
  f.start.drive_regime = regime;
  const int slip = v > 0 ? 1 : -1;
  f.mode = Mode{ModeKind::Free, face, regime, slip, slip};
  const double drive = (regime == 0 ? demand : regime * e.saturation) + e.torque_offset;
  const double motor = (drive - p.Fm * v - e.coulomb_motor * slip) / p.Jm;
  const double load = (-p.FL * v - e.coulomb_load * slip) / p.JL;
  if (!(face * (load - motor) < 0)) return std::nullopt;
  return f;
}

bool same_exit(const detail::Segment& a, const detail::Segment& b) {
  if (a.exit.has_value() != b.exit.has_value() || std::memcmp(&a.duration, &b.duration, sizeof a.duration) != 0)
    return false;
  if (!a.exit) return true;
  return std::memcmp(&a.exit->tau, &b.exit->tau, sizeof a.exit->tau) == 0 && a.exit->witness.guard == b.exit->witness.guard &&
         a.exit->witness.face == b.exit->witness.face && a.exit->grazing == b.exit->grazing;
}

// Points of a dense grid of (0, t) where the gap lies beyond the face left (by more than `noise`).
int dense_returns(const Parameters& p, const detail::Segment& segment, int face, double t, double noise) {
  constexpr int kPoints = 4000;
  int returns = 0;
  for (int k = 1; k < kPoints; ++k) {
    const HybridState s = segment.state(t * k / kPoints);
    returns += p.backlash / 2 - face * (s.theta_L - s.theta_m) < -noise;
  }
  return returns;
}

struct Tally {
  long flights = 0, differ = 0, skipped = 0, returns = 0, same_face = 0;
};

void run_flights(Effect effect, int kind, OneTurn one_turn, int sets, Tally& tally) {
  std::mt19937_64 random(1950 + 10 * static_cast<int>(effect) + kind);
  for (int set = 0; set < sets; ++set) {
    const Parameters p = random_gap_parameters(random, kind);
    const Effects e = random_effects(random, effect);
    const double horizon = 20 * slowest_time_scale(p);
    for (int i = 0; i < 12; ++i) {
      const std::optional<Flight> f = leaving_flight(p, e, random, kind == 2);
      if (!f) continue;
      const auto with = detail::closed_form_segment(p, e, f->mode, f->start, horizon, 0, 0, {}, one_turn);
      const auto without = detail::closed_form_segment(p, e, f->mode, f->start, horizon, 0, 0, {}, OneTurn::Off);
      ++tally.flights;
      if (!same_exit(*with, *without)) ++tally.differ;
      const bool proved = detail::free_gap_turns_once(p, e, f->mode);
      if (one_turn == OneTurn::Proved) {
        EXPECT_EQ(proved, kind != 2 && (effect != Effect::CoulombLoad || f->mode.regime != 0));
      }
      if (one_turn == OneTurn::Proved && !proved) continue;
      tally.skipped += with->exit && with->exit->witness.guard == Guard::GapOpposite;
      tally.same_face += with->exit && with->exit->witness.guard == Guard::GapSame;
      const double scale = std::max({1.0, std::fabs(f->start.theta_m), std::fabs(f->start.theta_L)});
      tally.returns += dense_returns(p, *with, f->start.face, with->duration, 1e-12 * scale) > 0;
    }
  }
}

TEST(EffectsGapTurnsOnce, item19_constant_torques_give_the_unshortened_searches_exits_with_no_return_missed) {
  for (Effect effect : {Effect::TorqueOffset, Effect::Saturation, Effect::CoulombMotor, Effect::CoulombLoad}) {
    for (int kind : {0, 1}) {
      Tally tally;
      run_flights(effect, kind, OneTurn::Proved, 30, tally);
      const int id = static_cast<int>(effect);
      std::printf("effect %d kind %d: %ld flights, %ld ended at the opposite face with the shortcut, %ld returned to "
                  "the face left, %ld differ\n",
                  id, kind, tally.flights, tally.skipped, tally.same_face, tally.differ);
      if (effect != Effect::CoulombLoad) {
        EXPECT_GT(tally.skipped, 40) << "effect " << id << " kind " << kind;
        // Returns are found where the gap has turned (the return's search is left out only while it rises).
        EXPECT_GT(tally.same_face, 5) << "effect " << id << " kind " << kind;
      }
      EXPECT_EQ(tally.differ, 0) << "effect " << id << " kind " << kind << ": exits not the unshortened searches' of "
                                 << tally.flights;
      EXPECT_EQ(tally.returns, 0) << "effect " << id << " kind " << kind << ": a return before the opposite face";
    }
  }
}

// A slipping load's Coulomb torque under a saturating drive: proved where the drive is clipped.
TEST(EffectsGapTurnsOnce, item19_a_clipped_drive_covers_the_loads_coulomb_torque) {
  Tally tally;
  std::mt19937_64 random(1999);
  for (int set = 0; set < 40; ++set) {
    const Parameters p = random_gap_parameters(random, static_cast<int>(random() % 2));
    Effects e = random_effects(random, Effect::CoulombLoad);
    e.saturation = 0.05;
    for (int i = 0; i < 12; ++i) {
      const std::optional<Flight> f = leaving_flight(p, e, random, false);
      if (!f || f->mode.regime == 0) continue;
      ASSERT_TRUE(detail::free_gap_turns_once(p, e, f->mode));
      const double horizon = 20 * slowest_time_scale(p);
      const auto with = detail::closed_form_segment(p, e, f->mode, f->start, horizon, 0, 0, {}, OneTurn::Proved);
      const auto without = detail::closed_form_segment(p, e, f->mode, f->start, horizon, 0, 0, {}, OneTurn::Off);
      ++tally.flights;
      tally.differ += !same_exit(*with, *without);
      tally.skipped += with->exit && with->exit->witness.guard == Guard::GapOpposite;
      tally.returns += dense_returns(p, *with, f->start.face, with->duration, 1e-12) > 0;
    }
  }
  std::printf("clipped, Coulomb load: %ld flights, %ld with the shortcut, %ld differ\n", tally.flights, tally.skipped,
              tally.differ);
  EXPECT_GT(tally.skipped, 40);
  EXPECT_EQ(tally.differ, 0) << "of " << tally.flights;
  EXPECT_EQ(tally.returns, 0);
}

TEST(EffectsGapTurnsOnce, item19_forced_where_the_proof_does_not_hold_the_shortcut_misses_returns) {
  Tally tally;
  for (Effect effect : {Effect::TorqueOffset, Effect::CoulombMotor}) run_flights(effect, 2, OneTurn::Forced, 80, tally);
  std::printf("forced, under-damped: %ld flights, %ld differ, %ld returns missed\n", tally.flights, tally.differ, tally.returns);
  // A slipping load's Coulomb torque with a linear drive (degree 4, not proved, so never shortened
  // in a run: the first test's EXPECT_EQ on free_gap_turns_once): forced here, reported only — the
  // return's search is left out where the gap still rises at a window's end, and these draws miss
  // no return that way (fx19g's look-ahead to the crossing missed 24 of 197).
  Tally load;
  run_flights(Effect::CoulombLoad, 0, OneTurn::Forced, 40, load);
  std::printf("forced, Coulomb load, linear drive: %ld flights, %ld differ, %ld returns missed\n", load.flights, load.differ,
              load.returns);
  EXPECT_GT(tally.differ, 0) << "of " << tally.flights << " flights";
  EXPECT_GT(tally.returns, 0) << "of " << tally.flights << " flights";
}

}  // namespace
