// backlash/numeric/reference.hpp — Boost.Odeint integration of the segment
// ODEs, the reference every evaluator is validated against.
//
//   free mode     θL'' = −(FL/JL)·θL'
//                 θm'' = (K(θR − θL) − Fm·θm')/Jm     (output at load, eq. 39)
//                 θm'' = (K(θR − θm) − Fm·θm')/Jm     (output at motor, eq. 16)
//                 from θm = θL = θR + cot φ·θ̇m0, θm' = θL' = θ̇m0
//   contact mode  θo'' = (K(θR − θo) − (Fm+FL)·θo')/(Jm+JL)  from (θo0, θ̇o0)
//
// runge_kutta_dopri5 with dense output, abs = rel tolerance (default 1e-12),
// sampled with integrate_times.  All odeint code lives in odeint_reference.cpp.
#pragma once

#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <functional>
#include <vector>

namespace backlash::numeric {

/// States at `times` (non-decreasing, ≥ 0; t = 0 is the separation point).
std::vector<FreeState> reference_free_trajectory(const Parameters& p, double dtheta_m0, const std::vector<double>& times,
                                                 double tolerance = 1e-12);
/// The same, ending at the first state for which `until` holds (that state included): the states
/// before it are the same bits as the whole run's (the gate stops at recombination, validation.cpp).
std::vector<FreeState> reference_free_trajectory(const Parameters& p, double dtheta_m0, const std::vector<double>& times,
                                                 double tolerance, const std::function<bool(const FreeState&)>& until);
std::vector<ContactState> reference_contact_trajectory(const Parameters& p, double theta_o0, double dtheta_o0,
                                                       const std::vector<double>& times, double tolerance = 1e-12);

/// One state at time t (integrates from 0 to t).
FreeState reference_free_state(const Parameters& p, double dtheta_m0, double t, double tolerance = 1e-12);
ContactState reference_contact_state(const Parameters& p, double theta_o0, double dtheta_o0, double t,
                                     double tolerance = 1e-12);

/// Any linear mode z' = A z + c (the effect modes of numeric/effects/effect_modes.hpp) from z0, at `times`.
std::vector<SmallVector> reference_linear_trajectory(const LinearSegment& segment, const SmallVector& z0,
                                                     const std::vector<double>& times, double tolerance = 1e-12);

}  // namespace backlash::numeric
