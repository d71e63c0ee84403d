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
#include "backlash/symbolic/case_derivation.hpp"

#include <string>
#include <vector>

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

/// A file `codegen` writes: its name inside the output folder and its content.
struct GeneratedFile {
  std::string name;  ///< "case_V.hpp" (the evaluator), "case_V.tex" (its expressions)
  std::string content;
};

/// `codegen CASE`: the self-contained evaluator header of the case (namespace case_<ID>,
/// depends only on <cmath>: the closed forms of every segment with the case's numbers) and
/// the LaTeX of its expressions, in the order the CLI writes them.  std::runtime_error (one
/// line) if a verification of the derivation fails.
std::vector<GeneratedFile> generate_code(const Case& source);

/// The derivation as a structure, for a program that lays it out itself (the report's case
/// pages: segments, steps, isoclines, eq. 38's C; symbolic/case_derivation.hpp), with the
/// evaluator header `codegen` makes from it.
struct ExactCase {
  symbolic::CaseDerivation derivation;
  std::string header;  ///< case_<ID>.hpp, byte for byte as generate_code's
};
ExactCase derive_exact(const Case& source);

}  // namespace backlash::api
