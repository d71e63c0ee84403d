#include "backlash/numeric/effects.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace backlash::numeric {

bool Effects::has(const model::EffectInfo& effect) const {
  return !effect.primary().is_neutral(model::field(*this, effect.primary().id));
}

bool Effects::any() const {
  for (const model::EffectInfo& effect : model::effects_table)
    if (has(effect)) return true;
  return false;
}

std::string Effects::describe() const {
  std::ostringstream out;
  out.precision(12);
  const char* separator = "";
  for (const model::EffectInfo& effect : model::effects_table) {
    if (!has(effect)) continue;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i) {
      const model::EffectParameterInfo& parameter = model::effect_parameters[i];
      out << separator << parameter.name << "=" << model::field(*this, parameter.id);
      separator = ", ";
    }
  }
  const std::string text = out.str();
  return text.empty() ? "none" : text;
}

Effects effects_of(const model::CaseSpec& spec) {
  Effects e;
  for (const model::EffectParameterInfo& parameter : model::effect_parameters)
    if (const std::optional<model::Rational>& value = model::field(spec.effects, parameter.id))
      model::field(e, parameter.id) = model::to_double(*value);
  return e;
}

double static_friction(const Effects& e, bool motor) {
  return motor ? e.coulomb_motor + e.stribeck_motor_static : e.coulomb_load + e.stribeck_load_static;
}

namespace {
// The Stribeck curve's drop Ts − Tk and velocity vs of a body.
std::pair<double, double> stribeck_curve(const Effects& e, bool motor) {
  return motor ? std::pair{e.stribeck_motor_static - e.stribeck_motor_kinetic, e.stribeck_motor_velocity}
               : std::pair{e.stribeck_load_static - e.stribeck_load_kinetic, e.stribeck_load_velocity};
}
}  // namespace

double stribeck_drop(const Effects& e, bool motor, double v) {
  const auto [drop, vs] = stribeck_curve(e, motor);
  if (!(drop > 0)) return 0;
  const double x = v / vs;
  return -drop * std::expm1(-x * x);  // (Ts − Tk)(1 − e^{−x²}), accurate for small x
}

double stribeck_drop_rate(const Effects& e, bool motor, double v) {
  const auto [drop, vs] = stribeck_curve(e, motor);
  if (!(drop > 0)) return 0;
  const double x = v / vs;
  return drop * 2 * x / vs * std::exp(-x * x);
}

double drive_constant(const Effects& e, int regime) {
  return regime == 0 ? e.torque_offset : regime * e.saturation + e.torque_offset;
}

double drive_constant_bound(const Effects& e) {
  return e.saturating() ? e.saturation + std::fabs(e.torque_offset) : std::fabs(e.torque_offset);
}

int drive_regime(const Parameters& p, const Effects& e, double theta_o_fed_back) {
  if (!e.saturating()) return 0;
  const double demand = p.K * (p.theta_R - theta_o_fed_back);
  return demand > e.saturation ? +1 : demand < -e.saturation ? -1 : 0;
}

double drive_torque_in_regime(const Parameters& p, const Effects& e, double theta_o_fed_back, int regime) {
  return regime == 0 ? p.K * (p.theta_R - theta_o_fed_back) + drive_constant(e, 0) : drive_constant(e, regime);
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
