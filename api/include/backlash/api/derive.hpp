// backlash/api/derive.hpp — the exact derivation of a case (target backlash::api_derive,
// which links GiNaC/CLN; backlash/api/backlash.hpp alone never does).
//
// For a case (backlash/api/backlash.hpp: load("V"), a file, or numbers given in code):
// every segment of the hybrid model — contact θo(t), θ̇o(t); free flight θm, θ̇m, θL, θ̇L
// from the separation point — solved exactly by residues of its Laplace form (real
// poles of any multiplicity, complex pairs as e^{αt}(P cos ωt + Q sin ωt), irrational
// roots as named radicals, never floats), each solution verified exactly (ODE residual
// and initial conditions reduce to 0; a failed check is an error); the separation line
// θo = θR + cot φ·θ̇o, the isocline tables, eq. 38's stability constant C, and the modes
// the effects add (constant torques, the closed motor loop, coupled free flight).
// symbolic/include/backlash/symbolic/derivation_output.hpp documents the content.
//
// Output is byte-identical from run to run (canonical printing).
// GiNaC is not thread-safe: these functions take one process-wide lock, so calls from
// several threads run one after the other (for parallel derivations use processes).
#pragma once

#include "backlash/api/backlash.hpp"

#include <string>

namespace backlash::api {

/// One case's derivation, as the CLI prints it (final newline included).
struct Derivation {
  std::string case_id;
  std::string text;   ///< `derive CASE`: plain text for a terminal
  std::string latex;  ///< `derive CASE --latex`: a LaTeX section (no preamble), forced modes included
  std::string json;   ///< `derive CASE --json`: parameters, radicals, segments with their steps,
                      ///< separation line, isoclines, C, verification, "forced_modes"
};

/// Derives `source` exactly.  std::runtime_error (one line) if a verification fails.
Derivation derive(const Case& source);

/// `derive general`: the 14 parametric pole-structure branches.
struct GeneralDerivation {
  std::string latex;  ///< `derive general`
  std::string json;   ///< `derive general --json`: an array, one entry per branch
};
GeneralDerivation derive_general();

}  // namespace backlash::api
