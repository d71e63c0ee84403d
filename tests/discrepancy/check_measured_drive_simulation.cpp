// The rigid drive under a measured drive signal (discrepancy/measured_drive_simulation.hpp, docs/effects.md
// "Measured drive (rigid)"):
//   MeasuredDriveExam   known answers — a constant drive without Coulomb friction is the
//                       textbook solution (F > 0 and F = 0), a drive inside the friction band
//                       never moves the body, a staircase slips at the first sample beyond
//                       the band (delayed by τ), a body stops and reverses at the closed-form
//                       instants, Tc = 0 passes through v = 0 without events, the parameters
//                       of a case map to the rigid drive;
//   MeasuredDriveCheck  randomised properties — the closed form against an independent
//                       Boost.Odeint (dopri5, 1e-12) reference integrated piece by piece with
//                       its own stick/slip handling, the mirror symmetry, and a run split in
//                       two equals the run in one go;
//   MeasuredDriveInput  bad input is refused with std::invalid_argument naming the problem.
#include "backlash/discrepancy/measured_drive_simulation.hpp"

#include <boost/numeric/odeint.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using backlash::discrepancy::DriveEventKind;
using backlash::discrepancy::MeasuredDriveRun;
using backlash::discrepancy::RigidDrive;
using backlash::discrepancy::simulate_measured_drive;

constexpr double eps = std::numeric_limits<double>::epsilon();
constexpr double infinity = std::numeric_limits<double>::infinity();

std::vector<double> sample_times(std::size_t n, double t0 = 0, double period = 1e-3) {
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) t[k] = t0 + static_cast<double>(k) * period;
  return t;
}

double max_abs(const std::vector<double>& values) {
  double m = 0;
  for (double v : values) m = std::max(m, std::fabs(v));
  return m;
}

// ---------------------------------------------------------------- known answers

// Constant net drive c, no Coulomb friction, from (x0, v0): the textbook solution, in long
// double.  The simulator composes n pieces (one per sample); each adds a few ulps of |x|
// and of its increment, so it is held to 16·n·eps·max|x| (and the velocity, whose error
// does not accumulate through a contracting e^{−Fh/J}, to 16·n·eps·max|v|).
void expect_textbook(double J, double F, double c, double x0, double v0) {
  const std::size_t n = 2001;
  const std::vector<double> t = sample_times(n, 0.25);
  const std::vector<double> drive(n, c);
  RigidDrive m;
  m.J = J;
  m.F = F;
  const MeasuredDriveRun run = simulate_measured_drive(m, t, drive, 0, n - 1, x0, v0);
  ASSERT_EQ(run.x.size(), n);
  EXPECT_TRUE(run.events.empty());
  const double x_tolerance = 16.0 * n * eps * max_abs(run.x);
  const double v_tolerance = 16.0 * n * eps * max_abs(run.v);
  double worst_x = 0, worst_v = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const long double h = static_cast<long double>(t[k]) - t[0];
    long double x, v;
    if (F == 0) {
      x = x0 + v0 * h + c * h * h / (2.0L * J);
      v = v0 + c * h / J;
    } else {
      const long double terminal = static_cast<long double>(c) / F;
      const long double decay = std::exp(-static_cast<long double>(F) * h / J);
      x = x0 + terminal * h + (v0 - terminal) * (static_cast<long double>(J) / F) * (1.0L - decay);
      v = terminal + (v0 - terminal) * decay;
    }
    worst_x = std::max(worst_x, static_cast<double>(std::fabs(run.x[k] - x)));
    worst_v = std::max(worst_v, static_cast<double>(std::fabs(run.v[k] - v)));
    ASSERT_LE(std::fabs(run.x[k] - x), x_tolerance)
        << "J=" << J << " F=" << F << " c=" << c << ": x at t=" << t[k] << " returned " << run.x[k] << " instead of "
        << static_cast<double>(x);
    ASSERT_LE(std::fabs(run.v[k] - v), v_tolerance)
        << "J=" << J << " F=" << F << " c=" << c << ": v at t=" << t[k] << " returned " << run.v[k] << " instead of "
        << static_cast<double>(v);
  }
  std::printf("J=%g F=%g c=%g: max |dx| = %.2e (tolerance %.2e), max |dv| = %.2e (tolerance %.2e)\n", J, F, c,
              worst_x, x_tolerance, worst_v, v_tolerance);
}

TEST(MeasuredDriveExam, AConstantDriveWithoutCoulombFrictionIsTheTextbookSolution) {
  expect_textbook(2.0, 3.0, 1.5, 0.1, -0.4);
  expect_textbook(95.1, 203.5, 120.0, 0.0, 0.0);    // EMPS-like: kg, N·s/m, N
  expect_textbook(0.01, 40.0, -2.0, 1.0, 3.0);      // F·h/J = 4 per sample: the expm1 branch
  expect_textbook(0.5, 1e-3, 0.7, -0.2, 0.3);       // F·h/J = 2e-6: the series branch
}

TEST(MeasuredDriveExam, WithoutViscousFrictionThePositionIsAParabola) {
  expect_textbook(2.0, 0.0, 1.5, 0.1, -0.4);
  expect_textbook(95.1, 0.0, -30.0, 0.2, 0.05);
}

TEST(MeasuredDriveExam, ADriveInsideTheFrictionBandNeverMovesABodyAtRest) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> inside(-2.4, 1.4);  // gain 1, T0 = 0.5: |u + T0| ≤ 1.9 < Tc = 2
  const std::size_t n = 3000;
  const std::vector<double> t = sample_times(n, 1.0);
  std::vector<double> drive(n);
  for (double& d : drive) d = inside(rng);
  RigidDrive m;
  m.J = 3;
  m.F = 5;
  m.coulomb = 2;
  m.offset = 0.5;
  m.delay = 0.0037;
  for (bool start_stuck : {false, true}) {
    const MeasuredDriveRun run = simulate_measured_drive(m, t, drive, 10, n - 1, 0.125, 0.0, start_stuck);
    for (std::size_t k = 0; k < run.x.size(); ++k) {
      ASSERT_EQ(run.x[k], 0.125) << "x at sample " << k << " returned " << run.x[k] << " instead of 0.125";
      ASSERT_EQ(run.v[k], 0.0) << "v at sample " << k << " returned " << run.v[k] << " instead of 0";
    }
    EXPECT_EQ(run.event_count, 0u) << "returned " << run.event_count << " events instead of 0";
    EXPECT_TRUE(run.stuck_at_end) << "returned not stuck at the end instead of stuck";
  }
}

// A staircase drive_k = ±0.1·k with T0 = ∓0.35, Tc = 1: the net drive |0.1k − 0.35| first
// exceeds 1 at k = 14; the body slips when that sample acts, at t_14 + τ, and not before.
TEST(MeasuredDriveExam, AStaircaseSlipsAtTheFirstSampleBeyondTheBandDelayedByTau) {
  const std::size_t n = 40;
  const std::vector<double> t = sample_times(n, 2.0);
  for (double sign : {1.0, -1.0}) {
    for (double tau : {0.0, 0.0025, 0.003}) {
      std::vector<double> drive(n);
      for (std::size_t k = 0; k < n; ++k) drive[k] = sign * 0.1 * static_cast<double>(k);
      RigidDrive m;
      m.J = 0.5;
      m.F = 0;
      m.coulomb = 1;
      m.offset = -sign * 0.35;
      m.delay = tau;
      std::size_t first_beyond = n;
      for (std::size_t k = 0; k < n && first_beyond == n; ++k)
        if (std::fabs(drive[k] + m.offset) > m.coulomb) first_beyond = k;
      ASSERT_EQ(first_beyond, 14u);
      const double t_slip = t[first_beyond] + tau;
      const MeasuredDriveRun run = simulate_measured_drive(m, t, drive, 0, n - 1, -1.0, 0.0);
      ASSERT_FALSE(run.events.empty()) << "tau=" << tau << ": returned no event instead of a slip at " << t_slip;
      EXPECT_EQ(run.events[0].kind, DriveEventKind::Slip)
          << "returned " << to_string(run.events[0].kind) << " instead of slip";
      EXPECT_EQ(run.events[0].t, t_slip) << "tau=" << tau << ": slipped at " << run.events[0].t << " instead of " << t_slip;
      EXPECT_EQ(run.event_count, 1u) << "returned " << run.event_count << " events instead of 1 (the drive only grows)";
      for (std::size_t k = 0; k < n; ++k) {
        if (t[k] <= t_slip) {
          ASSERT_EQ(run.x[k], -1.0) << "tau=" << tau << ": x at t=" << t[k] << " returned " << run.x[k]
                                    << " instead of -1 (before the slip)";
        } else {
          ASSERT_GT(sign * (run.x[k] + 1.0), 0.0) << "tau=" << tau << ": x at t=" << t[k] << " returned " << run.x[k]
                                                  << " instead of a position beyond -1 in the direction of the drive";
        }
      }
      // The first output after the slip, by hand: the net drive of sample 14 acts from t_slip.
      std::size_t k_after = 0;
      while (t[k_after] <= t_slip) ++k_after;
      const double c = drive[first_beyond] + m.offset - m.coulomb * sign;
      const double h = t[k_after] - t_slip;
      const double expected = -1.0 + c * h * h / (2 * m.J);
      EXPECT_NEAR(run.x[k_after], expected, 8 * eps) << "tau=" << tau << ": x at t=" << t[k_after] << " returned "
                                                    << run.x[k_after] << " instead of " << expected;
    }
  }
}

// Constant net drive a with |a| < Tc on a body moving at v0 > 0: it stops at
// h* = (J/F)·ln(1 + F·v0/(Tc − a)) (F = 0: J·v0/(Tc − a)) and stays; with a < −Tc it
// reverses there instead and accelerates backwards under a + Tc.  The simulator reaches
// the zero after n* = h*/period pieces, each adding a few ulps to v (≤ 16·eps·v0 counted
// generously) and to x (≤ 16·eps·max|x|): the zero's time is then off by at most
// 16·n*·eps·v0/|v'| (v' = (a − Tc)/J), plus 16 ulps of t for h* itself.  After a
// reversal the Coulomb torque flips that much early or late: the velocity is off by at
// most 2Tc/J times that, the position by that times the time since.
TEST(MeasuredDriveExam, AMovingBodyStopsOrReversesAtTheClosedFormInstant) {
  const std::size_t n = 1000;
  const double period = 1e-3;
  const std::vector<double> t = sample_times(n, 0.0, period);
  for (double F : {0.0, 0.8}) {
    for (double a : {0.3, -1.7}) {
      RigidDrive m;
      m.J = 2;
      m.F = F;
      m.coulomb = 1;
      const std::vector<double> drive(n, a);
      const double v0 = 0.2;
      const double c = a - m.coulomb;  // while moving forward
      const long double h_star =
          F == 0 ? -static_cast<long double>(m.J) * v0 / c : (m.J / F) * std::log1p(-static_cast<long double>(F) * v0 / c);
      const long double x_star =
          F == 0 ? v0 * h_star / 2
                 : (c / F) * h_star + (v0 - c / F) * (m.J / F) * (1 - std::exp(-static_cast<long double>(F) * h_star / m.J));
      const MeasuredDriveRun run = simulate_measured_drive(m, t, drive, 0, n - 1, 0.0, v0);
      ASSERT_EQ(run.event_count, 1u) << "F=" << F << " a=" << a << ": returned " << run.event_count << " events instead of 1";
      const auto& e = run.events[0];
      EXPECT_EQ(e.kind, a > -m.coulomb ? DriveEventKind::Stick : DriveEventKind::Reversal)
          << "returned " << to_string(e.kind) << " instead of " << (a > -m.coulomb ? "stick" : "reversal");
      const double pieces = static_cast<double>(h_star) / period + 1;
      const double t_tolerance = 16 * pieces * eps * v0 / (std::fabs(c) / m.J) + 16 * eps * e.t;
      const double x_tolerance = 16 * pieces * eps * std::fabs(static_cast<double>(x_star));
      EXPECT_NEAR(e.t, static_cast<double>(h_star), t_tolerance)
          << "F=" << F << " a=" << a << ": stopped at " << e.t << " instead of " << static_cast<double>(h_star);
      EXPECT_NEAR(e.x, static_cast<double>(x_star), x_tolerance)
          << "F=" << F << " a=" << a << ": stopped at x=" << e.x << " instead of " << static_cast<double>(x_star);
      const long double c_back = a + m.coulomb;  // after a reversal
      const double v_flip = 2 * m.coulomb / m.J * t_tolerance;
      for (std::size_t k = 0; k < n; ++k) {
        if (t[k] <= e.t) continue;
        long double x = x_star, v = 0;
        const long double h = t[k] - h_star;
        if (a <= -m.coulomb) {
          if (F == 0) {
            x = x_star + c_back * h * h / (2 * m.J);
            v = c_back * h / m.J;
          } else {
            const long double decay = std::exp(-F * h / m.J);
            x = x_star + (c_back / F) * h - (c_back / F) * (m.J / F) * (1 - decay);
            v = (c_back / F) * (1 - decay);
          }
        }
        const double x_k_tolerance = 16 * (static_cast<double>(k) + 1) * eps * max_abs(run.x) + x_tolerance +
                                     v_flip * static_cast<double>(h);
        const double v_k_tolerance = 16 * (static_cast<double>(k) + 1) * eps * max_abs(run.v) + v_flip;
        ASSERT_NEAR(run.x[k], static_cast<double>(x), x_k_tolerance)
            << "F=" << F << " a=" << a << ": x at t=" << t[k] << " returned " << run.x[k] << " instead of "
            << static_cast<double>(x);
        ASSERT_NEAR(run.v[k], static_cast<double>(v), v_k_tolerance)
            << "F=" << F << " a=" << a << ": v at t=" << t[k] << " returned " << run.v[k] << " instead of "
            << static_cast<double>(v);
      }
      std::printf("F=%g a=%g: %s at t = %.17g (closed form %.17g, |dt| = %.1e, tolerance %.1e)\n", F, a,
                  to_string(e.kind), e.t, static_cast<double>(h_star), std::fabs(e.t - static_cast<double>(h_star)),
                  t_tolerance);
      EXPECT_EQ(run.stuck_at_end, a > -m.coulomb);
    }
  }
}

TEST(MeasuredDriveExam, WithoutCoulombFrictionTheVelocityPassesThroughZeroWithoutEvents) {
  const std::size_t n = 500;
  const std::vector<double> t = sample_times(n, 0.0);
  const std::vector<double> drive(n, -1.0);
  RigidDrive m;
  m.J = 0.1;
  const MeasuredDriveRun run = simulate_measured_drive(m, t, drive, 0, n - 1, 0.0, 0.02);  // zero at 2 ms
  EXPECT_EQ(run.event_count, 0u) << "returned " << run.event_count << " events instead of 0";
  EXPECT_FALSE(run.stuck_at_end);
  const double h = t[n - 1];
  EXPECT_NEAR(run.v.back(), 0.02 - h / 0.1, 1e-12) << "returned " << run.v.back() << " instead of " << 0.02 - h / 0.1;
  EXPECT_NEAR(run.x.back(), 0.02 * h - h * h / 0.2, 1e-12)
      << "returned " << run.x.back() << " instead of " << 0.02 * h - h * h / 0.2;
}

TEST(MeasuredDriveExam, SaturationClipsTheDriveBeforeTheOffsetIsAdded) {
  RigidDrive m;
  m.gain = 2;
  m.saturation = 3;
  m.offset = 0.5;
  EXPECT_EQ(applied_torque(m, 1.0), 2.5);
  EXPECT_EQ(applied_torque(m, 10.0), 3.5) << "returned " << applied_torque(m, 10.0) << " instead of 3.5";
  EXPECT_EQ(applied_torque(m, -10.0), -2.5) << "returned " << applied_torque(m, -10.0) << " instead of -2.5";
}

TEST(MeasuredDriveExam, ACaseMapsToOneRigidBodyWithOneFriction) {
  backlash::numeric::Parameters p;
  p.Jm = 1.5;
  p.JL = 2.5;
  p.Fm = 0.25;
  p.FL = 0.5;
  p.backlash = 0;
  backlash::numeric::Effects e;
  e.coulomb_motor = 0.125;
  e.coulomb_load = 0.375;
  e.torque_offset = -0.2;
  e.saturation = 7;
  e.delay = 0.004;
  const RigidDrive m = backlash::discrepancy::rigid_drive_of(p, e, 35.15);
  EXPECT_EQ(m.J, 4.0);
  EXPECT_EQ(m.F, 0.75);
  EXPECT_EQ(m.coulomb, 0.5) << "returned " << m.coulomb << " instead of 0.5 (coulomb_motor + coulomb_load)";
  EXPECT_EQ(m.offset, -0.2);
  EXPECT_EQ(m.saturation, 7.0);
  EXPECT_EQ(m.delay, 0.004);
  EXPECT_EQ(m.gain, 35.15);
}

// ---------------------------------------------------------------- the independent reference

// Boost.Odeint dopri5 (abs = rel = 1e-12) on J·v' = a − F·v − Tc·s, x' = v, written from
// the equations, not from the simulator: its own piece list (every output time and every
// shifted sample t_k + τ inside the run, sorted), its own drive lookup, and stick/slip by
// the static rule at v = 0, a velocity zero found by bisection on the dense output.
struct ReferenceEvent {
  double t;
  DriveEventKind kind;
  double x;
  double deceleration;  ///< |v'| just before the zero (Stick, Reversal), for the time tolerance
};
struct ReferenceRun {
  std::vector<double> x, v;
  std::vector<ReferenceEvent> events;
  long steps = 0;  ///< accepted dopri5 steps plus dense-output evaluations
  bool stuck_at_end = false;
};

constexpr double odeint_tolerance = 1e-12;

ReferenceRun reference_run(const RigidDrive& m, const std::vector<double>& t, const std::vector<double>& drive,
                           std::size_t first, std::size_t last, double x0, double v0, bool start_stuck) {
  namespace odeint = boost::numeric::odeint;
  using State = std::array<double, 2>;
  std::vector<double> cuts(t.begin() + static_cast<long>(first), t.begin() + static_cast<long>(last) + 1);
  for (std::size_t k = 0; k <= last; ++k) {
    const double b = t[k] + m.delay;
    if (b > t[first] && b < t[last]) cuts.push_back(b);
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  auto net_drive_at = [&](double time) {  // sample k acts on [t_k + τ, t_{k+1} + τ); before t_0 + τ the first
    std::size_t k = 0;
    while (k + 1 < t.size() && t[k + 1] + m.delay <= time) ++k;
    double u = m.gain * drive[k];
    if (u > m.saturation) u = m.saturation;
    if (u < -m.saturation) u = -m.saturation;
    return u + m.offset;
  };

  ReferenceRun out;
  out.x.push_back(x0);
  out.v.push_back(v0);
  double x = x0, v = v0;
  bool stuck = start_stuck;
  int previous_direction = 0;  // of the motion that ended at the current zero (0: from rest)
  double deceleration = 0;     // |v'| as that motion reached the zero
  std::size_t next_output = first + 1;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = net_drive_at(cuts[i]);
    const double end = cuts[i + 1];
    double now = cuts[i];
    for (int pass = 0; now < end; ++pass) {
      if (pass > 3) throw std::logic_error("reference: no progress in a piece");
      int s = v > 0 ? 1 : v < 0 ? -1 : 0;
      if (m.coulomb > 0 && v == 0) {  // the static rule
        if (std::fabs(a) <= m.coulomb) {
          if (!stuck && previous_direction != 0) out.events.push_back({now, DriveEventKind::Stick, x, deceleration});
          stuck = true;
          break;
        }
        s = a > 0 ? 1 : -1;
        if (stuck || previous_direction == 0)
          out.events.push_back({now, DriveEventKind::Slip, x, 0});
        else if (s != previous_direction)
          out.events.push_back({now, DriveEventKind::Reversal, x, deceleration});
        stuck = false;
        previous_direction = 0;
      }
      const double forcing = a - m.coulomb * s;
      auto rhs = [&](const State& y, State& dy, double) {
        dy[0] = y[1];
        dy[1] = (forcing - m.F * y[1]) / m.J;
      };
      auto stepper = odeint::make_dense_output(odeint_tolerance, odeint_tolerance, end - now,
                                               odeint::runge_kutta_dopri5<State>());
      stepper.initialize(State{x, v}, now, end - now);
      for (;;) {
        const auto [t_old, t_new] = stepper.do_step(rhs);
        ++out.steps;
        State y;
        const double t_high = std::min(t_new, end);
        if (t_new <= end) {
          y = stepper.current_state();
        } else {
          stepper.calc_state(end, y);
          ++out.steps;
        }
        if (m.coulomb > 0 && y[1] * s <= 0) {  // v reached 0 in (t_old, t_high]: bisect
          double lo = t_old, hi = t_high;
          for (;;) {
            const double mid = lo + (hi - lo) / 2;
            if (mid <= lo || mid >= hi) break;
            State ym;
            stepper.calc_state(mid, ym);
            ++out.steps;
            (ym[1] * s > 0 ? lo : hi) = mid;
          }
          if (hi < t_high) {
            stepper.calc_state(hi, y);
            ++out.steps;
          }
          x = y[0];
          v = 0;
          previous_direction = s;
          deceleration = std::fabs(forcing) / m.J;
          now = hi;  // the next pass decides (at the piece's end: the next piece does)
          break;
        }
        if (t_new >= end) {
          x = y[0];
          v = y[1];
          now = end;
          break;
        }
      }
    }
    if (next_output <= last && end == t[next_output]) {
      out.x.push_back(x);
      out.v.push_back(v);
      ++next_output;
    }
  }
  out.stuck_at_end = stuck;
  return out;
}

}  // namespace
namespace {

// ---------------------------------------------------------------- random records

struct RandomCase {
  RigidDrive model;
  std::vector<double> t, drive;
  std::size_t first = 0, last = 0;
  double x0 = 0, v0 = 0;
  bool start_stuck = false;
  std::string label;
};

// A random walk of a few hundred samples at 1 kHz (with EMPS's timing jitter of up to
// 5e-8 s), random J, F (sometimes 0), Tc (sometimes 0, else comparable to the drive so that
// the body sticks and slips), T0, L (sometimes none), τ (0, a multiple of the period, or any).
RandomCase random_case(std::mt19937_64& rng, int index) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
  RandomCase c;
  const std::size_t n = 200 + static_cast<std::size_t>(unit(rng) * 400);
  c.t.resize(n);
  c.drive.resize(n);
  const double t0 = 10 * unit(rng);
  for (std::size_t k = 0; k < n; ++k) c.t[k] = t0 + 1e-3 * static_cast<double>(k) + 5e-8 * (2 * unit(rng) - 1);
  const double step = 0.05 + 0.3 * unit(rng);
  c.drive[0] = 3 * (2 * unit(rng) - 1);
  for (std::size_t k = 1; k < n; ++k) c.drive[k] = c.drive[k - 1] + step * normal(rng);
  RigidDrive& m = c.model;
  m.J = log_uniform(0.01, 20);
  m.F = unit(rng) < 0.25 ? 0.0 : m.J * log_uniform(0.1, 300);
  m.gain = log_uniform(0.3, 3) * (unit(rng) < 0.2 ? -1 : 1);
  m.coulomb = unit(rng) < 0.2 ? 0.0 : 2 * unit(rng);
  m.offset = unit(rng) - 0.5;
  m.saturation = unit(rng) < 0.5 ? infinity : 0.5 + 3 * unit(rng);
  const double r = unit(rng);
  m.delay = r < 0.25 ? 0.0 : r < 0.5 ? 1e-3 * std::floor(1 + 5 * unit(rng)) : 6e-3 * unit(rng);
  c.first = static_cast<std::size_t>(unit(rng) * 20);
  c.last = n - 1 - static_cast<std::size_t>(unit(rng) * 20);
  c.x0 = 2 * unit(rng) - 1;
  c.v0 = unit(rng) < 0.3 ? 0.0 : 0.5 * normal(rng);
  c.start_stuck = c.v0 == 0 && unit(rng) < 0.5;
  char text[320];
  std::snprintf(text, sizeof text,
                "case %d: n=%zu first=%zu last=%zu J=%.17g F=%.17g Tc=%.17g T0=%.17g L=%g tau=%.17g gain=%.17g x0=%.17g "
                "v0=%.17g%s",
                index, n, c.first, c.last, m.J, m.F, m.coulomb, m.offset, m.saturation, m.delay, m.gain, c.x0, c.v0,
                c.start_stuck ? " stuck" : "");
  c.label = text;
  return c;
}

MeasuredDriveRun run_of(const RandomCase& c) {
  return simulate_measured_drive(c.model, c.t, c.drive, c.first, c.last, c.x0, c.v0, c.start_stuck);
}

// The tolerance, derived (not tuned).  dopri5 keeps each accepted step's local error within
// ε = 1e-12·(1 + |y| + h|y'|) per component; the dense output is as accurate.  The velocity
// equation contracts (∂v'/∂v = −F/J ≤ 0) and a stick resets its error, so after M steps and
// evaluations |Δv| ≤ M·ε; a zero found with velocity error Δv is off by Δt = Δv/|v'| (plus
// the bisection's resolution, an ulp of t); after a reversal the Coulomb torque 2Tc acts over
// Δt more or less, adding 2Tc·Δt/J to |Δv|; the position integrates the velocity over the
// run's length T: |Δx| ≤ M·ε + |Δv|·T.  The closed form's own rounding (a few ulps per piece)
// is far below.
struct Tolerance {
  double x = 0, v = 0;
  std::vector<double> t;  ///< per reference event
};

Tolerance derive_tolerance(const RandomCase& c, const MeasuredDriveRun& run, const ReferenceRun& ref) {
  const RigidDrive& m = c.model;
  const double X = max_abs(run.x), V = max_abs(run.v);
  double a_max = 0;
  for (std::size_t k = 0; k <= c.last; ++k) a_max = std::max(a_max, std::fabs(applied_torque(m, c.drive[k])));
  const double A = (a_max + m.coulomb + m.F * V) / m.J;
  const double h = 1e-3 + 1e-7;  // the longest piece
  const double step_error = odeint_tolerance * (1 + std::max(X + h * V, V + h * A));
  const double M = static_cast<double>(ref.steps);
  Tolerance tol;
  double dv = M * step_error;
  for (const auto& e : ref.events) {
    const double dt = (e.kind == DriveEventKind::Slip ? 0.0 : M * step_error / e.deceleration) + 2 * eps * std::fabs(e.t);
    tol.t.push_back(dt);
    if (e.kind == DriveEventKind::Reversal) dv += 2 * m.coulomb * dt / m.J;
  }
  tol.v = dv;
  tol.x = M * step_error + dv * (c.t[c.last] - c.t[c.first]);
  return tol;
}

TEST(MeasuredDriveCheck, AgreesWithAnIndependentOdeintReferenceOnRandomRecords) {
  std::mt19937_64 rng(20261123);
  const int runs = 150;
  double worst_x = 0, worst_v = 0, worst_t = 0, worst_x_ratio = 0, worst_t_ratio = 0;
  long events = 0, sticks = 0, slips = 0, reversals = 0;
  for (int i = 0; i < runs; ++i) {
    const RandomCase c = random_case(rng, i);
    const MeasuredDriveRun run = run_of(c);
    const ReferenceRun ref = reference_run(c.model, c.t, c.drive, c.first, c.last, c.x0, c.v0,
                                           c.start_stuck && c.model.coulomb > 0);
    ASSERT_EQ(run.x.size(), ref.x.size()) << c.label;
    const Tolerance tol = derive_tolerance(c, run, ref);
    for (std::size_t k = 0; k < run.x.size(); ++k) {
      const double dx = std::fabs(run.x[k] - ref.x[k]), dv = std::fabs(run.v[k] - ref.v[k]);
      worst_x = std::max(worst_x, dx);
      worst_v = std::max(worst_v, dv);
      worst_x_ratio = std::max(worst_x_ratio, dx / tol.x);
      ASSERT_LE(dx, tol.x) << c.label << "\n  x at t=" << c.t[c.first + k] << " returned " << run.x[k] << " instead of "
                           << ref.x[k] << " (odeint; tolerance " << tol.x << ")";
      ASSERT_LE(dv, tol.v) << c.label << "\n  v at t=" << c.t[c.first + k] << " returned " << run.v[k] << " instead of "
                           << ref.v[k] << " (odeint; tolerance " << tol.v << ")";
    }
    ASSERT_EQ(run.event_count, ref.events.size()) << c.label << "\n  returned " << run.event_count << " events instead of "
                                                  << ref.events.size();
    for (std::size_t e = 0; e < ref.events.size(); ++e) {
      const auto& mine = run.events[e];
      const auto& theirs = ref.events[e];
      ASSERT_EQ(mine.kind, theirs.kind) << c.label << "\n  event " << e << " returned " << to_string(mine.kind)
                                        << " instead of " << to_string(theirs.kind) << " at t=" << theirs.t;
      const double dt = std::fabs(mine.t - theirs.t);
      worst_t = std::max(worst_t, dt);
      worst_t_ratio = std::max(worst_t_ratio, dt / tol.t[e]);
      ASSERT_LE(dt, tol.t[e]) << c.label << "\n  event " << e << " (" << to_string(mine.kind) << ") at t=" << mine.t
                              << " instead of " << theirs.t << " (tolerance " << tol.t[e] << ")";
      ASSERT_LE(std::fabs(mine.x - theirs.x), tol.x) << c.label << "\n  event " << e << " at x=" << mine.x << " instead of "
                                                     << theirs.x;
      ++events;
      sticks += mine.kind == DriveEventKind::Stick;
      slips += mine.kind == DriveEventKind::Slip;
      reversals += mine.kind == DriveEventKind::Reversal;
    }
    EXPECT_EQ(run.stuck_at_end, ref.stuck_at_end) << c.label;
  }
  std::printf("%d random records, %ld events (%ld stick, %ld slip, %ld reversal): max |dx| = %.2e, max |dv| = %.2e, "
              "max |dt| = %.2e; largest fraction of the derived tolerance: x %.2e, t %.2e\n",
              runs, events, sticks, slips, reversals, worst_x, worst_v, worst_t, worst_x_ratio, worst_t_ratio);
  EXPECT_GT(sticks, 50) << "the random records should exercise sticking";
  EXPECT_GT(reversals, 20) << "the random records should exercise reversals";
}

// drive → −drive and T0 → −T0 (and x0, v0 → −x0, −v0) mirrors the motion: every formula is
// odd in (x, v, a) and IEEE rounding is symmetric, so the mirror is exact, bit for bit.
TEST(MeasuredDriveCheck, NegatingTheDriveAndTheOffsetMirrorsTheMotionExactly) {
  std::mt19937_64 rng(99);
  for (int i = 0; i < 100; ++i) {
    const RandomCase c = random_case(rng, i);
    RandomCase mirror = c;
    for (double& d : mirror.drive) d = -d;
    mirror.model.offset = -c.model.offset;
    mirror.x0 = -c.x0;
    mirror.v0 = -c.v0;
    const MeasuredDriveRun run = run_of(c), back = run_of(mirror);
    for (std::size_t k = 0; k < run.x.size(); ++k) {
      ASSERT_EQ(back.x[k], -run.x[k]) << c.label << "\n  mirrored x at sample " << k << " returned " << back.x[k]
                                      << " instead of " << -run.x[k];
      ASSERT_EQ(back.v[k], -run.v[k]) << c.label << "\n  mirrored v at sample " << k << " returned " << back.v[k]
                                      << " instead of " << -run.v[k];
    }
    ASSERT_EQ(back.events.size(), run.events.size()) << c.label;
    for (std::size_t e = 0; e < run.events.size(); ++e) {
      EXPECT_EQ(back.events[e].kind, run.events[e].kind) << c.label;
      EXPECT_EQ(back.events[e].t, run.events[e].t) << c.label;
      EXPECT_EQ(back.events[e].x, -run.events[e].x) << c.label;
    }
    EXPECT_EQ(back.stuck_at_end, run.stuck_at_end) << c.label;
  }
}

// A run split at an output sample and continued from the state there (x, v, stuck_at_end)
// is the run in one go, bit for bit: the growing-horizon fits of the discrepancy workflow
// may rely on it.
TEST(MeasuredDriveCheck, ARunContinuedFromItsStateAtASampleIsTheRunInOneGo) {
  std::mt19937_64 rng(4242);
  for (int i = 0; i < 100; ++i) {
    const RandomCase c = random_case(rng, i);
    const MeasuredDriveRun whole = run_of(c);
    const std::size_t mid = c.first + (c.last - c.first) / 3;
    const MeasuredDriveRun head =
        simulate_measured_drive(c.model, c.t, c.drive, c.first, mid, c.x0, c.v0, c.start_stuck);
    const MeasuredDriveRun tail = simulate_measured_drive(c.model, c.t, c.drive, mid, c.last, head.x.back(),
                                                          head.v.back(), head.stuck_at_end);
    for (std::size_t k = 0; k < tail.x.size(); ++k) {
      ASSERT_EQ(tail.x[k], whole.x[mid - c.first + k]) << c.label << "\n  continued x at sample " << mid + k
                                                       << " returned " << tail.x[k] << " instead of "
                                                       << whole.x[mid - c.first + k];
      ASSERT_EQ(tail.v[k], whole.v[mid - c.first + k]) << c.label;
    }
    std::vector<double> times;
    for (const auto& e : head.events) times.push_back(e.t);
    for (const auto& e : tail.events) times.push_back(e.t);
    std::vector<double> whole_times;
    for (const auto& e : whole.events) whole_times.push_back(e.t);
    EXPECT_EQ(times, whole_times) << c.label;
    EXPECT_EQ(tail.stuck_at_end, whole.stuck_at_end) << c.label;
  }
}

TEST(MeasuredDriveCheck, TheEventRecordIsCappedButEveryEventIsCounted) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 50; ++i) {
    const RandomCase c = random_case(rng, i);
    const MeasuredDriveRun all = run_of(c);
    const MeasuredDriveRun capped =
        simulate_measured_drive(c.model, c.t, c.drive, c.first, c.last, c.x0, c.v0, c.start_stuck, 2);
    EXPECT_EQ(capped.event_count, all.event_count) << c.label;
    EXPECT_EQ(capped.events.size(), std::min<std::size_t>(2, all.events.size())) << c.label;
    EXPECT_EQ(capped.x, all.x) << c.label;
  }
}

// ---------------------------------------------------------------- bad input

template <class Call>
void expect_refused(Call call, const std::string& naming) {
  try {
    call();
    ADD_FAILURE() << "returned normally instead of std::invalid_argument naming \"" << naming << "\"";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(naming), std::string::npos)
        << "returned \"" << error.what() << "\" instead of a message naming \"" << naming << "\"";
  }
}

TEST(MeasuredDriveInput, BadInputIsRefusedNamingTheProblem) {
  const std::vector<double> t = sample_times(10), drive(10, 1.0);
  const RigidDrive good;
  auto with = [&](auto change) {
    RigidDrive m = good;
    change(m);
    return [m, &t, &drive] { simulate_measured_drive(m, t, drive, 0, 9, 0, 0); };
  };
  expect_refused(with([](RigidDrive& m) { m.J = 0; }), "J = 0 must be > 0");
  expect_refused(with([](RigidDrive& m) { m.J = -2; }), "J = -2");
  expect_refused(with([](RigidDrive& m) { m.F = -1; }), "F = -1 must be >= 0");
  expect_refused(with([](RigidDrive& m) { m.coulomb = -0.5; }), "Coulomb torque Tc = -0.5");
  expect_refused(with([](RigidDrive& m) { m.saturation = 0; }), "saturation L = 0");
  expect_refused(with([](RigidDrive& m) { m.saturation = std::nan(""); }), "saturation L = nan");
  expect_refused(with([](RigidDrive& m) { m.delay = -1e-3; }), "delay tau = -0.001");
  expect_refused(with([](RigidDrive& m) { m.delay = infinity; }), "delay tau = inf is not finite");
  expect_refused(with([](RigidDrive& m) { m.offset = std::nan(""); }), "torque offset T0 = nan is not finite");
  expect_refused(with([](RigidDrive& m) { m.gain = infinity; }), "drive gain = inf");
  expect_refused(with([](RigidDrive& m) { m.F = infinity; }), "F = inf is not finite");

  expect_refused([&] { simulate_measured_drive(good, t, std::vector<double>(9, 1.0), 0, 8, 0, 0); },
                 "differ in length (10 and 9 samples)");
  expect_refused([&] { simulate_measured_drive(good, t, drive, 5, 3, 0, 0); }, "first = 5 > last = 3");
  expect_refused([&] { simulate_measured_drive(good, t, drive, 0, 10, 0, 0); }, "last = 10 is out of range (10 samples)");
  expect_refused([&] { simulate_measured_drive(good, t, drive, 0, 9, std::nan(""), 0); }, "x0 = nan");
  expect_refused([&] { simulate_measured_drive(good, t, drive, 0, 9, 0, infinity); }, "v0 = inf");
  expect_refused([&] { simulate_measured_drive(good, t, drive, 0, 9, 0, 0.5, true); }, "start_stuck with v0 = 0.5");
  std::vector<double> bad_t = t;
  bad_t[6] = bad_t[5];
  expect_refused([&] { simulate_measured_drive(good, bad_t, drive, 0, 9, 0, 0); },
                 "not strictly increasing at sample 6");
  bad_t = t;
  bad_t[3] = std::nan("");
  expect_refused([&] { simulate_measured_drive(good, bad_t, drive, 0, 9, 0, 0); }, "t[3] = nan is not finite");
  std::vector<double> bad_drive = drive;
  bad_drive[4] = infinity;
  expect_refused([&] { simulate_measured_drive(good, t, bad_drive, 0, 9, 0, 0); }, "drive[4] = inf is not finite");
  // a sample that is never used need not be valid: with τ = 0 a run from sample 5 starts with
  // sample 5; with τ = 2.5 ms sample 2 acts at t[5] and sample 1 is not used
  EXPECT_NO_THROW(simulate_measured_drive(good, t, bad_drive, 5, 9, 0, 0));
  bad_t = t;
  bad_t[1] = std::nan("");
  EXPECT_NO_THROW(simulate_measured_drive(good, bad_t, drive, 5, 9, 0, 0));
  RigidDrive delayed = good;
  delayed.delay = 2.5e-3;
  EXPECT_NO_THROW(simulate_measured_drive(delayed, bad_t, drive, 5, 9, 0, 0));
  bad_t[2] = std::nan("");
  expect_refused([&] { simulate_measured_drive(delayed, bad_t, drive, 5, 9, 0, 0); }, "t[2] = nan is not finite");
  bad_drive[2] = infinity;
  expect_refused([&] { simulate_measured_drive(delayed, t, bad_drive, 5, 9, 0, 0); }, "drive[2] = inf is not finite");
  bad_drive[9] = std::nan("");
  expect_refused([&] { simulate_measured_drive(good, t, bad_drive, 5, 9, 0, 0); }, "drive[9] = nan");
}

TEST(MeasuredDriveInput, EffectsThatNeedAGapOrAMeshAreRefused) {
  backlash::numeric::Parameters p;
  backlash::numeric::Effects e;
  p.backlash = 0.01;
  expect_refused([&] { backlash::discrepancy::rigid_drive_of(p, e, 1); }, "backlash = 0.01");
  p.backlash = 0;
  e.restitution = 0.4;
  expect_refused([&] { backlash::discrepancy::rigid_drive_of(p, e, 1); }, "restitution = 0.4 needs a gap");
  e.restitution = 0;
  e.mesh_stiffness = 1e4;
  expect_refused([&] { backlash::discrepancy::rigid_drive_of(p, e, 1); }, "compliance");
  e.mesh_stiffness = infinity;
  p.Jm = -3;
  expect_refused([&] { backlash::discrepancy::rigid_drive_of(p, e, 1); }, "J = -2 must be > 0");
}

}  // namespace
