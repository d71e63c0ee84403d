// Soak: random valid parameter sets through simulate, limit cycle and trace.
// Both measurements; every pole structure (contact under-, critically and over-damped, free
// modes with and without friction on either body) and sets within 1e-12 (relative) of each
// branch boundary (critical damping of the contact and of the free motor, FL = 0, Fm = 0,
// cot φ = 0); random backlash, reference and step.  From a fixed seed: the same sets every run.
// Each set must
//   – pass the validation gate (its branches validated through a ValidatedParametricFamily,
//     as sweeps do) or be refused up front by the scale checks, with a reason;
//   – simulate with a status (no exception, no NaN), the closed-form and the odeint
//     simulators agreeing on the status, on every event (kind, time within 1e-7) and on the
//     final state (1e-6) — unless an event grazes the face, where the event sequence is not
//     decided by finite precision (counted and printed);
//   – give a limit-cycle verdict with a status and, for a cycle, finite numbers; a reason
//     otherwise;
//   – trace three separation velocities with a status each.
// Work is bounded by the simulators' own budgets (event cap, interval budget): a set that
// hits one comes back with that status, which the test accepts and counts.  Counts: 10000 sets
// (1000 under BACKLASH_SANITIZE, where every call is ~10× slower), printed at the end.
#include "backlash/numeric/dividing_lines.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/odeint_simulation.hpp"
#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/validated_family.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>

namespace {

using namespace backlash;
using numeric::Parameters;

#ifdef BACKLASH_SOAK_SANITIZED
constexpr int soak_sets = 1000;
#else
constexpr int soak_sets = 10000;
#endif

struct Generator {
  std::mt19937_64 random{10'000};
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(random); }
  double log_uniform(double a, double b) { return std::exp(uniform(std::log(a), std::log(b))); }
  double near(double x) { return x * (1 + uniform(-1e-12, 1e-12)); }  // within 1e-12 of a boundary

  Parameters next(std::string& kind) {
    Parameters p;
    p.measured_at = random() % 2 ? model::MeasuredAt::Load : model::MeasuredAt::Motor;
    p.Jm = log_uniform(0.1, 3);
    p.JL = log_uniform(0.1, 3);
    p.K = log_uniform(0.2, 5);
    p.backlash = log_uniform(0.02, 1);
    p.theta_R = uniform(-5, 5);
    const double J = p.Jm + p.JL;
    switch (random() % 8) {
      case 0: kind = "random friction"; p.Fm = uniform(0, 1); p.FL = uniform(0, 1); break;
      case 1: kind = "no load friction"; p.Fm = uniform(0, 1); p.FL = 0; break;
      case 2: kind = "no motor friction"; p.Fm = 0; p.FL = uniform(0.01, 1); break;
      case 3: kind = "near FL = 0"; p.Fm = uniform(0, 1); p.FL = uniform(0, 1e-12); break;
      case 4: {  // contact critically damped: F² = 4 J K
        kind = "near critical contact";
        const double F = near(2 * std::sqrt(J * p.K)), share = uniform(0, 1);
        p.Fm = share * F, p.FL = (1 - share) * F;
        break;
      }
      case 5: kind = "over-damped contact"; p.Fm = uniform(1, 4) * std::sqrt(J * p.K); p.FL = uniform(1, 3) * std::sqrt(J * p.K); break;
      case 6: {  // cot φ = 0: Jm FL = Fm JL
        kind = "near cot phi = 0";
        p.Fm = uniform(0.01, 1);
        p.FL = near(p.Fm * p.JL / p.Jm);
        break;
      }
      default: {  // free motor critically damped (measured at the motor): Fm² = 4 Jm K
        kind = "near critical free motor";
        p.Fm = near(2 * std::sqrt(p.Jm * p.K));
        p.FL = uniform(0, 0.5);
        break;
      }
    }
    return p;
  }
};

bool finite(const numeric::HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}

TEST(Soak, RandomValidParameterSetsFinishWithAStatusAndTheSimulatorsAgree) {
  Generator g;
  numeric::ValidatedParametricFamily family;
  std::map<std::string, long> statuses, cycles, kinds;
  long refused = 0, unvalidated = 0, compared = 0, grazing = 0, events = 0, traced = 0;
  for (int i = 0; i < soak_sets; ++i) {
    std::string kind;
    const Parameters p = g.next(kind);
    ++kinds[kind];
    const double step = (g.random() % 2 ? 1 : -1) * g.log_uniform(0.05, 3) * std::max(1.0, p.backlash);
    char label[320];
    std::snprintf(label, sizeof label, "set %d (%s): Jm %.17g Fm %.17g JL %.17g FL %.17g K %.17g b %.17g R %.17g at %s, step %.17g",
                  i, kind.c_str(), p.Jm, p.Fm, p.JL, p.FL, p.K, p.backlash, p.theta_R,
                  p.measured_at == model::MeasuredAt::Load ? "load" : "motor", step);
    if (const auto problem = numeric::parameter_scale_problem(p)) {
      ++refused;
      EXPECT_FALSE(problem->empty()) << label;
      continue;
    }
    const std::optional<numeric::ValidatedEvaluator> evaluator = family.at(p);
    if (!evaluator) {
      ++unvalidated;
      continue;
    }

    // Simulate: both simulators, the same story.
    numeric::SimulationOptions o;
    o.t_end = 20;
    o.max_events = 400;
    const numeric::SimulationResult closed = numeric::simulate_step(*evaluator, step, o);
    const numeric::SimulationResult odeint = numeric::simulate_step_with_odeint(p, step, o);
    ++statuses[numeric::to_string(closed.status)];
    ASSERT_TRUE(finite(closed.final_state)) << label << ": returned a non-finite final state";
    if (numeric::stopped_early(closed.status)) {
      EXPECT_FALSE(closed.stop_reason.empty()) << label;
    }
    bool grazed = false;
    for (const auto* r : {&closed, &odeint})
      for (const numeric::SimulationEvent& e : r->events) grazed = grazed || e.grazing;
    const bool same_story = closed.status == odeint.status && closed.events.size() == odeint.events.size();
    if (!same_story && grazed) {
      ++grazing;
    } else {
      ++compared;
      EXPECT_EQ(numeric::to_string(closed.status), std::string(numeric::to_string(odeint.status)))
          << label << ": odeint returned " << numeric::to_string(odeint.status) << " instead of " << numeric::to_string(closed.status);
      ASSERT_EQ(closed.events.size(), odeint.events.size())
          << label << ": odeint returned " << odeint.events.size() << " events instead of " << closed.events.size();
      for (std::size_t k = 0; k < closed.events.size(); ++k) {
        const numeric::SimulationEvent &c = closed.events[k], &d = odeint.events[k];
        ASSERT_EQ(c.kind, d.kind) << label << ": event " << k << ": odeint returned " << numeric::to_string(d.kind)
                                  << " instead of " << numeric::to_string(c.kind);
        if (c.kind == numeric::EventKind::Rest) continue;  // the rest time is ill-conditioned (check_simulators_agree)
        EXPECT_NEAR(c.t, d.t, 1e-7 * std::max(1.0, c.t)) << label << ": event " << k;
      }
      events += static_cast<long>(closed.events.size());
      const double scale = std::max(1.0, std::fabs(p.theta_R));
      EXPECT_NEAR(closed.final_state.theta_m, odeint.final_state.theta_m, 1e-6 * scale) << label;
      EXPECT_NEAR(closed.final_state.theta_L, odeint.final_state.theta_L, 1e-6 * scale) << label;
    }

    // Limit cycle: a status, finite numbers for a cycle, a reason otherwise.
    const numeric::LimitCycle cycle = numeric::find_limit_cycle(*evaluator);
    ++cycles[numeric::to_string(cycle.status)];
    if (cycle.status == numeric::CycleStatus::LimitCycle) {
      EXPECT_TRUE(std::isfinite(cycle.peak_to_peak) && std::isfinite(cycle.period) && cycle.period > 0)
          << label << ": limit cycle with peak-to-peak " << cycle.peak_to_peak << ", period " << cycle.period;
    } else {
      EXPECT_FALSE(cycle.reason.empty()) << label << ": " << cycle.status << " without a reason";
    }

    // Trace: a status for each velocity, finite states where it recombines.
    for (double v0 : {0.05, 1.0, 20.0}) {
      const numeric::DividingLinePoint d = numeric::dividing_line_point(*evaluator, v0);
      ++traced;
      if (d.status != numeric::RecombinationStatus::NoRecombination) {
        EXPECT_TRUE(std::isfinite(d.t) && d.t > 0 && std::isfinite(d.theta_o) && std::isfinite(d.dtheta_o))
            << label << ": v0 = " << v0 << " returned t = " << d.t;
      }
    }
    if (HasFatalFailure()) return;
  }
  std::printf("soak: %d sets (refused by the scale checks %ld, refused by the gate %ld); simulations compared %ld "
              "(%ld events), grazing sequences not compared %ld; %ld traced points\n",
              soak_sets, refused, unvalidated, compared, events, grazing, traced);
  std::printf("  kinds:");
  for (const auto& [k, n] : kinds) std::printf(" %s %ld;", k.c_str(), n);
  std::printf("\n  simulation statuses:");
  for (const auto& [s, n] : statuses) std::printf(" %s %ld;", s.c_str(), n);
  std::printf("\n  limit cycles:");
  for (const auto& [s, n] : cycles) std::printf(" %s %ld;", s.c_str(), n);
  std::printf("\n");
  EXPECT_LE(grazing, soak_sets / 20) << "returned " << grazing << " grazing disagreements instead of at most " << soak_sets / 20;
}

}  // namespace
