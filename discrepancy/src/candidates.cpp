// The effects the workflow can name, as things a fit can vary (docs/discrepancy.md):
// each effect's parameters and the range searched, scaled to the model — torques
// to the initial drive K·|step|, times to the servo period, the backlash to its
// nominal value.
#include "internal.hpp"

#include <cmath>
#include <stdexcept>

namespace backlash::discrepancy::detail {

double ParameterRange::value(double u) const {
  u = std::min(1.0, std::max(0.0, u));
  return logarithmic ? low * std::pow(high / low, u) : low + (high - low) * u;
}

double ParameterRange::derivative(double u) const {
  return logarithmic ? value(u) * std::log(high / low) : high - low;
}

std::vector<std::vector<double>> EffectCandidate::scan() const {
  std::vector<std::vector<double>> points;
  if (ranges.size() == 1) {
    constexpr int n = 40;  // fine: with many bounces or events the cost has many shallow valleys
    for (int i = 0; i < n; ++i) points.push_back({i / double(n - 1)});
  } else {
    constexpr int n0 = 7, n1 = 5;
    for (int i = 0; i < n0; ++i)
      for (int j = 0; j < n1; ++j) points.push_back({i / double(n0 - 1), j / double(n1 - 1)});
  }
  return points;
}

const std::vector<std::string>& names() {
  static const std::vector<std::string> all{"coulomb_motor", "coulomb_load", "restitution", "saturation",
                                            "compliance",    "delay",        "backlash_size", "torque_offset"};
  return all;
}

EffectCandidate candidate_for(const std::string& effect, const ModelPoint& base, double step) {
  const numeric::Parameters& p = base.p;
  const double torque = p.K * std::fabs(step);  // the drive at the start of the step
  const double period = numeric::servo_period(p);
  const double reduced_inertia = p.Jm * p.JL / (p.Jm + p.JL);
  EffectCandidate c;
  c.effect = effect;
  using Values = std::vector<double>;
  if (effect == "coulomb_motor" || effect == "coulomb_load") {
    const bool motor = effect == "coulomb_motor";
    c.ranges = {{"torque", 1e-4 * torque, 0.3 * torque, true}};
    c.apply = [motor](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      (motor ? m.e.coulomb_motor : m.e.coulomb_load) = v[0];
      return m;
    };
  } else if (effect == "restitution") {
    c.ranges = {{"e", 0.02, 0.95, false}};
    c.apply = [](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.e.restitution = v[0];
      m.e.mesh_stiffness = INFINITY;  // the rigid impact law replaces a compliant mesh
      m.e.mesh_damping = 0;
      return m;
    };
  } else if (effect == "saturation") {
    c.ranges = {{"limit", 0.02 * torque, 1.0 * torque, true}};
    c.apply = [](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.e.saturation = v[0];
      return m;
    };
  } else if (effect == "compliance") {
    // stiffness, and the damping through its ratio ζ = cc/(2√(kc·m)), m the reduced inertia
    c.ranges = {{"stiffness", 1.0 * p.K, 1e5 * p.K, true}, {"damping", 0.02, 4.0, true}};
    c.apply = [reduced_inertia](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.e.mesh_stiffness = v[0];
      m.e.mesh_damping = 2 * v[1] * std::sqrt(v[0] * reduced_inertia);
      m.e.restitution = 0;
      return m;
    };
  } else if (effect == "delay") {
    c.ranges = {{"tau", 1e-3 * period, 0.1 * period, true}};
    c.apply = [](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.e.delay = v[0];
      return m;
    };
  } else if (effect == "backlash_size") {
    const double b0 = p.backlash;
    c.ranges = {b0 > 0 ? ParameterRange{"backlash", 0.05 * b0, 4.0 * b0, true}
                       : ParameterRange{"backlash", 1e-3 * std::fabs(step), 0.5 * std::fabs(step), true}};
    c.apply = [](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.p.backlash = v[0];
      return m;
    };
  } else if (effect == "torque_offset") {
    c.ranges = {{"torque", -0.2 * torque, 0.2 * torque, false}};
    c.apply = [](const ModelPoint& b, const Values& v) {
      ModelPoint m = b;
      m.e.torque_offset = v[0];
      return m;
    };
  } else {
    throw std::invalid_argument("unknown effect '" + effect + "'");
  }
  return c;
}

}  // namespace backlash::discrepancy::detail

namespace backlash::discrepancy {

const std::vector<std::string>& vocabulary() { return detail::names(); }

}  // namespace backlash::discrepancy
