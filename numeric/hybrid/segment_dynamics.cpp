#include "backlash/numeric/segment_dynamics.hpp"

#include <algorithm>
#include <cmath>

namespace backlash::numeric {

LinearSegment free_mode_segment(const Parameters& p) {
  LinearSegment s{SmallMatrix::Zero(4, 4), SmallVector::Zero(4)};
  s.A(0, 1) = 1;
  s.A(1, 1) = -p.Fm / p.Jm;
  if (p.measured_at == model::MeasuredAt::Motor) s.A(1, 0) = -p.K / p.Jm; else s.A(1, 2) = -p.K / p.Jm;
  s.c(1) = p.K * p.theta_R / p.Jm;
  s.A(2, 3) = 1;
  s.A(3, 3) = -p.FL / p.JL;
  return s;
}

LinearSegment contact_mode_segment(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  LinearSegment s{SmallMatrix::Zero(2, 2), SmallVector::Zero(2)};
  s.A(0, 1) = 1;
  s.A(1, 0) = -p.K / J;
  s.A(1, 1) = -F / J;
  s.c(1) = p.K * p.theta_R / J;
  return s;
}

TransmittedTorque transmitted_torque(const Parameters& p) {
  // Tc = JL (K(θR − θ) − F θ̇)/J + FL θ̇
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  TransmittedTorque t{SmallRow(2), p.JL * p.K * p.theta_R / J};
  t.r(0) = -p.JL * p.K / J;
  t.r(1) = -p.JL * F / J + p.FL;
  return t;
}

double contact_acceleration(const Parameters& p, double theta_o, double dtheta_o) {
  return (p.K * (p.theta_R - theta_o) - (p.Fm + p.FL) * dtheta_o) / (p.Jm + p.JL);
}

double transmitted_torque_at(const Parameters& p, double theta_o, double dtheta_o) {
  return p.JL * contact_acceleration(p, theta_o, dtheta_o) + p.FL * dtheta_o;
}

double recombined_velocity(const Parameters& p, double dtheta_m, double dtheta_L) {
  return (p.Jm * dtheta_m + p.JL * dtheta_L) / (p.Jm + p.JL);
}

double servo_time_unit(const Parameters& p) { return std::sqrt((p.Jm + p.JL) / p.K); }

double slowest_time_scale(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  double scale = 0;
  auto consider_rate = [&](double rate) { if (rate > 0) scale = std::max(scale, 1 / rate); };
  consider_rate(F / (2 * J));
  consider_rate(p.Fm / (2 * p.Jm));
  consider_rate(p.Fm / p.Jm);
  consider_rate(p.FL / p.JL);
  scale = std::max(scale, 2 * M_PI / std::sqrt(p.K / J));
  scale = std::max(scale, 2 * M_PI / std::sqrt(p.K / p.Jm));
  return scale;
}

}  // namespace backlash::numeric
