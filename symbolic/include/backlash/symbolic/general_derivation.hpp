// backlash/symbolic/general_derivation.hpp — the general parametric solutions.
//
// With Jm, Fm, JL, FL, K, θR symbolic, the inverse transforms depend on the
// pole structure, and GiNaC cannot decide the sign of a symbolic discriminant.
// So the engine enumerates the branches and derives each in a parametrisation
// that makes its pole structure explicit:
//
//   contact mode (J s² + F s + K, J = Jm+JL, F = Fm+FL):
//     contact_underdamped   K = J(ω_c² + F²/4J²),  ω_c = sqrt(K/J − F²/4J²) > 0
//     contact_critical      K = F²/4J
//     contact_overdamped    K = J(F²/4J² − δ_c²),  δ_c = sqrt(F²/4J² − K/J) > 0
//   free mode, output at load (s² (Jm s + Fm)(JL s + FL)):
//     load_generic, load_FL0 (FL = 0), load_Fm0 (Fm = 0), load_Fm0_FL0,
//     load_equal_rates (FL = Fm·JL/Jm)
//   free mode, output at motor (Jm s² + Fm s + K, load s(JL s + FL)):
//     motor_underdamped / motor_critical / motor_overdamped (ω_m, δ_m as above
//     with Jm, Fm), each also with FL = 0 (the load drifts without decelerating).
//
// Every branch verifies itself exactly like a case, and `reproduces_case`
// proves that substituting a case's numbers into the branch the engine
// selects for it gives that case's own derivation, term by term.
#pragma once

#include "backlash/symbolic/case_derivation.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::symbolic {

/// The symbolic physical parameters of the general solutions.
struct GeneralSymbols {
  GiNaC::possymbol Jm, Fm, JL, FL, K;
  GiNaC::realsymbol theta_R;
};
const GeneralSymbols& general_symbols();

/// A positive parameter that replaces K in a branch, with its definition.
struct BranchParameter {
  GiNaC::possymbol symbol;
  GiNaC::ex square_in_physical_parameters;  ///< e.g. ω_c² = K/J − F²/(4J²)
  std::string meaning;
};

struct GeneralBranch {
  enum class Mode { Contact, Free };
  std::string name;             ///< "contact_underdamped", "load_generic", "motor_critical_FL0", …
  Mode mode = Mode::Contact;
  std::string condition;        ///< where it applies, e.g. "F^2 < 4*J*K"
  CaseParameters parameters;    ///< the symbolic parameters with the branch substitution applied
  GiNaC::exmap substitution;    ///< physical parameter → branch expression (e.g. K → …)
  std::vector<BranchParameter> branch_parameters;
  ContactDerivation contact;    ///< when mode == Contact
  FreeDerivation free;          ///< when mode == Free
  std::vector<VerificationCheck> checks;
};

/// All 14 branches (3 contact, 5 load-measured free, 6 motor-measured free),
/// derived and verified; throws VerificationError if any check fails.
std::vector<GeneralBranch> derive_general_branches();

/// Name of the branch that applies to a case: its contact branch, and its free branch.
std::string contact_branch_name(ContactBranch branch);
std::string free_branch_name(FreeBranch branch);

/// True iff the branch's solutions with the case's numbers substituted equal
/// the case's own derivation exactly (each segment, term by term).  `why`
/// receives the first mismatch.
bool reproduces_case(const GeneralBranch& branch, const CaseDerivation& derivation, std::string* why = nullptr);

}  // namespace backlash::symbolic
