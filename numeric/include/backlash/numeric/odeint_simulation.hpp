// backlash/numeric/odeint_simulation.hpp — an independent hybrid simulator on
// Boost.Odeint: the cross-check of the closed-form one (hybrid_simulation.hpp).
//
// Same automaton, same event semantics, same result structure as simulate():
//   contact on face σ    eq. 25 integrated in the deviation (θo − θR, θ̇o), so Tc keeps its
//                        relative accuracy near equilibrium; holds while −σ·Tc ≥ 0
//   separation           the first zero of the witness −σ·Tc, except where the motion has
//                        decayed to rounding level (the rule of hybrid_simulation.cpp:
//                        |θo − θR| ≤ ν, |θ̇o| ≤ ν√(K/J), ν = 1024 ε max(1, |θR|)): contact holds
//   free                 eqs. 16/39 and 17, integrated in start-relative coordinates
//                        (θm − θm0, θ̇m, S·Δ, S·Δ̇), Δ the gap change since the start, so the
//                        gap is resolved far below the positions' rounding (1e-13 excursions)
//   recombination        the first zero of σ·x + b/2  (x = θL − θm reaches −σ b/2)
//   recontact            the first zero of σ·x − b/2  (x returns to σ b/2), armed once the
//                        gap is strictly inside; the first step is kept below 3|Δ''/Δ'''|/6
//                        when the gap leaves inward but curves back, so a quick return is seen
//   impact (eq. 24)      inelastic; a bounce when the torque does not hold on the face hit
//   rest                 as simulate(): no further event before t_end and every velocity
//                        below rest_velocity at t_end; the rest event is the last time a
//                        velocity was ≥ rest_velocity
// Every segment is integrated from its own initial state with
// runge_kutta_dopri5 + dense output (abs = rel = `tolerance`), the step bounded
// by `max_step_fraction` / (fastest rate of the modes) so that no double
// crossing of a witness hides inside a step; each step's dense interpolant is
// checked at points at most max_step/(interior_checks + 1) apart (a full-length
// step: `interior_checks` interior points plus its end; the shorter steps that the
// tolerance usually imposes: fewer), and the first sign change is refined with
// Boost.Math's toms748 on the interpolant.
// Nothing here calls the closed-form evaluators or first_crossing: the
// two simulators share only the data types and the problem statement.
// Statuses as simulate(): completed, rest, chattering (zeno_impacts impacts
// within zeno_window), event_limit, non_finite (also when odeint gives up);
// stop_after_separations, sample_interval and track_extremes (event states and
// the velocity zeros, located on the interpolant) as well.
#pragma once

#include "backlash/numeric/hybrid_simulation.hpp"

namespace backlash::numeric {

struct OdeintSimulationOptions {
  double tolerance = 1e-12;        ///< dopri5 absolute = relative error tolerance
  double max_step_fraction = 0.1;  ///< max step = this / fastest rate of the modes
  int interior_checks = 8;         ///< witness samples inside a step of max length (plus its end)
  double gap_scale = 1e8;          ///< S: the gap change is integrated as S·Δ (abs. error tolerance/S on Δ)
};

/// The fastest rate (1/s) among the contact and free modes' poles (bounds the step).
double fastest_rate(const Parameters& p);

SimulationResult simulate_with_odeint(const Parameters& p, const HybridState& start, const SimulationOptions& options,
                                      const OdeintSimulationOptions& odeint_options = {});

/// step_start(p, step) simulated with odeint.
SimulationResult simulate_step_with_odeint(const Parameters& p, double step, const SimulationOptions& options,
                                           const OdeintSimulationOptions& odeint_options = {});

}  // namespace backlash::numeric
