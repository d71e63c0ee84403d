// backlash/symbolic/derivation_output.hpp — a derivation as JSON, LaTeX and text.
//
// JSON (`backlash derive CASE --json`): parameters (exact and decimal), the
// radicals with their defining squares, every segment's Laplace form and
// exact solution (as one expression and as structured terms, each exact and
// decimal), the separation line, the isocline tables, the momentum balance,
// the stability constant and the verification status with every check.
#pragma once

#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace backlash::symbolic {

nlohmann::json to_json(const CaseDerivation& derivation);
nlohmann::json to_json(const GeneralBranch& branch);

/// A LaTeX section (no preamble) with every equation of the derivation.
std::string to_latex(const CaseDerivation& derivation);
std::string to_latex(const GeneralBranch& branch);

/// Plain text for a terminal.
std::string to_text(const CaseDerivation& derivation);

/// A time function as one exact expression in t (radicals written as square roots).
std::string exact_text(const TimeFunction& f, const RadicalList& radicals);
/// The same with decimal coefficients (10 significant digits).
std::string decimal_text(const TimeFunction& f, const RadicalList& radicals);

}  // namespace backlash::symbolic
