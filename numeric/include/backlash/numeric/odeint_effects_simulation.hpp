// backlash/numeric/odeint_effects_simulation.hpp — the independent hybrid
// simulator with every effect (docs/effects.md), on Boost.Odeint.
//
// The cross-check of the closed-form effects simulator (effects_simulation.hpp)
// and the generator of test data for the discrepancy workflow, so that the
// workflow is never tested on the code path that fits.  It shares with the
// closed-form simulator only the data types and the semantics of
// docs/effects.md — never its dynamics, event location or mode logic.
//
// Every mode (rigid contact, free flight, mesh engaged; each body slipping or
// stuck; the drive linear or clipped) is integrated with runge_kutta_dopri5 and
// dense output from the mode's start, the step bounded so that no double
// crossing of a guard hides inside a step; guards are bracketed on the dense
// interpolant and refined with Boost.Math's toms748.  With a delay the
// fed-back angle θo(t − τ) is read from a history of dense-output segments
// (method of steps: the integrator stops exactly on the breakpoints
// t_event + kτ where the delayed signal's derivative jumps).
// Statuses as simulate(): completed, rest, chattering, event_limit, non_finite.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/odeint_simulation.hpp"

namespace backlash::numeric {

SimulationResult simulate_effects_with_odeint(const Parameters& p, const Effects& e, const HybridState& start,
                                              const SimulationOptions& options,
                                              const OdeintSimulationOptions& odeint_options = {});

/// effects_step_start(p, e, step) simulated with odeint.
SimulationResult simulate_effects_step_with_odeint(const Parameters& p, const Effects& e, double step,
                                                   const SimulationOptions& options,
                                                   const OdeintSimulationOptions& odeint_options = {});

}  // namespace backlash::numeric
