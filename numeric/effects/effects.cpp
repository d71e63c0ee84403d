#include "backlash/numeric/effects.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace backlash::numeric {

std::string Effects::describe() const {
  std::ostringstream out;
  out.precision(12);
  const char* separator = "";
  auto item = [&](const char* name, double value) {
    out << separator << name << "=" << value;
    separator = ", ";
  };
  if (coulomb_motor > 0) item("coulomb_motor", coulomb_motor);
  if (coulomb_load > 0) item("coulomb_load", coulomb_load);
  if (restitution != 0) item("restitution", restitution);
  if (saturating()) item("saturation", saturation);
  if (compliant()) {
    item("stiffness", mesh_stiffness);
    item("damping", mesh_damping);
  }
  if (delayed()) item("delay", delay);
  if (torque_offset != 0) item("torque_offset", torque_offset);
  const std::string text = out.str();
  return text.empty() ? "none" : text;
}

Effects effects_of(const model::CaseSpec& spec) {
  const model::Effects& m = spec.effects;
  Effects e;
  e.coulomb_motor = model::to_double(m.coulomb_motor);
  e.coulomb_load = model::to_double(m.coulomb_load);
  e.restitution = model::to_double(m.restitution);
  if (m.saturation) e.saturation = model::to_double(*m.saturation);
  if (m.compliance) {
    e.mesh_stiffness = model::to_double(m.compliance->stiffness);
    e.mesh_damping = model::to_double(m.compliance->damping);
  }
  e.delay = model::to_double(m.delay);
  e.torque_offset = model::to_double(m.torque_offset);
  return e;
}

int drive_regime(const Parameters& p, const Effects& e, double theta_o_fed_back) {
  if (!e.saturating()) return 0;
  const double demand = p.K * (p.theta_R - theta_o_fed_back);
  return demand > e.saturation ? +1 : demand < -e.saturation ? -1 : 0;
}

double drive_torque_in_regime(const Parameters& p, const Effects& e, double theta_o_fed_back, int regime) {
  const double clipped = regime == 0 ? p.K * (p.theta_R - theta_o_fed_back) : regime * e.saturation;
  return clipped + e.torque_offset;
}

double drive_torque(const Parameters& p, const Effects& e, double theta_o_fed_back) {
  return drive_torque_in_regime(p, e, theta_o_fed_back, drive_regime(p, e, theta_o_fed_back));
}

double servo_period(const Parameters& p) { return 2 * M_PI * std::sqrt((p.Jm + p.JL) / p.K); }

double slowest_bounce(const Parameters& p) { return 1e-9 * std::sqrt(p.K / (p.Jm + p.JL)) * std::max(1.0, p.backlash); }

HybridState effects_step_start(const Parameters& p, const Effects& e, double step) {
  HybridState s = state_on_face(p, step >= 0 ? -1 : +1, p.theta_R - step, 0, true);
  s.drive_regime = drive_regime(p, e, p.theta_R - step);
  return s;
}

ImpactVelocities impact_velocities(const Parameters& p, double restitution, double dtheta_m, double dtheta_L) {
  const double J = p.Jm + p.JL;
  const double common = (p.Jm * dtheta_m + p.JL * dtheta_L) / J;
  const double relative_after = -restitution * (dtheta_L - dtheta_m);
  return {common - p.JL / J * relative_after, common + p.Jm / J * relative_after};
}

}  // namespace backlash::numeric
