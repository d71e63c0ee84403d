// Issue 18, items 9 and 10, the effects engine's share: limit-cycle searches that ran for minutes
// (or for ever) answer within seconds, and their answers are those of the motion.
//   item 10  a very soft mesh (compliance stiffness 1e-6 and 1e-100, damping 0, case V): the
//            search looped at one instant (a ZoneExit handing over to itself) or bisected to its
//            resolution (a matrix-exponential flow whose balanced bound overflowed);
//   item 9   delayed loops: the search simulated max_cycles horizons in steps of at most τ,
//            whatever the crossings did; it now ends where they repeat or grow, and a stuck motor
//            with a coasting load comes to rest once nothing can happen any more.
// Each search runs in a child (fork) under a CPU-time limit, so that a hang is a failure, not a hang.
// The answers are checked against what an independent simulation (Boost.Odeint) shows.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace backlash;

constexpr double kStep = 0.62;   // case V's experiment
#ifdef BACKLASH_ITEMS_SANITIZED
constexpr rlim_t kSeconds = 120;  // as the boundaries test under the sanitizers
#else
constexpr rlim_t kSeconds = 20;  // CPU seconds per search: the boundaries test's limit per run
#endif

const numeric::ValidatedEvaluator& case_v() {
  static const numeric::ValidationResult v = numeric::validate(numeric::case_evaluator(model::load_case("V")));
  return v.evaluator();
}

/// What a child's limit-cycle search answered: "status|reason|period_count|peak_to_peak".
struct Answer {
  bool finished = false;
  std::string status, reason;
  int period_count = 0;
  double peak_to_peak = NAN;
};

Answer search_in_child(const numeric::Effects& effects) {
  int ends[2];
  if (::pipe(ends) != 0) return {};
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(ends[0]);
    // CPU time, not wall time: the answer's cost, whatever else runs on the machine (a wall
    // alarm of 10× guards against a child that sleeps).
    const rlimit cpu{kSeconds, kSeconds};
    ::setrlimit(RLIMIT_CPU, &cpu);
    ::alarm(10 * kSeconds);
    const numeric::EffectValidationResult model = numeric::validate_effects(case_v(), effects);
    numeric::EffectLimitCycleOptions o;
    o.step = kStep;
    const numeric::LimitCycle c = numeric::find_limit_cycle(model.model(), o);
    char text[1024];
    const int n = std::snprintf(text, sizeof text, "%s\n%d\n%.17g\n%s", numeric::to_string(c.status), c.period_count,
                                c.peak_to_peak, c.reason.c_str());
    (void)!::write(ends[1], text, static_cast<std::size_t>(std::min<int>(n, sizeof text - 1)));
    ::_exit(0);
  }
  ::close(ends[1]);
  std::string out;
  char buffer[1024];
  for (ssize_t n; (n = ::read(ends[0], buffer, sizeof buffer)) > 0;) out.append(buffer, static_cast<std::size_t>(n));
  ::close(ends[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  Answer a;
  a.finished = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!a.finished) return a;
  const std::size_t l1 = out.find('\n'), l2 = out.find('\n', l1 + 1), l3 = out.find('\n', l2 + 1);
  a.status = out.substr(0, l1);
  a.period_count = std::stoi(out.substr(l1 + 1, l2 - l1 - 1));
  a.peak_to_peak = std::stod(out.substr(l2 + 1, l3 - l2 - 1));
  a.reason = out.substr(l3 + 1);
  return a;
}

/// The independent simulator from the step: its events over [0, t_end].
numeric::SimulationResult odeint_run(const numeric::Effects& e, double t_end) {
  numeric::SimulationOptions o;
  o.t_end = t_end;
  o.max_events = 1'000'000;
  numeric::OdeintSimulationOptions odeint;
  odeint.tolerance = 1e-10;
  return numeric::simulate_effects_step_with_odeint(case_v().parameters(), e, kStep, o, odeint);
}

int recombinations_on_plus(const numeric::SimulationResult& r) {
  return static_cast<int>(std::count_if(r.events.begin(), r.events.end(), [](const numeric::SimulationEvent& e) {
    return e.kind == numeric::EventKind::Recombination && e.after.face == +1;
  }));
}

// ---------------------------------------------------------------- item 10

TEST(Item10_VerySoftMesh, LimitCycleAnswersAndTheMotionAgrees) {
  // Stiffness 1e-6: the mesh's own swing, 2π√(Jr/kc) ≈ 4.4e3 s, is far slower than the rigid
  // model's time scales; the search awaits a return for 60 of the slowest scales, the mesh's
  // included.  The soft coupling inside the loop grows (a double integrator closed through the
  // soft spring): the answer is `divergent`, and the independent run shows the growth.
  numeric::Effects soft;
  soft.mesh_stiffness = 1e-6;
  const Answer a = search_in_child(soft);
  ASSERT_TRUE(a.finished) << "stiffness 1e-6: no answer within " << kSeconds << " s";
  EXPECT_EQ(a.status, "divergent") << a.reason;
  double early = 0, late = 0;  // the largest |θ̇o| at a separation before and after 50,000 s
  for (const numeric::SimulationEvent& ev : odeint_run(soft, 1e5).events)
    if (ev.kind == numeric::EventKind::Separation) (ev.t < 5e4 ? early : late) = std::max(ev.t < 5e4 ? early : late, std::fabs(ev.dtheta_o));
  EXPECT_GT(late, 10 * early) << "the independent run does not grow: separation speeds " << early << " then " << late;
  // Stiffness 1e-100: one swing of the mesh, ~3e50 s, is beyond what double precision times:
  // never `none` (a claim that the motion settles), but unresolved with the reason.
  numeric::Effects softest;
  softest.mesh_stiffness = 1e-100;
  const Answer b = search_in_child(softest);
  ASSERT_TRUE(b.finished) << "stiffness 1e-100: no answer within " << kSeconds << " s";
  EXPECT_EQ(b.status, "unresolved") << b.reason;
  EXPECT_NE(b.reason.find("beyond what double precision times"), std::string::npos) << b.reason;
}

// ---------------------------------------------------------------- item 9

numeric::Effects delayed(double delay, double stiffness = 0, double damping = 0, double coulomb_motor = 0) {
  numeric::Effects e;
  e.delay = delay;
  if (stiffness > 0) e.mesh_stiffness = stiffness, e.mesh_damping = damping;
  e.coulomb_motor = coulomb_motor;
  return e;
}

// The boundaries test's cases (check_effects_boundaries.cpp: the delay at 1e-3 and 0.1 of the
// servo period 2π, the mesh damping at its middle ζ for the middle stiffness √1e5).
const double servo = 2 * std::numbers::pi, damping = std::sqrt(0.02 * 4.0) * 2 * std::sqrt(std::sqrt(1e5) * 0.25);

TEST(Item09_DelayedLimitCycle, SoftMeshWithAShortDelayFindsItsCycle) {
  const numeric::Effects e = delayed(1e-3 * servo, 1, damping);
  const Answer a = search_in_child(e);
  ASSERT_TRUE(a.finished) << "no answer within " << kSeconds << " s";
  ASSERT_EQ(a.status, "limit_cycle") << a.reason;
  // The long run settles onto the same swing: its last 60 s span the cycle's peak-to-peak.
  const numeric::SimulationResult r = odeint_run(e, 600);
  double low = INFINITY, high = -INFINITY;
  for (const numeric::SimulationEvent& ev : r.events)
    if (ev.t > 540) low = std::min(low, ev.theta_o), high = std::max(high, ev.theta_o);
  ASSERT_TRUE(high > low) << "the independent run has no events in its last 60 s";
  // Events sample θo at impacts and separations, not at its extremes: they lie inside the swing.
  EXPECT_LE(high - low, a.peak_to_peak * (1 + 1e-6)) << a.peak_to_peak;
  EXPECT_GT(recombinations_on_plus(r), 10);
}

TEST(Item09_DelayedLimitCycle, StiffMeshWithALongDelayDiverges) {
  const numeric::Effects e = delayed(0.1 * servo, 1e5, damping);
  const Answer a = search_in_child(e);
  ASSERT_TRUE(a.finished) << "no answer within " << kSeconds << " s";
  EXPECT_EQ(a.status, "divergent") << a.reason;
}

TEST(Item09_DelayedLimitCycle, StuckMotorWithACoastingLoadComesToRest) {
  const numeric::Effects e = delayed(1e-3 * servo, 0, 0, 0.3 * kStep);
  const Answer a = search_in_child(e);
  ASSERT_TRUE(a.finished) << "no answer within " << kSeconds << " s";
  EXPECT_EQ(a.status, "none") << a.reason;
  EXPECT_NE(a.reason.find("every seed comes to rest"), std::string::npos) << a.reason;
  // The independent run from the step: no event after the motor sticks, over a long time.
  const numeric::SimulationResult r = odeint_run(e, 600);
  ASSERT_FALSE(r.events.empty());
  EXPECT_LT(r.events.back().t, 60) << "an event at " << r.events.back().t;
}

}  // namespace
