#include "backlash/symbolic/case_derivation.hpp"

#include "backlash/symbolic/inverse_laplace.hpp"

#include <optional>

namespace backlash::symbolic {

using namespace GiNaC;

const DerivationSymbols& derivation_symbols() {
  static const DerivationSymbols symbols{
      symbol("s"),
      possymbol("t"),
      realsymbol("dtheta_m0", "\\dot{\\theta}_{m0}"),
      realsymbol("theta_o0", "\\theta_{o0}"),
      realsymbol("dtheta_o0", "\\dot{\\theta}_{o0}"),
      realsymbol("theta_o", "\\theta_{o}"),
      realsymbol("dtheta_o", "\\dot{\\theta}_{o}"),
  };
  return symbols;
}

CaseParameters exact_parameters(const model::CaseSpec& spec) {
  CaseParameters p;
  p.Jm = to_numeric(spec.Jm);
  p.Fm = to_numeric(spec.Fm);
  p.JL = to_numeric(spec.JL);
  p.FL = to_numeric(spec.FL);
  p.K = to_numeric(spec.K);
  p.theta_R = to_numeric(spec.reference);
  p.backlash = to_numeric(spec.backlash);
  p.measured_at = spec.measured_at;
  return p;
}

const char* to_string(ContactBranch branch) {
  switch (branch) {
    case ContactBranch::Underdamped: return "underdamped";
    case ContactBranch::CriticallyDamped: return "critically_damped";
    case ContactBranch::Overdamped: return "overdamped";
  }
  return "?";
}

const char* to_string(FreeBranch branch) {
  switch (branch) {
    case FreeBranch::LoadGeneric: return "load_generic";
    case FreeBranch::LoadNoLoadFriction: return "load_FL0";
    case FreeBranch::LoadNoMotorFriction: return "load_Fm0";
    case FreeBranch::LoadNoFriction: return "load_Fm0_FL0";
    case FreeBranch::LoadEqualRates: return "load_equal_rates";
    case FreeBranch::MotorUnderdamped: return "motor_underdamped";
    case FreeBranch::MotorUnderdampedNoLoadFriction: return "motor_underdamped_FL0";
    case FreeBranch::MotorCritical: return "motor_critical";
    case FreeBranch::MotorCriticalNoLoadFriction: return "motor_critical_FL0";
    case FreeBranch::MotorOverdamped: return "motor_overdamped";
    case FreeBranch::MotorOverdampedNoLoadFriction: return "motor_overdamped_FL0";
  }
  return "?";
}

namespace {

int exact_sign_or_throw(const ex& value, const char* what) {
  const ex v = normal(value);
  if (!is_a<numeric>(v) || !ex_to<numeric>(v).is_rational())
    throw std::domain_error(std::string("cannot decide the sign of ") + what + " = " + text(v) +
                            " for symbolic parameters: choose a pole-structure branch");
  const numeric n = ex_to<numeric>(v);
  return n.is_zero() ? 0 : (n.is_positive() ? 1 : -1);
}

bool exactly_zero_parameter(const ex& value) { return normal(value).is_zero(); }

}  // namespace

ContactBranch classify_contact(const CaseParameters& p) {
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  const int sign = exact_sign_or_throw(F * F - 4 * J * p.K, "the contact discriminant F^2-4JK");
  return sign < 0 ? ContactBranch::Underdamped : (sign == 0 ? ContactBranch::CriticallyDamped : ContactBranch::Overdamped);
}

FreeBranch classify_free(const CaseParameters& p) {
  const bool no_load_friction = exactly_zero_parameter(p.FL);
  if (p.measured_at == model::MeasuredAt::Load) {
    const bool no_motor_friction = exactly_zero_parameter(p.Fm);
    if (no_load_friction && no_motor_friction) return FreeBranch::LoadNoFriction;
    if (no_load_friction) return FreeBranch::LoadNoLoadFriction;
    if (no_motor_friction) return FreeBranch::LoadNoMotorFriction;
    if (exactly_zero_parameter(p.Fm * p.JL - p.FL * p.Jm)) return FreeBranch::LoadEqualRates;
    return FreeBranch::LoadGeneric;
  }
  const int sign = exact_sign_or_throw(p.Fm * p.Fm - 4 * p.Jm * p.K, "the motor-alone discriminant Fm^2-4JmK");
  if (sign < 0) return no_load_friction ? FreeBranch::MotorUnderdampedNoLoadFriction : FreeBranch::MotorUnderdamped;
  if (sign == 0) return no_load_friction ? FreeBranch::MotorCriticalNoLoadFriction : FreeBranch::MotorCritical;
  return no_load_friction ? FreeBranch::MotorOverdampedNoLoadFriction : FreeBranch::MotorOverdamped;
}

bool CaseDerivation::verified() const {
  for (const VerificationCheck& check : checks)
    if (!check.passed) return false;
  return !checks.empty();
}

namespace {

// a2 y'' + a1 y' + a0 y − forcing ≡ 0
bool satisfies_ode(const TimeFunction& y, const ex& a2, const ex& a1, const ex& a0, const TimeFunction& forcing,
                   const RadicalList& radicals) {
  const TimeFunction dy = y.derivative();
  const TimeFunction residual = dy.derivative() * a2 + dy * a1 + y * a0 - forcing;
  return residual.is_zero(radicals);
}

class Checker {
 public:
  Checker(std::vector<VerificationCheck>& checks, const RadicalList& radicals) : checks_(checks), radicals_(radicals) {}
  void expect(const std::string& name, bool passed) { checks_.push_back({name, passed}); }
  void expect_zero(const std::string& name, const ex& value) { expect(name, is_exactly_zero(value, radicals_)); }
  void expect_same(const std::string& name, const TimeFunction& a, const TimeFunction& b) {
    expect(name, (a - b).is_zero(radicals_));
  }

 private:
  std::vector<VerificationCheck>& checks_;
  const RadicalList& radicals_;
};

Segment make_segment(const std::string& name, const std::string& equations, const ex& laplace, RadicalList& radicals,
                     const std::string& radical_name, const std::string& role) {
  return Segment{name, equations, laplace, inverse_laplace(laplace, derivation_symbols().s, radicals, radical_name, role)};
}

}  // namespace

std::vector<ex> default_isocline_slopes() {
  std::vector<ex> etas;
  for (const char* text : {"10", "7", "5", "3", "5/2", "2", "3/2", "6/5", "1", "7/10", "1/2", "3/10", "1/5", "1/10", "0",
                           "-1/10", "-1/5", "-3/10", "-2/5", "-1/2", "-3/5", "-7/10", "-4/5", "-1", "-6/5", "-3/2",
                           "-17/10", "-2", "-5/2", "-3", "-5", "-7", "-10"})
    etas.push_back(numeric(text));
  return etas;
}

ex isocline_angle_degrees(const ex& eta, const ex& K, const ex& J, const ex& F) {
  const ex shifted = normal(eta + F / J);
  if (shifted.is_zero()) return 90;
  return atan(normal(-(K / J) / shifted)) * 180 / Pi;
}

IsoclineTable isocline_table(const std::string& system, const ex& K, const ex& J, const ex& F, const std::vector<ex>& etas) {
  IsoclineTable table{system, J, F, {}};
  IsoclineRow infinite;
  infinite.eta = 0;
  infinite.is_infinite = true;
  infinite.tangent = 0;
  infinite.angle_degrees = 0;
  table.rows.push_back(infinite);
  for (const ex& eta : etas) {
    IsoclineRow row;
    row.eta = eta;
    const ex shifted = normal(eta + F / J);
    row.is_vertical = shifted.is_zero();
    row.tangent = row.is_vertical ? ex(0) : normal(-(K / J) / shifted);
    row.angle_degrees = isocline_angle_degrees(eta, K, J, F);
    table.rows.push_back(row);
  }
  return table;
}

namespace {

StabilityConstant derive_stability_constant(const CaseParameters& p, const Segment& contact_position,
                                            const RadicalList& radicals, std::vector<VerificationCheck>& checks);

}  // namespace

ContactDerivation derive_contact(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks) {
  ContactDerivation out;
  Segment& position = out.position;
  Segment& velocity = out.velocity;
  const DerivationSymbols& x = derivation_symbols();
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  const ex transform = (J * (x.s * x.theta_o0 + x.dtheta_o0) + F * x.theta_o0 + p.K * p.theta_R / x.s) /
                       (J * x.s * x.s + F * x.s + p.K);
  position = make_segment("theta_o", "6, 15, 25", transform, radicals, "omega_c",
                          "damped frequency of the combined (contact) system, sqrt(K/J - F^2/(4J^2))");
  velocity = make_segment("dtheta_o", "6, 15, 25", x.s * transform - x.theta_o0, radicals, "omega_c",
                          "damped frequency of the combined (contact) system, sqrt(K/J - F^2/(4J^2))");
  Checker check(checks, radicals);
  check.expect("contact: J*theta_o'' + F*theta_o' + K*theta_o = K*theta_R",
               satisfies_ode(position.solution, J, F, p.K, TimeFunction::constant(p.K * p.theta_R), radicals));
  check.expect_zero("contact: theta_o(0) = theta_o0", position.solution.at_zero() - x.theta_o0);
  check.expect_zero("contact: theta_o'(0) = dtheta_o0", position.solution.derivative().at_zero() - x.dtheta_o0);
  check.expect_same("contact: L^-1[s*Theta_o - theta_o0] = d/dt theta_o", velocity.solution,
                    position.solution.derivative());
  out.stability = derive_stability_constant(p, position, radicals, checks);
  return out;
}

FreeDerivation derive_free(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks) {
  const DerivationSymbols& x = derivation_symbols();
  const ex& v0 = x.dtheta_m0;
  FreeDerivation out;
  out.cot_phi = normal((p.Jm * p.FL - p.Fm * p.JL) / (p.K * p.JL));
  out.separation_theta = p.theta_R + out.cot_phi * v0;
  out.eta_separation = normal(-p.FL / p.JL);
  {
    // On θo = θR + cot φ θ̇o: η = θ̈/θ̇ for combined, motor-alone and load coincide (eqs. 12, 45, 87–91).
    Checker check(checks, radicals);
    const ex error_over_velocity = -out.cot_phi;  // (θR − θo)/θ̇o on the line
    const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
    const ex eta_combined = (p.K * error_over_velocity - F) / J;
    const ex eta_motor = (p.K * error_over_velocity - p.Fm) / p.Jm;
    check.expect_zero("separation line: combined slope eta1 = -FL/JL", eta_combined - out.eta_separation);
    check.expect_zero("separation line: motor-alone slope eta2 = -FL/JL", eta_motor - out.eta_separation);
    check.expect_zero("separation line: transmitted torque JL*theta'' + FL*theta' = 0", p.JL * eta_combined + p.FL);
  }
  const ex& theta0 = out.separation_theta;
  const ex load_transform = theta0 / x.s + v0 / (x.s * (x.s + p.FL / p.JL));
  out.load_position = make_segment("theta_L", "22, 53, 64, 73, 79, 94, 104, 105, 116, 128", load_transform, radicals, "", "");
  out.load_velocity = make_segment("dtheta_L", "23, 55, 117, 129", x.s * load_transform - theta0, radicals, "", "");

  const bool at_motor = p.measured_at == model::MeasuredAt::Motor;
  const ex motor_transform =
      at_motor ? (p.Jm * (x.s * theta0 + v0) + p.Fm * theta0 + p.K * p.theta_R / x.s) / (p.Jm * x.s * x.s + p.Fm * x.s + p.K)
               : (p.Jm * (x.s * theta0 + v0) + p.Fm * theta0 + p.K * (p.theta_R / x.s - load_transform)) /
                     (p.Jm * x.s * x.s + p.Fm * x.s);
  const std::string role = "damped frequency of the motor-alone closed loop, sqrt(K/Jm - Fm^2/(4Jm^2))";
  out.motor_position = make_segment("theta_m", at_motor ? "18, 20, 49, 50, 51, 61, 62" : "40, 69, 70, 77, 92, 102, 114, 126",
                                    motor_transform, radicals, "omega_m", role);
  out.motor_velocity = make_segment("dtheta_m", at_motor ? "21, 52, 63" : "41, 71, 72, 78, 93, 103, 115, 127",
                                    x.s * motor_transform - theta0, radicals, "omega_m", role);

  Checker check(checks, radicals);
  const TimeFunction& load = out.load_position.solution;
  const TimeFunction& motor = out.motor_position.solution;
  check.expect("free load: JL*theta_L'' + FL*theta_L' = 0 (eq. 17)",
               satisfies_ode(load, p.JL, p.FL, 0, TimeFunction{}, radicals));
  check.expect_zero("free load: theta_L(0) = theta_R + cot(phi)*dtheta_m0", load.at_zero() - theta0);
  check.expect_zero("free load: theta_L'(0) = dtheta_m0", load.derivative().at_zero() - v0);
  check.expect_same("free load: L^-1[s*Theta_L - theta_L(0)] = d/dt theta_L", out.load_velocity.solution, load.derivative());
  if (at_motor)
    check.expect("free motor: Jm*theta_m'' + Fm*theta_m' + K*theta_m = K*theta_R (eq. 16)",
                 satisfies_ode(motor, p.Jm, p.Fm, p.K, TimeFunction::constant(p.K * p.theta_R), radicals));
  else
    check.expect("free motor: Jm*theta_m'' + Fm*theta_m' = K*(theta_R - theta_L(t)) (eq. 39)",
                 satisfies_ode(motor, p.Jm, p.Fm, 0, (TimeFunction::constant(p.theta_R) - load) * p.K, radicals));
  check.expect_zero("free motor: theta_m(0) = theta_R + cot(phi)*dtheta_m0", motor.at_zero() - theta0);
  check.expect_zero("free motor: theta_m'(0) = dtheta_m0", motor.derivative().at_zero() - v0);
  check.expect_same("free motor: L^-1[s*Theta_m - theta_m(0)] = d/dt theta_m", out.motor_velocity.solution,
                    motor.derivative());

  out.gap = (load - motor).combined(radicals);
  out.recombined_velocity =
      ((out.motor_velocity.solution * p.Jm + out.load_velocity.solution * p.JL) * (1 / (p.Jm + p.JL))).combined(radicals);
  check.expect_zero("momentum (eq. 24): (Jm+JL)*dtheta_o+ = Jm*dtheta_m + JL*dtheta_L at t = 0 gives dtheta_m0",
                    out.recombined_velocity.at_zero() - v0);
  return out;
}

namespace {

StabilityConstant derive_stability_constant(const CaseParameters& p, const Segment& contact_position,
                                            const RadicalList& radicals, std::vector<VerificationCheck>& checks) {
  StabilityConstant out;
  ex omega;
  for (const ExpTerm& term : contact_position.solution.terms())
    if (term.oscillation != Oscillation::None) omega = term.frequency;
  if (omega.is_zero()) {
    out.region = "not applicable: the contact mode is not under-damped (no log-spiral, eq. 32 needs K/J > F^2/(4J^2))";
    return out;
  }
  const DerivationSymbols& x = derivation_symbols();
  const ex J = p.Jm + p.JL, F = p.Fm + p.FL;
  const ex a = F / (2 * J);
  const ex e = p.theta_R - x.theta_o;
  const ex Q = pow(x.dtheta_o, 2) - F / J * x.dtheta_o * e + p.K / J * pow(e, 2);
  const ex z = (x.dtheta_o - a * e) / (e * omega);
  out.applicable = true;
  out.C = sqrt(Q) / omega * exp(a / omega * atan(z));
  // d(ln C)/dt along J θ̈ + F θ̇ + K θ = K θR.
  const ex log_C = log(Q) / 2 + a / omega * atan(z);
  const ex acceleration = (p.K * e - F * x.dtheta_o) / J;
  out.dlnC_dt = simplify(log_C.diff(x.theta_o) * x.dtheta_o + log_C.diff(x.dtheta_o) * acceleration, radicals);
  out.jump_factor = exp(-Pi * a / omega);
  out.region =
      "C is constant along every contact-mode trajectory inside each open half-plane theta_o < theta_R and "
      "theta_o > theta_R (d ln C/dt = 0 exactly); on the line theta_o = theta_R the principal arctan of eq. 38 "
      "jumps by pi, so each crossing of theta_o = theta_R multiplies C by exp(-pi*F/(2*J*omega_c)); C compares "
      "separation and recombination points only when both lie in the same half-plane (or after that correction)";
  Checker check(checks, radicals);
  check.expect("stability constant (eq. 38): dC/dt = 0 along contact trajectories", out.dlnC_dt.is_zero());
  return out;
}

}  // namespace

void require_all_checks_passed(const std::string& what, const std::vector<VerificationCheck>& checks) {
  std::string failures;
  for (const VerificationCheck& check : checks)
    if (!check.passed) failures += (failures.empty() ? "" : "; ") + check.name;
  if (!failures.empty()) throw VerificationError(what + ": exact verification failed: " + failures);
}

CaseDerivation derive(const std::string& case_id, const std::string& name, const CaseParameters& p, RadicalList radicals) {
  CaseDerivation d;
  d.case_id = case_id;
  d.name = name;
  d.parameters = p;
  d.radicals = std::move(radicals);
  d.contact_branch = classify_contact(p);
  d.free_branch = classify_free(p);
  d.contact = derive_contact(p, d.radicals, d.checks);
  d.free = derive_free(p, d.radicals, d.checks);
  const std::vector<ex> etas = default_isocline_slopes();
  d.isoclines.push_back(isocline_table("combined", p.K, p.Jm + p.JL, p.Fm + p.FL, etas));
  d.isoclines.push_back(isocline_table("motor_alone", p.K, p.Jm, p.Fm, etas));
  require_all_checks_passed("case " + case_id, d.checks);
  return d;
}

CaseDerivation derive_case(const model::CaseSpec& spec) { return derive(spec.id, spec.name, exact_parameters(spec)); }

}  // namespace backlash::symbolic
