// backlash/symbolic/forced_modes.hpp — the exact forced modes of a case: the
// linear segments with a constant forcing that the effects (docs/effects.md:
// Coulomb friction, saturation, torque offset) add to the nominal model.
//
// Thesis notation, J = Jm + JL, F = Fm + FL; every solution is a displacement
// Δ = θ − θ(0) (never an absolute angle: the numeric layer forms gaps as
// differences of displacements) and the forcing is a runtime symbol:
//
//   contact_constant  J Δ'' + F Δ' = g,          Δ(0) = 0, Δ'(0) = w0      [t, w0, g]
//                     (contact with the drive clipped, or any constant torque g)
//   load_constant     JL Δ'' + FL Δ' = g,        Δ(0) = 0, Δ'(0) = v0      [t, v0, g]
//   motor_constant    Jm Δ'' + Fm Δ' = g,        Δ(0) = 0, Δ'(0) = v0      [t, v0, g]
//   motor_closed      Jm y'' + Fm y' + K y = 0,  y(0) = y0, y'(0) = v0     [t, y0, v0]
//                     (output at the motor, drive linear: y the deviation from the
//                     shifted equilibrium θR + (T0 − Tm·sm)/K); also Δ = y − y0
//   coupled           Jm Δm'' + Fm Δm' = −K (yL0 + ΔL(t)) + um,
//                     JL ΔL'' + FL ΔL' = uL,  Δm(0) = ΔL(0) = 0,
//                     Δm'(0) = vm0, ΔL'(0) = vL0                           [t, vm0, yL0, vL0, um, uL]
//                     (output at the load, drive linear: yL = θL − θR)
// motor_closed exists for cases measured at the motor, coupled for cases
// measured at the load (the other three for every case).
//
// Each solution comes from the residue inverse Laplace transform of its
// transformed ODE (inverse_laplace.hpp) and is verified exactly, twice: as a
// TimeFunction (residual and initial conditions reduce to 0 with the radicals'
// relations, velocities equal the derivatives of the displacements) and as an
// expression in t differentiated by GiNaC with the radicals written as square
// roots (normal(expand(residual)) and normal(expand(initial condition)) are 0).
// A failed check throws VerificationError.  Exact rationals only.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/document.hpp"
#include "backlash/symbolic/exact.hpp"
#include "backlash/symbolic/time_function.hpp"

#include <ginac/ginac.h>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace backlash::symbolic {

/// The runtime arguments of the forced solutions (their names are the C++
/// argument names of the generated code; TeX names for LaTeX).
struct ForcedSymbols {
  GiNaC::realsymbol w0;   ///< contact: initial velocity ω0
  GiNaC::realsymbol g;    ///< constant torque (contact, load, motor)
  GiNaC::realsymbol v0;   ///< free body: initial velocity
  GiNaC::realsymbol y0;   ///< motor_closed: initial deviation from the shifted equilibrium
  GiNaC::realsymbol vm0, yL0, vL0;  ///< coupled: θ̇m(0), θL(0) − θR, θ̇L(0)
  GiNaC::realsymbol um, uL;         ///< coupled: constant torques on the motor and on the load
};
const ForcedSymbols& forced_symbols();

/// One output of a forced mode: its Segment (name, Laplace transform, exact
/// solution), the LaTeX of its left-hand side (\Delta_L(t)) and its meaning.
struct ForcedOutput {
  Segment segment;
  std::string lhs_latex;
  std::string meaning;
};

/// One forced mode: its ODE, its runtime arguments (after t) and its outputs.
struct ForcedSolution {
  std::string name;                    ///< "contact_constant", …
  std::string meaning;                 ///< what the mode is, in words
  std::string equation;                ///< the ODE and initial state, plain text
  std::string equation_latex;          ///< the same in LaTeX
  std::vector<GiNaC::ex> arguments;    ///< runtime arguments after t, in order (symbols of forced_symbols())
  std::vector<std::string> argument_names;
  std::vector<ForcedOutput> outputs;   ///< e.g. displacement, velocity

  const ForcedOutput& output(const std::string& output_name) const;  ///< throws std::out_of_range
};

struct ForcedModes {
  std::string case_id, name;
  CaseParameters parameters;
  RadicalList radicals;                ///< the radicals the solutions use (frequencies, real half-splits)
  ForcedSolution contact_constant, load_constant, motor_constant;
  std::optional<ForcedSolution> motor_closed;  ///< output at the motor only
  std::optional<ForcedSolution> coupled;       ///< output at the load only
  std::vector<VerificationCheck> checks;

  /// The applicable solutions in a fixed order: contact_constant, load_constant,
  /// motor_constant, then motor_closed or coupled.
  std::vector<const ForcedSolution*> solutions() const;
  bool verified() const;
};

/// Derive and verify every applicable forced mode.  Throws VerificationError
/// if an exact check fails.  `radicals` seeds the radical list (pass a case
/// derivation's radicals to share its frequency symbols, e.g. ω_m).
ForcedModes derive_forced_modes(const std::string& case_id, const std::string& name, const CaseParameters& parameters,
                                RadicalList radicals = {});
ForcedModes derive_forced_modes(const model::CaseSpec& spec);
/// With the case derivation's radicals (the same ω_m symbol as its free mode).
ForcedModes derive_forced_modes(const CaseDerivation& derivation);

/// JSON for `backlash derive CASE --json` (key "forced_modes"): per mode its
/// equation, arguments, every output's Laplace form, exact and decimal solution
/// and structured terms; the radicals; the verification with every check.
nlohmann::json forced_modes_json(const ForcedModes& modes);

/// The forced modes as document blocks (headings from `level`), and as a LaTeX
/// section (no preamble) for `backlash derive CASE --latex`.
doc::Document forced_modes_document(const ForcedModes& modes, int level = 2);
std::string forced_modes_latex(const ForcedModes& modes);

}  // namespace backlash::symbolic
