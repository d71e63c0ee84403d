// backlash/numeric/segment_dynamics.hpp — each mode as a linear ODE x' = A x + c
// (the witness functions' bounds need A and c; the states themselves always
// come from the validated closed forms).
//
//   free mode, x = (θm, θ̇m, θL, θ̇L):
//     θ̈m = (K(θR − θo) − Fm θ̇m)/Jm,  θo = θm (output at motor, eq. 16) or θL (at load, eq. 39)
//     θ̈L = −FL θ̇L / JL                                                   (eq. 17)
//   contact mode, y = (θo, θ̇o):  θ̈o = (K(θR − θo) − F θ̇o)/J, J = Jm + JL, F = Fm + FL  (eq. 25)
//
// Transmitted torque in contact (docs/physics.md): Tc = JL·θ̈o + FL·θ̇o.  Contact
// on the face x = −b/2 holds while Tc ≥ 0, on x = +b/2 while Tc ≤ 0.
#pragma once

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/parametric.hpp"

#include <Eigen/Dense>

namespace backlash::numeric {

struct LinearSegment {
  SmallMatrix A;
  SmallVector c;
};

LinearSegment free_mode_segment(const Parameters& p);
LinearSegment contact_mode_segment(const Parameters& p);

/// Tc as a row vector on (θo, θ̇o) plus constant: Tc = r·y + r0.
struct TransmittedTorque {
  SmallRow r;
  double r0;
};
TransmittedTorque transmitted_torque(const Parameters& p);

/// Contact acceleration and transmitted torque at a contact state.
double contact_acceleration(const Parameters& p, double theta_o, double dtheta_o);
double transmitted_torque_at(const Parameters& p, double theta_o, double dtheta_o);

/// Eq. 24: (Jm + JL) θ̇o = Jm θ̇m + JL θ̇L.
double recombined_velocity(const Parameters& p, double dtheta_m, double dtheta_L);

/// A time scale for horizons: the slowest time constant (or period) of the segments.
double slowest_time_scale(const Parameters& p);

/// The servo's time unit √(J/K), J = Jm + JL: 1 s for the thesis's cases (J = K = 1).  Rounding
/// tolerances on times, and velocities compared with angles, are taken in it.
double servo_time_unit(const Parameters& p);

}  // namespace backlash::numeric
