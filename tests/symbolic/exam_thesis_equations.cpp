// Equation-by-equation tests of the exact derivations against the thesis.
// Each test is named after the thesis equation (and case) it checks; printed
// numbers are compared at their printed precision, and every disagreement
// must be pinned in reports/errata/ledger.toml with the exact value.
#include "thesis_printed.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <gtest/gtest.h>

#include <map>

namespace {

using namespace GiNaC;
using namespace backlash::symbolic;
using backlash::testing::expect_printed;
using backlash::testing::expect_printed_angle;

const CaseDerivation& thesis_case(const std::string& id) {
  static std::map<std::string, CaseDerivation> cache;
  auto found = cache.find(id);
  if (found == cache.end()) found = cache.emplace(id, derive_case(backlash::model::load_case(id))).first;
  return found->second;
}

const realsymbol& v0() { return derivation_symbols().dtheta_m0; }
const possymbol& t() { return derivation_symbols().t; }
const symbol& s() { return derivation_symbols().s; }

// Coefficient of θ̇m0 · t^k e^{rate t} (osc) in a free-mode solution.
ex per_v0(const CaseDerivation& d, const TimeFunction& f, unsigned k, const ex& rate, Oscillation osc = Oscillation::None) {
  const ex c = f.coefficient(k, rate, osc, d.radicals);
  return simplify(c.coeff(v0(), 1), d.radicals);
}
// Part of the constant term free of θ̇m0.
ex constant_part(const CaseDerivation& d, const TimeFunction& f) {
  return simplify(f.coefficient(0, 0, Oscillation::None, d.radicals).coeff(v0(), 0), d.radicals);
}

ex damped_frequency(const TimeFunction& f) {
  for (const ExpTerm& term : f.terms())
    if (term.oscillation != Oscillation::None) return term.frequency;
  return 0;
}

bool same(const ex& a, const ex& b, const RadicalList& radicals = {}) { return is_exactly_zero(a - b, radicals); }

// ---------------------------------------------------------------- general forms (eqs. 18–24, 39–41)

TEST(Eq18_Eq20_General_MotorAloneLaplace, ClosedLoopMotorTransformIsTheThesisForm) {
  // Eq. 20: Θm = KθR/(s(s²+Fm/Jm s+K/Jm))/Jm·Jm … written with θm0 = θR + θ̇m0/tan φ.
  for (const auto& branch : derive_general_branches()) {
    if (branch.name.rfind("motor_", 0) != 0) continue;
    const CaseParameters& p = branch.parameters;
    const ex q = s() * s() + p.Fm / p.Jm * s() + p.K / p.Jm;
    const ex theta0 = branch.free.separation_theta;
    const ex eq20 = p.K * p.theta_R / (p.Jm * s() * q) + (theta0 * (s() + p.Fm / p.Jm) + v0()) / q;
    EXPECT_TRUE(same(branch.free.motor_position.laplace, eq20))
        << branch.name << ": returned " << branch.free.motor_position.laplace << " instead of eq. 20 " << eq20;
    // Eq. 21 is s·Θm − θm0 (the printed eq. 21 multiplies the whole of eq. 20 by s, dropping −θm0).
    EXPECT_TRUE(same(branch.free.motor_velocity.laplace, s() * eq20 - theta0));
  }
}

TEST(Eq21_General_MotorAloneVelocityLaplace, VelocityTransformIsSTimesThetaMMinusItsInitialValue) {
  // Eq. 21: the motor's velocity transform when the output is measured at the motor (the
  // closed-loop motor of eq. 16).  The transform of a derivative is s·Θm(s) − θm(0): with eq. 20
  // for Θm and θm0 = θR + cot φ·θ̇m0 (eq. 19).  The printed eq. 21 is s times all of eq. 20 (and
  // K·θ̇R for K·θR): it lacks −θm0, so it is improper and would put an impulse θm0·δ(t) into θ̇m.
  int checked = 0;
  for (const auto& branch : derive_general_branches()) {
    if (branch.name.rfind("motor_", 0) != 0) continue;
    const CaseParameters& p = branch.parameters;
    const ex q = s() * s() + p.Fm / p.Jm * s() + p.K / p.Jm;
    // θm0 from eq. 19 written out (not the branch's own separation point)
    const ex theta0 = p.theta_R + (p.Jm * p.FL - p.Fm * p.JL) / (p.K * p.JL) * v0();
    const ex eq20 = p.K * p.theta_R / (p.Jm * s() * q) + (theta0 * (s() + p.Fm / p.Jm) + v0()) / q;
    const ex eq21 = s() * eq20 - theta0;
    EXPECT_TRUE(same(branch.free.motor_velocity.laplace, eq21))
        << branch.name << ": returned " << branch.free.motor_velocity.laplace << " instead of " << eq21;
    // proper: numerator of lower degree in s than the denominator (no impulse)
    const ex fraction = numer_denom(normal(eq21));
    EXPECT_LT(fraction.op(0).degree(s()), fraction.op(1).degree(s())) << branch.name << ": eq. 21 is not proper";
    // the printed form, s times eq. 20, is not the derived transform: it is improper (the
    // degrees of its numerator and denominator are equal), its inverse an impulse θm0·δ(t)
    // plus the derived velocity
    const ex printed = numer_denom(normal(s() * eq20));
    EXPECT_EQ(printed.op(0).degree(s()), printed.op(1).degree(s())) << branch.name << ": s·(eq. 20) is proper";
    EXPECT_FALSE(same(branch.free.motor_velocity.laplace, s() * eq20)) << branch.name << ": returned the printed eq. 21";
    // its inverse is the derivative of θm(t), term by term, and starts at θ̇m0
    EXPECT_TRUE((branch.free.motor_velocity.solution - branch.free.motor_position.solution.derivative()).is_zero({}))
        << branch.name << ": L^-1[eq. 21] is not d/dt of L^-1[eq. 20]";
    EXPECT_TRUE(same(branch.free.motor_velocity.solution.at_zero(), v0())) << branch.name;
    ++checked;
  }
  EXPECT_EQ(checked, 6) << "returned " << checked << " motor-measured branches instead of 6";
}

TEST(Eq19_General_SeparationLine, CotPhiIsTheMotorAloneIsoclineOfSlopeEta3) {
  const GeneralSymbols& g = general_symbols();
  for (const auto& branch : derive_general_branches()) {
    if (branch.mode != GeneralBranch::Mode::Free) continue;
    const CaseParameters& p = branch.parameters;
    EXPECT_TRUE(same(branch.free.cot_phi, (p.Jm * p.FL - p.Fm * p.JL) / (p.K * p.JL))) << branch.name;
    EXPECT_TRUE(same(branch.free.separation_theta, p.theta_R + branch.free.cot_phi * v0())) << branch.name;
    EXPECT_TRUE(same(branch.free.eta_separation, -p.FL / p.JL)) << branch.name;
  }
  (void)g;
}

TEST(Eq22_Eq23_General_LoadLaplace, DriftingLoadTransforms) {
  for (const auto& branch : derive_general_branches()) {
    if (branch.mode != GeneralBranch::Mode::Free) continue;
    const CaseParameters& p = branch.parameters;
    const ex theta0 = branch.free.separation_theta;
    const ex eq22 = (theta0 * (s() + p.FL / p.JL) + v0()) / (s() * (s() + p.FL / p.JL));
    const ex eq23 = v0() / (s() + p.FL / p.JL);
    EXPECT_TRUE(same(branch.free.load_position.laplace, eq22)) << branch.name << ": returned " << branch.free.load_position.laplace;
    EXPECT_TRUE(same(branch.free.load_velocity.laplace, eq23)) << branch.name;
  }
}

TEST(Eq24_General_MomentumBalance, RecombinedVelocityConservesMomentum) {
  for (const auto& id : backlash::model::thesis_case_ids()) {
    const CaseDerivation& d = thesis_case(id);
    const CaseParameters& p = d.parameters;
    const TimeFunction lhs = d.free.recombined_velocity * (p.Jm + p.JL);
    const TimeFunction rhs = d.free.motor_velocity.solution * p.Jm + d.free.load_velocity.solution * p.JL;
    EXPECT_TRUE((lhs - rhs).is_zero(d.radicals)) << "case " << id;
  }
}

TEST(Eq40_Eq41_General_LoadMeasuredMotorLaplace, OpenLoopMotorTransformIsTheThesisForm) {
  for (const auto& branch : derive_general_branches()) {
    if (branch.name.rfind("load_", 0) != 0) continue;
    const CaseParameters& p = branch.parameters;
    const ex am = p.Fm / p.Jm, aL = p.FL / p.JL, k = p.K / p.Jm, c = branch.free.cot_phi;
    // Eq. 40 with θR general (the thesis sets θR = 1): the last term is θm0/s.
    const ex eq40 = k * (-v0() * c) / (s() * s() * (s() + am)) - k * v0() / (s() * s() * (s() + am) * (s() + aL)) +
                    v0() / (s() * (s() + am)) + (p.theta_R + v0() * c) / s();
    const ex eq41 = k * (-v0() * c) / (s() * (s() + am)) - k * v0() / (s() * (s() + am) * (s() + aL)) + v0() / (s() + am);
    EXPECT_TRUE(same(branch.free.motor_position.laplace, eq40)) << branch.name << ": returned "
                                                                 << branch.free.motor_position.laplace << " instead of " << eq40;
    EXPECT_TRUE(same(branch.free.motor_velocity.laplace, eq41)) << branch.name;
  }
}

TEST(Eq38_General_StabilityConstant, InvariantAlongContactTrajectoriesWithinEachHalfPlane) {
  for (const auto& branch : derive_general_branches()) {
    if (branch.mode != GeneralBranch::Mode::Contact) continue;
    const StabilityConstant& c = branch.contact.stability;
    if (branch.name == "contact_underdamped") {
      ASSERT_TRUE(c.applicable);
      EXPECT_TRUE(c.dlnC_dt.is_zero()) << "d ln C/dt returned " << c.dlnC_dt << " instead of 0";
      EXPECT_NE(c.region.find("theta_o = theta_R"), std::string::npos);
    } else {
      EXPECT_FALSE(c.applicable) << branch.name << ": no log-spiral without complex poles";
    }
  }
  for (const auto& id : backlash::model::thesis_case_ids()) {
    const CaseDerivation& d = thesis_case(id);
    ASSERT_TRUE(d.contact.stability.applicable) << id;
    EXPECT_TRUE(d.contact.stability.dlnC_dt.is_zero()) << id;
  }
}

TEST(Eq38_General_StabilityConstant, PrincipalBranchJumpsByExpMinusPiAOverOmegaAcrossThetaR) {
  // Along the exact contact solution of case V from rest at θo = 0, C is
  // constant until θo reaches θR, and is multiplied by the jump factor there.
  const CaseDerivation& d = thesis_case("V");
  const DerivationSymbols& x = derivation_symbols();
  const ex theta = d.contact.position.solution.to_ex(t()).subs(lst{x.theta_o0 == 0, x.dtheta_o0 == 0});
  const ex dtheta = d.contact.velocity.solution.to_ex(t()).subs(lst{x.theta_o0 == 0, x.dtheta_o0 == 0});
  auto C_at = [&](double time) {
    const ex point = lst{x.theta_o == theta.subs(t() == numeric(time)), x.dtheta_o == dtheta.subs(t() == numeric(time))};
    return to_double(d.contact.stability.C.subs(ex_to<lst>(point)), d.radicals);
  };
  const double before_a = C_at(0.5), before_b = C_at(1.5);
  EXPECT_NEAR(before_a / before_b, 1.0, 1e-12);  // same half-plane θo < θR (first crossing at t ≈ 2.1)
  const double after = C_at(3.0);                // θo > θR
  EXPECT_NEAR(after / before_b, to_double(d.contact.stability.jump_factor, d.radicals), 1e-12);
}

// ---------------------------------------------------------------- Case I (eqs. 42–55)

TEST(Eq45_CaseI_SeparationSlope, LoadDecelerationRatio) {
  const CaseDerivation& d = thesis_case("I");
  expect_printed("Eq45", "I", "eta3", d.free.eta_separation, "-.8");
  EXPECT_TRUE(d.free.cot_phi.is_zero()) << "separation line is theta_o = 1 (cot phi = 0), returned " << d.free.cot_phi;
}

TEST(Eq47_CaseI_MotorAloneIsoclines, Coefficients) {
  const CaseParameters& p = thesis_case("I").parameters;
  expect_printed("Eq47", "I", "Fm/Jm", p.Fm / p.Jm, ".8");
  expect_printed("Eq47", "I", "K/Jm", p.K / p.Jm, "1.66");
}

TEST(Eq48_CaseI_MotorAloneEquation, Coefficients) {
  const CaseParameters& p = thesis_case("I").parameters;
  expect_printed("Eq48", "I", "Fm/Jm", p.Fm / p.Jm, ".8");
  expect_printed("Eq48", "I", "K/Jm", p.K / p.Jm, "1.666");
}

TEST(Eq50_CaseI_MotorAlonePoles, RootsOfTheQuadratic) {
  const CaseDerivation& d = thesis_case("I");
  const ex omega = damped_frequency(d.free.motor_position.solution);
  expect_printed("Eq50", "I", "real part of the roots", -d.parameters.Fm / (2 * d.parameters.Jm), "-.4");
  expect_printed("Eq50", "I", "imaginary part of the roots", omega, "1.225", d.radicals);
}

TEST(Eq51_CaseI_ThetaM, DampedSineFromTheSeparationPoint) {
  const CaseDerivation& d = thesis_case("I");
  const TimeFunction& f = d.free.motor_position.solution;
  const ex omega = damped_frequency(f);
  EXPECT_TRUE(same(constant_part(d, f), 1, d.radicals));
  EXPECT_TRUE(per_v0(d, f, 0, 0).is_zero());
  EXPECT_TRUE(per_v0(d, f, 0, numeric(-2, 5), Oscillation::Cos).is_zero());
  // Printed θ̇m0/1.225 · e^{−.4t} sin 1.225t: the divisor is the frequency.
  expect_printed("Eq51", "I", "divisor of the sine amplitude", 1 / per_v0(d, f, 0, numeric(-2, 5), Oscillation::Sin), "1.225", d.radicals);
  expect_printed("Eq51", "I", "frequency", omega, "1.225", d.radicals);
  expect_printed("Eq51", "I", "decay rate", -d.parameters.Fm / (2 * d.parameters.Jm), "-.4");
}

TEST(Eq52_CaseI_DThetaM, DampedVelocity) {
  const CaseDerivation& d = thesis_case("I");
  const TimeFunction& f = d.free.motor_velocity.solution;
  // Printed −(θ̇m0/1.225) e^{−.4t} sin 1.225t: the divisor x of −θ̇m0/x.
  expect_printed("Eq52", "I", "divisor x of the sine term -dtheta_m0/x", -1 / per_v0(d, f, 0, numeric(-2, 5), Oscillation::Sin), "1.225", d.radicals);
  expect_printed("Eq52", "I", "cosine coefficient per dtheta_m0", per_v0(d, f, 0, numeric(-2, 5), Oscillation::Cos), "1", d.radicals);
}

TEST(Eq53_Eq54_Eq55_CaseI_Load, DriftingLoad) {
  const CaseDerivation& d = thesis_case("I");
  const ex a = numeric(-4, 5);
  const TimeFunction& L = d.free.load_position.solution;
  expect_printed("Eq54", "I", "1/.8 per dtheta_m0", per_v0(d, L, 0, 0), "1.25");
  expect_printed("Eq54", "I", "exponential coefficient per dtheta_m0", per_v0(d, L, 0, a), "-1.25");
  expect_printed("Eq55", "I", "velocity coefficient", per_v0(d, d.free.load_velocity.solution, 0, a), "1");
  EXPECT_TRUE(same(d.free.load_position.laplace, v0() / (s() * (s() + numeric(4, 5))) + 1 / s()));  // eq. 53, θm0 = 1
}

// ---------------------------------------------------------------- Case II (eqs. 56–65)

TEST(Eq58_CaseII_SeparationSlope, LoadWithoutFriction) {
  expect_printed("Eq58", "II", "eta3", thesis_case("II").free.eta_separation, "0");
}

TEST(Eq60_CaseII_MotorAloneIsoclines, Coefficients) {
  const CaseParameters& p = thesis_case("II").parameters;
  expect_printed("Eq60", "II", "Fm/Jm", p.Fm / p.Jm, ".4");
  expect_printed("Eq60", "II", "K/Jm", p.K / p.Jm, "2");
}

TEST(Eq62_CaseII_ThetaM, ShiftedSine) {
  // θm = 1 + A θ̇m0 e^{−.2t} sin(1.4t − φ):  A = |(S, C)|, tan φ = −C/S for S sin + C cos.
  const CaseDerivation& d = thesis_case("II");
  const TimeFunction& f = d.free.motor_position.solution;
  const ex omega = damped_frequency(f);
  const ex S = per_v0(d, f, 0, numeric(-1, 5), Oscillation::Sin), C = per_v0(d, f, 0, numeric(-1, 5), Oscillation::Cos);
  expect_printed("Eq62", "II", "frequency", omega, "1.4", d.radicals);
  expect_printed("Eq62", "II", "amplitude per dtheta_m0", sqrt(S * S + C * C), ".715", d.radicals);
  expect_printed_angle("Eq62", "II", "phase phi (degrees)", atan(-C / S) * 180 / Pi, "16.25");
}

TEST(Eq63_CaseII_DThetaM, ShiftedVelocity) {
  // θ̇m = a θ̇m0 e sin(1.4t − φ) + b θ̇m0 e cos(1.4t − φ) with the same φ (tan φ = 7/24).
  const CaseDerivation& d = thesis_case("II");
  const TimeFunction& f = d.free.motor_velocity.solution;
  const ex S = per_v0(d, f, 0, numeric(-1, 5), Oscillation::Sin), C = per_v0(d, f, 0, numeric(-1, 5), Oscillation::Cos);
  const TimeFunction& pos = d.free.motor_position.solution;
  const ex Sp = per_v0(d, pos, 0, numeric(-1, 5), Oscillation::Sin), Cp = per_v0(d, pos, 0, numeric(-1, 5), Oscillation::Cos);
  const ex norm = sqrt(Sp * Sp + Cp * Cp), cos_phi = Sp / norm, sin_phi = -Cp / norm;
  const ex a = S * cos_phi - C * sin_phi, b = S * sin_phi + C * cos_phi;
  expect_printed("Eq63", "II", "sine coefficient per dtheta_m0", a, "-.1430");
  expect_printed("Eq63", "II", "cosine coefficient per dtheta_m0", b, "1");
}

TEST(Eq64_Eq65_CaseII_Load, UndeceleratedDrift) {
  const CaseDerivation& d = thesis_case("II");
  expect_printed("Eq65", "II", "t coefficient per dtheta_m0", per_v0(d, d.free.load_position.solution, 1, 0), "1");
  EXPECT_TRUE(same(d.free.load_position.laplace, v0() / (s() * s()) + d.free.separation_theta / s()));
}

// ---------------------------------------------------------------- Case III (eqs. 66–73)

TEST(Eq69_CaseIII_ThetaMLaplace, PartialFractions) {
  // Printed: 13.5/s² − 5/s³ − 31.25(1/s + 1/(s+.4)) + (1 − .2θ̇m0)/s, all times θ̇m0 where shown.
  const CaseDerivation& d = thesis_case("III");
  const ex F = d.free.motor_position.laplace;
  const ex printed_corrected =
      numeric(27, 2) * v0() / pow(s(), 2) - 5 * v0() / pow(s(), 3) - numeric(125, 4) * v0() * (1 / s() - 1 / (s() + numeric(2, 5))) +
      (1 - numeric(1, 5) * v0()) / s();
  EXPECT_TRUE(same(F, printed_corrected)) << "returned " << F;
  const ex printed_as_is =
      numeric(27, 2) * v0() / pow(s(), 2) - 5 * v0() / pow(s(), 3) - numeric(125, 4) * v0() * (1 / s() + 1 / (s() + numeric(2, 5))) +
      (1 - numeric(1, 5) * v0()) / s();
  EXPECT_FALSE(same(F, printed_as_is)) << "the printed sign of 1/(s+.4) is wrong (see ledger Eq69)";
  expect_printed("Eq69", "III", "coefficient of 1/(s+.4) per dtheta_m0",
                 normal(F.diff(v0()) * (s() + numeric(2, 5))).subs(s() == numeric(-2, 5)), "-31.25");
}

TEST(Eq70_CaseIII_ThetaM, TriplePoleAtZero) {
  const CaseDerivation& d = thesis_case("III");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq70", "III", "t coefficient", per_v0(d, f, 1, 0), "13.5");
  expect_printed("Eq70", "III", "t^2 coefficient", per_v0(d, f, 2, 0), "-2.5");
  expect_printed("Eq70", "III", "exponential coefficient", per_v0(d, f, 0, numeric(-2, 5)), "31.25");
  expect_printed("Eq70", "III", "constant per dtheta_m0 (-31.25 - .2)", per_v0(d, f, 0, 0), "-31.45");
  EXPECT_TRUE(same(constant_part(d, f), 1));
}

TEST(Eq71_CaseIII_DThetaMLaplace, VelocityTransform) {
  const CaseDerivation& d = thesis_case("III");
  const ex F = d.free.motor_velocity.laplace;
  const ex exact = numeric(27, 2) * v0() / s() - 5 * v0() / pow(s(), 2) - numeric(25, 2) * v0() / (s() + numeric(2, 5));
  EXPECT_TRUE(same(F, exact)) << "returned " << F;
  expect_printed("Eq71", "III", "coefficient of 1/(s+.4) per dtheta_m0",
                 normal(F.diff(v0()) * (s() + numeric(2, 5))).subs(s() == numeric(-2, 5)), "31.25");
}

TEST(Eq72_CaseIII_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("III");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq72", "III", "constant", per_v0(d, f, 0, 0), "13.5");
  expect_printed("Eq72", "III", "exponential (1 - 13.5)", per_v0(d, f, 0, numeric(-2, 5)), "-12.5");
  expect_printed("Eq72", "III", "t coefficient", per_v0(d, f, 1, 0), "-5");
}

TEST(Eq73_CaseIII_ThetaL, UndeceleratedDrift) {
  const CaseDerivation& d = thesis_case("III");
  expect_printed("Eq73", "III", "t coefficient", per_v0(d, d.free.load_position.solution, 1, 0), "1");
  expect_printed("Eq73", "III", "theta_L0 per dtheta_m0 (cot phi)", per_v0(d, d.free.load_position.solution, 0, 0), "-.2");
}

// ---------------------------------------------------------------- Case IV (eqs. 74–81)

TEST(Eq77_CaseIV_ThetaM, TriplePoleAtZero) {
  const CaseDerivation& d = thesis_case("IV");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq77", "IV", "t^2 coefficient", per_v0(d, f, 2, 0), "-2.5");
  expect_printed("Eq77", "IV", "t coefficient", per_v0(d, f, 1, 0), "6");
  expect_printed("Eq77", "IV", "exponential coefficient", per_v0(d, f, 0, -1), "5");
  expect_printed("Eq77", "IV", "constant per dtheta_m0 (-5 - .2)", per_v0(d, f, 0, 0), "-5.2");
}

TEST(Eq78_CaseIV_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("IV");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq78", "IV", "t coefficient", per_v0(d, f, 1, 0), "-5");
  expect_printed("Eq78", "IV", "constant", per_v0(d, f, 0, 0), "6");
  expect_printed("Eq78", "IV", "exponential", per_v0(d, f, 0, -1), "-5");
}

TEST(Eq79_CaseIV_ThetaL, UndeceleratedDrift) {
  const CaseDerivation& d = thesis_case("IV");
  expect_printed("Eq79", "IV", "t coefficient", per_v0(d, d.free.load_position.solution, 1, 0), "1");
}

// ---------------------------------------------------------------- Case V (eqs. 82–94)

TEST(Eq87_CaseV_SeparationSlope, LoadDecelerationRatio) {
  expect_printed("Eq87", "V", "eta3", thesis_case("V").free.eta_separation, "-0.6");
}

TEST(Eq89_Eq90_CaseV_SeparationIsocline, MotorAloneIsoclineTangent) {
  // η2 + Fm/Jm = (K/Jm)(1 − θm0)/θ̇m0  ⇒  θ̇m0/(1 − θm0) = (K/Jm)/(η2 + Fm/Jm); the printed constant is 1.2.
  const CaseParameters& p = thesis_case("V").parameters;
  expect_printed("Eq89", "V", "Fm/Jm", p.Fm / p.Jm, "0.2");
  expect_printed("Eq90", "V", "constant added to eta2", p.Fm / p.Jm, "1.2");
}

TEST(Eq91_CaseV_SeparationAngle, Phi) {
  const CaseDerivation& d = thesis_case("V");
  expect_printed_angle("Eq91", "V", "phi (degrees)", atan(1 / d.free.cot_phi) * 180 / Pi, "78.7");
}

TEST(Eq92_CaseV_ThetaM, GenericLoadMeasured) {
  const CaseDerivation& d = thesis_case("V");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq92", "V", "constant per dtheta_m0", per_v0(d, f, 0, 0), "126.3");
  expect_printed("Eq92", "V", "coefficient of e^{-.2t}", per_v0(d, f, 0, numeric(-1, 5)), "-140");
  expect_printed("Eq92", "V", "coefficient of e^{-.6t}", per_v0(d, f, 0, numeric(-3, 5)), "13.9");
  expect_printed("Eq92", "V", "t coefficient", per_v0(d, f, 1, 0), "-18.66");
}

TEST(Eq93_CaseV_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("V");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq93", "V", "constant", per_v0(d, f, 0, 0), "-18.66");
  expect_printed("Eq93", "V", "coefficient of e^{-.2t}", per_v0(d, f, 0, numeric(-1, 5)), "28");
  expect_printed("Eq93", "V", "coefficient of e^{-.6t}", per_v0(d, f, 0, numeric(-3, 5)), "-8.33");
}

TEST(Eq94_CaseV_ThetaL, DeceleratingLoad) {
  const CaseDerivation& d = thesis_case("V");
  const TimeFunction& f = d.free.load_position.solution;
  expect_printed("Eq94", "V", "theta_L0 per dtheta_m0 (cot phi)", d.free.cot_phi, ".2");
  expect_printed("Eq94", "V", "drift amplitude JL/FL", -per_v0(d, f, 0, numeric(-3, 5)), "1.66");
}

// ---------------------------------------------------------------- Case VI (eqs. 95–105)

TEST(Eq98_CaseVI_SeparationSlope, LoadDecelerationRatio) {
  expect_printed("Eq98", "VI", "eta3", thesis_case("VI").free.eta_separation, "-.2");
}

TEST(Eq100_Eq101_CaseVI_SeparationAngle, Phi) {
  const CaseDerivation& d = thesis_case("VI");
  const CaseParameters& p = d.parameters;
  expect_printed("Eq100", "VI", "Fm/Jm", p.Fm / p.Jm, ".6");
  expect_printed("Eq100", "VI", "K/Jm", p.K / p.Jm, "2");
  expect_printed_angle("Eq101", "VI", "phi (degrees)", atan(1 / d.free.cot_phi) * 180 / Pi, "101.3");
}

TEST(Eq102_CaseVI_ThetaM, GenericLoadMeasured) {
  const CaseDerivation& d = thesis_case("VI");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq102", "VI", "t coefficient", per_v0(d, f, 1, 0), "-16");
  expect_printed("Eq102", "VI", "constant per dtheta_m0", per_v0(d, f, 0, 0), "111.455");
  expect_printed("Eq102", "VI", "coefficient of e^{-.6t}", per_v0(d, f, 0, numeric(-3, 5)), "13.345");
  expect_printed("Eq102", "VI", "coefficient of e^{-.2t}", per_v0(d, f, 0, numeric(-1, 5)), "-125");
}

TEST(Eq103_CaseVI_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("VI");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq103", "VI", "constant", per_v0(d, f, 0, 0), "-16");
  expect_printed("Eq103", "VI", "coefficient of e^{-.6t}", per_v0(d, f, 0, numeric(-3, 5)), "-8");
  expect_printed("Eq103", "VI", "coefficient of e^{-.2t}", per_v0(d, f, 0, numeric(-1, 5)), "25");
}

TEST(Eq104_Eq105_CaseVI_ThetaL, DeceleratingLoad) {
  const CaseDerivation& d = thesis_case("VI");
  EXPECT_TRUE(same(d.free.load_position.laplace, (1 - numeric(1, 5) * v0()) / s() + v0() / (s() * (s() + numeric(1, 5)))));
  const TimeFunction& f = d.free.load_position.solution;
  expect_printed("Eq105", "VI", "theta_L0 per dtheta_m0 (cot phi)", d.free.cot_phi, "-.2");
  expect_printed("Eq105", "VI", "drift amplitude JL/FL", -per_v0(d, f, 0, numeric(-1, 5)), "5");
}

// ---------------------------------------------------------------- Case VII (eqs. 106–117)

TEST(Eq109_CaseVII_SeparationSlope, LoadDecelerationRatio) {
  expect_printed("Eq109", "VII", "eta3", thesis_case("VII").free.eta_separation, "-.375");
}

TEST(Eq111_Eq113_CaseVII_SeparationAngle, Phi) {
  const CaseDerivation& d = thesis_case("VII");
  const CaseParameters& p = d.parameters;
  expect_printed("Eq111", "VII", "Fm/Jm", p.Fm / p.Jm, ".5");
  expect_printed("Eq111", "VII", "K/Jm", p.K / p.Jm, "5");
  expect_printed_angle("Eq113", "VII", "arctan(5/(-.375+.5)) (degrees)", atan(ex(numeric(40))) * 180 / Pi, "88.56");
  expect_printed_angle("Eq113", "VII", "phi (degrees)", atan(1 / d.free.cot_phi) * 180 / Pi, "91.14");
}

TEST(Eq114_CaseVII_ThetaM, GenericLoadMeasured) {
  const CaseDerivation& d = thesis_case("VII");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq114", "VII", "t coefficient", per_v0(d, f, 1, 0), "-26.4");
  expect_printed("Eq114", "VII", "coefficient of e^{-.5t}", per_v0(d, f, 0, numeric(-1, 2)), "158.475");
  expect_printed("Eq114", "VII", "constant per dtheta_m0", per_v0(d, f, 0, 0), "125.975");
  expect_printed("Eq114", "VII", "coefficient of e^{-.375t}", per_v0(d, f, 0, numeric(-3, 8)), "-284.475");
}

TEST(Eq115_CaseVII_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("VII");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq115", "VII", "constant", per_v0(d, f, 0, 0), "-26.4");
  expect_printed("Eq115", "VII", "coefficient of e^{-.5t}", per_v0(d, f, 0, numeric(-1, 2)), "-79.238");
  expect_printed("Eq115", "VII", "coefficient of e^{-.375t}", per_v0(d, f, 0, numeric(-3, 8)), "106.638");
}

TEST(Eq116_Eq117_CaseVII_Load, DeceleratingLoad) {
  const CaseDerivation& d = thesis_case("VII");
  expect_printed("Eq116", "VII", "theta_L0 per dtheta_m0 (cot phi)", d.free.cot_phi, "-.025");
  expect_printed("Eq116", "VII", "drift amplitude JL/FL", -per_v0(d, d.free.load_position.solution, 0, numeric(-3, 8)), "2.668");
  expect_printed("Eq117", "VII", "velocity coefficient", per_v0(d, d.free.load_velocity.solution, 0, numeric(-3, 8)), "1");
}

// ---------------------------------------------------------------- Case VIII (eqs. 118–129)

TEST(Eq121_CaseVIII_SeparationSlope, LoadDecelerationRatio) {
  expect_printed("Eq121", "VIII", "eta3", thesis_case("VIII").free.eta_separation, "-.125");
}

TEST(Eq123_Eq125_CaseVIII_SeparationAngle, Phi) {
  const CaseDerivation& d = thesis_case("VIII");
  const CaseParameters& p = d.parameters;
  expect_printed("Eq123", "VIII", "Fm/Jm", p.Fm / p.Jm, "1.5");
  expect_printed("Eq123", "VIII", "K/Jm", p.K / p.Jm, "5");
  expect_printed_angle("Eq125", "VIII", "arctan(5/1.375) (degrees)", atan(ex(numeric(40, 11))) * 180 / Pi, "74.6");
  expect_printed_angle("Eq125", "VIII", "phi (degrees)", atan(1 / d.free.cot_phi) * 180 / Pi, "105.4");
}

TEST(Eq126_CaseVIII_ThetaM, GenericLoadMeasured) {
  const CaseDerivation& d = thesis_case("VIII");
  const TimeFunction& f = d.free.motor_position.solution;
  expect_printed("Eq126", "VIII", "t coefficient", per_v0(d, f, 1, 0), "-25.75");
  expect_printed("Eq126", "VIII", "constant per dtheta_m0", per_v0(d, f, 0, 0), "231.581");
  expect_printed("Eq126", "VIII", "coefficient of e^{-1.5t}", per_v0(d, f, 0, numeric(-3, 2)), "1.564");
  expect_printed("Eq126", "VIII", "coefficient of e^{-.125t}", per_v0(d, f, 0, numeric(-1, 8)), "-233.42");
}

TEST(Eq127_CaseVIII_DThetaM, Velocity) {
  const CaseDerivation& d = thesis_case("VIII");
  const TimeFunction& f = d.free.motor_velocity.solution;
  expect_printed("Eq127", "VIII", "coefficient of e^{-1.5t}", per_v0(d, f, 0, numeric(-3, 2)), "-2.34");
  expect_printed("Eq127", "VIII", "coefficient of e^{-.125t}", per_v0(d, f, 0, numeric(-1, 8)), "29.08");
  expect_printed("Eq127", "VIII", "constant", per_v0(d, f, 0, 0), "-25.74");
}

TEST(Eq128_Eq129_CaseVIII_Load, DeceleratingLoad) {
  const CaseDerivation& d = thesis_case("VIII");
  expect_printed("Eq128", "VIII", "theta_L0 per dtheta_m0 (cot phi)", d.free.cot_phi, "-.275");
  expect_printed("Eq128", "VIII", "drift amplitude JL/FL", -per_v0(d, d.free.load_position.solution, 0, numeric(-1, 8)), "8");
  expect_printed("Eq129", "VIII", "velocity coefficient", per_v0(d, d.free.load_velocity.solution, 0, numeric(-1, 8)), "1");
}


// ---------------------------------------------------------------- Laplace forms of cases I, II and the separation isoclines

TEST(Eq49_CaseI_ThetaMLaplace, ClosedLoopMotorTransform) {
  // Θm = (1.666/s + s θm0 + .8 θm0 + θ̇m0)/(s² + .8 s + 1.666), θm0 = 1 on case I's separation line.
  const CaseDerivation& d = thesis_case("I");
  const ex k = d.parameters.K / d.parameters.Jm, a = d.parameters.Fm / d.parameters.Jm, theta0 = d.free.separation_theta;
  const ex eq49 = (k / s() + s() * theta0 + a * theta0 + v0()) / (s() * s() + a * s() + k);
  EXPECT_TRUE(same(d.free.motor_position.laplace, eq49)) << "returned " << d.free.motor_position.laplace;
  expect_printed("Eq49", "I", "K/Jm", k, "1.666");
  expect_printed("Eq49", "I", "Fm/Jm", a, ".8");
}

TEST(Eq61_CaseII_ThetaMLaplace, ClosedLoopMotorTransform) {
  // Printed "(2/s + θ̇m0 + 5θm0 + .4θm0)/(s² + .4s + 2)": the "5θm0" is the OCR of "sθm0".
  const CaseDerivation& d = thesis_case("II");
  const ex theta0 = d.free.separation_theta;
  const ex eq61 = (2 / s() + v0() + s() * theta0 + numeric(2, 5) * theta0) / (s() * s() + numeric(2, 5) * s() + 2);
  EXPECT_TRUE(same(d.free.motor_position.laplace, eq61)) << "returned " << d.free.motor_position.laplace;
}

// At separation the motor-alone isocline reads η2 + Fm/Jm = (K/Jm)(1 − θm0)/θ̇m0, i.e.
// θ̇m0/(1 − θm0) = (K/Jm)/(η2 + Fm/Jm); with η2 = η3 it is the separation line.
void expect_separation_isocline(const std::string& eq_friction, const std::string& eq_tangent, const std::string& id,
                                const char* friction, const char* gain) {
  const CaseDerivation& d = thesis_case(id);
  const CaseParameters& p = d.parameters;
  expect_printed(eq_friction, id, "Fm/Jm", p.Fm / p.Jm, friction);
  expect_printed(eq_friction, id, "K/Jm", p.K / p.Jm, gain);
  // The tangent at η2 = η3 is −1/cot φ (θ̇/(1 − θ) on θ = 1 + cot φ θ̇).
  const ex tangent = (p.K / p.Jm) / (d.free.eta_separation + p.Fm / p.Jm);
  EXPECT_TRUE(same(tangent, -1 / d.free.cot_phi)) << eq_tangent << " case " << id << ": returned " << tangent;
}

TEST(Eq88_Eq90_CaseV_SeparationIsoclineForm, Coefficients) { expect_separation_isocline("Eq88", "Eq90", "V", "0.2", "2"); }
TEST(Eq99_Eq101_CaseVI_SeparationIsoclineForm, Coefficients) { expect_separation_isocline("Eq99", "Eq101", "VI", ".6", "2"); }
TEST(Eq110_Eq112_CaseVII_SeparationIsoclineForm, Coefficients) { expect_separation_isocline("Eq110", "Eq112", "VII", ".5", "5"); }
TEST(Eq122_Eq124_CaseVIII_SeparationIsoclineForm, Coefficients) { expect_separation_isocline("Eq122", "Eq124", "VIII", "1.5", "5"); }

// ---------------------------------------------------------------- every segment of every case verifies

TEST(Eq6_Eq15_Eq25_AllCases_ContactMode, ExactSolutionVerified) {
  for (const auto& id : backlash::model::thesis_case_ids()) {
    const CaseDerivation& d = thesis_case(id);
    EXPECT_TRUE(d.verified()) << "case " << id;
    EXPECT_EQ(d.contact_branch, ContactBranch::Underdamped) << "case " << id;
  }
}

TEST(Eq18_Eq24_AllCases_BranchSubstitution, GeneralBranchReproducesEachCase) {
  const auto branches = derive_general_branches();
  for (const auto& id : backlash::model::thesis_case_ids()) {
    const CaseDerivation& d = thesis_case(id);
    int matched = 0;
    for (const auto& branch : branches) {
      if (branch.name != contact_branch_name(d.contact_branch) && branch.name != free_branch_name(d.free_branch)) continue;
      std::string why;
      EXPECT_TRUE(reproduces_case(branch, d, &why)) << "case " << id << " branch " << branch.name << ": " << why;
      ++matched;
    }
    EXPECT_EQ(matched, 2) << "case " << id;
  }
}

TEST(ErrataLedger, EveryEntryBelongsToAThesisTest) {
  std::vector<std::string> names;
  const auto* unit = ::testing::UnitTest::GetInstance();
  for (int i = 0; i < unit->total_test_suite_count(); ++i) names.push_back(unit->GetTestSuite(i)->name());
  for (const std::string& where : backlash::testing::ledger_places()) {
    const bool symbolic_place = where.rfind("Eq", 0) == 0 || where == "Table1" || where == "Table2" || where == "Table6" ||
                                where == "Table7" || where == "Table17";
    if (!symbolic_place) continue;  // dividing-line tables and limit cycles are checked by numeric/ tests
    bool found = false;
    for (const std::string& n : names) found = found || n.rfind(where + "_", 0) == 0 || n.find("_" + where + "_") != std::string::npos;
    EXPECT_TRUE(found) << "ledger entry for " << where << " has no test named after it";
  }
}

}  // namespace
