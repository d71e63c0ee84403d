// backlash/symbolic/case_derivation.hpp — the exact derivation of one case.
//
// For a case (thesis notation, N = 1; output θo = θm for "motor", θL for "load"):
//
//  contact mode (eqs. 6, 15, 25)   J θo'' + F θo' + K θo = K θR,  J = Jm+JL, F = Fm+FL,
//      Θo(s) = [J(s θo0 + θ̇o0) + F θo0 + K θR/s] / (J s² + F s + K), symbolic θo0, θ̇o0;
//  separation line (eqs. 19, 45, 87–91, 98–101, 109–113, 121–125)
//      θo = θR + cot φ · θ̇o,  cot φ = (Jm FL − Fm JL)/(K JL);
//      on it the combined (η1), motor-alone (η2) and load (η3 = −FL/JL)
//      isocline slopes coincide — proved exactly here;
//  free mode from the separation point, θm(0) = θL(0) = θR + cot φ·θ̇m0,
//  θ̇m(0) = θ̇L(0) = θ̇m0 (eqs. 18–23):
//      load   ΘL(s) = θ0/s + θ̇m0/(s(s + FL/JL))                  (eqs. 22, 53, 64, 104)
//      motor, output at motor: Θm = [Jm(s θ0 + θ̇m0) + Fm θ0 + K θR/s]/(Jm s² + Fm s + K)  (eqs. 18, 20, 49)
//      motor, output at load:  Θm = [Jm(s θ0 + θ̇m0) + Fm θ0 + K(θR/s − ΘL)]/(Jm s² + Fm s)  (eqs. 40, 69)
//      velocities s Θ − θ(0)                                    (eqs. 21, 23, 41, 71)
//  recombination momentum balance (eq. 24)
//      (Jm + JL) θ̇o⁺ = Jm θ̇m + JL θ̇L;
//  stability constant (eq. 38), with a = F/2J, ω_c² = K/J − a², e = θR − θo,
//      C = sqrt(θ̇o² − (F/J) θ̇o e + (K/J) e²)/ω_c · exp((a/ω_c) · arctan((θ̇o − a e)/(e ω_c))).
//
// Every solution verifies itself exactly (ODE residual and initial conditions
// reduce to 0; each velocity equals the derivative of its position); a failed
// check throws VerificationError — never a silent result.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/exact.hpp"
#include "backlash/symbolic/time_function.hpp"

#include <ginac/ginac.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace backlash::symbolic {

/// The shared symbols of every derivation.
struct DerivationSymbols {
  GiNaC::symbol s;            ///< Laplace variable
  GiNaC::possymbol t;         ///< time since the segment began
  GiNaC::realsymbol dtheta_m0;  ///< θ̇m0: velocity on the separation line (the dividing-line parameter)
  GiNaC::realsymbol theta_o0, dtheta_o0;  ///< contact-mode initial state
  GiNaC::realsymbol theta_o, dtheta_o;    ///< phase-plane coordinates (isoclines, C)
};
const DerivationSymbols& derivation_symbols();

/// Physical parameters as exact GiNaC expressions (numbers for a case, symbols
/// for the general solutions).
struct CaseParameters {
  GiNaC::ex Jm, Fm, JL, FL, K, theta_R, backlash;
  model::MeasuredAt measured_at = model::MeasuredAt::Load;
};
CaseParameters exact_parameters(const model::CaseSpec& spec);

enum class ContactBranch { Underdamped, CriticallyDamped, Overdamped };
/// Pole structure of the free-mode motor/load solutions.
enum class FreeBranch {
  LoadGeneric,          ///< output at load: poles 0², −Fm/Jm, −FL/JL
  LoadNoLoadFriction,   ///< FL = 0: 0³, −Fm/Jm
  LoadNoMotorFriction,  ///< Fm = 0: 0³, −FL/JL
  LoadNoFriction,       ///< Fm = FL = 0: 0⁴
  LoadEqualRates,       ///< Fm/Jm = FL/JL: 0², (−Fm/Jm)²
  MotorUnderdamped, MotorUnderdampedNoLoadFriction,
  MotorCritical, MotorCriticalNoLoadFriction,
  MotorOverdamped, MotorOverdampedNoLoadFriction,
};
const char* to_string(ContactBranch branch);
const char* to_string(FreeBranch branch);
/// The branch is decided from the exact parameters (never guessed).
ContactBranch classify_contact(const CaseParameters& p);
FreeBranch classify_free(const CaseParameters& p);

struct VerificationCheck {
  std::string name;
  bool passed = false;
};

class VerificationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Segment {
  std::string name;        ///< e.g. "theta_m"
  std::string equations;   ///< thesis equation numbers it generalises
  GiNaC::ex laplace;       ///< its Laplace transform
  TimeFunction solution;   ///< its exact inverse
};

struct IsoclineRow {
  GiNaC::ex eta;            ///< trajectory slope θ̈/θ̇ (infinity as the symbol-free ex 1/0 is avoided: see is_infinite)
  bool is_infinite = false;
  bool is_vertical = false; ///< η = −F/J: the line θo = θR
  GiNaC::ex tangent;        ///< θ̇/(θ − θR) on the isocline, exact (0 for η = ∞)
  GiNaC::ex angle_degrees;  ///< arctan(tangent) in degrees in (−90°, 90°], exact (atan form)
};
struct IsoclineTable {
  std::string system;       ///< "combined" (η1) or "motor_alone" (η2)
  GiNaC::ex inertia, friction;  ///< J and F of that system (slope θ̇/(θ−θR) = −(K/J)/(η + F/J))
  std::vector<IsoclineRow> rows;
};
/// The thesis's η grid (Tables 1, 2, 6, 7, 17) plus the vertical and the load's η3.
std::vector<GiNaC::ex> default_isocline_slopes();
IsoclineTable isocline_table(const std::string& system, const GiNaC::ex& K, const GiNaC::ex& J, const GiNaC::ex& F,
                             const std::vector<GiNaC::ex>& etas);
/// The thesis's angle ψ = arctan(θ̇/(θ−θR)) of the isocline of slope η, degrees.
GiNaC::ex isocline_angle_degrees(const GiNaC::ex& eta, const GiNaC::ex& K, const GiNaC::ex& J, const GiNaC::ex& F);

struct StabilityConstant {
  bool applicable = false;      ///< contact mode under-damped (the log-spiral exists)
  GiNaC::ex C;                  ///< C(θo, θ̇o) of eq. 38 (principal arctan)
  GiNaC::ex dlnC_dt;            ///< d(ln C)/dt along contact trajectories, simplified: 0
  GiNaC::ex jump_factor;        ///< C(after)/C(before) when a trajectory crosses θo = θR: exp(−π a/ω_c)
  std::string region;           ///< where C is invariant, in words
};

/// Contact mode (eqs. 6, 15, 25) with symbolic initial state (θo0, θ̇o0).
struct ContactDerivation {
  Segment position, velocity;
  StabilityConstant stability;
};

/// Free mode from the separation line (eqs. 18–24, 39–41) as functions of (t, θ̇m0).
struct FreeDerivation {
  GiNaC::ex cot_phi;            ///< separation line θo = θR + cot φ θ̇o
  GiNaC::ex separation_theta;   ///< θ0 = θR + cot φ θ̇m0
  GiNaC::ex eta_separation;     ///< η1 = η2 = η3 = −FL/JL on the line
  Segment motor_position, motor_velocity, load_position, load_velocity;
  TimeFunction gap;             ///< θL − θm (thesis convention: 0 at separation, b at recombination)
  TimeFunction recombined_velocity;  ///< eq. 24: (Jm θ̇m + JL θ̇L)/(Jm + JL) at time t
};

/// Each derives and appends its exact checks (they do not throw; `derive` does).
ContactDerivation derive_contact(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks);
FreeDerivation derive_free(const CaseParameters& p, RadicalList& radicals, std::vector<VerificationCheck>& checks);

struct CaseDerivation {
  std::string case_id, name;
  CaseParameters parameters;
  RadicalList radicals;         ///< ω_c, ω_m, δ… with their defining squares
  ContactBranch contact_branch = ContactBranch::Underdamped;
  FreeBranch free_branch = FreeBranch::LoadGeneric;
  ContactDerivation contact;
  FreeDerivation free;
  std::vector<IsoclineTable> isoclines;  ///< "combined" (η1) and "motor_alone" (η2)
  std::vector<VerificationCheck> checks;

  bool verified() const;
};

/// Throws VerificationError naming every failed check.
void require_all_checks_passed(const std::string& what, const std::vector<VerificationCheck>& checks);

/// Derive everything for exact parameters (numbers, or symbols in a branch
/// parametrisation).  Throws VerificationError if any exact check fails.
CaseDerivation derive(const std::string& case_id, const std::string& name, const CaseParameters& parameters,
                      RadicalList radicals = {});
CaseDerivation derive_case(const model::CaseSpec& spec);

}  // namespace backlash::symbolic
