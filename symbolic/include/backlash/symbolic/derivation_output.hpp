// backlash/symbolic/derivation_output.hpp — a derivation as JSON, LaTeX, text
// and as document blocks (document.hpp) for the report's case pages.
//
// JSON (`backlash derive CASE --json`): parameters (exact and decimal), the
// radicals with their defining squares, every segment's Laplace form and
// exact solution (as one expression and as structured terms, each exact and
// decimal) with its steps (rational function, factored denominator, poles and
// partial-fraction coefficients), the separation line, the isocline tables,
// the momentum balance, the stability constant and the verification status
// with every check.  Every expression is printed canonically (pretty.hpp), so
// the output is byte-identical from run to run.
#pragma once

#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/document.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

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

/// The thesis's equation numbers for the places of a case's derivation, by slot:
///   contact_equation free_motor_equation free_load_equation combined_isocline
///   combined_isocline_line motor_isocline motor_equation_normalized separation_slope
///   separation_isocline separation_tangent separation_angle, and per segment X in
///   theta_o dtheta_o theta_m dtheta_m theta_L dtheta_L: X_transform X_factored
///   X_partial X (the time function).
/// A slot's value is printed in \tag{…} ("92", or "88, 89").
using EquationTags = std::map<std::string, std::string>;

/// The derivation of a case as document blocks: the model, the derivation of
/// every segment step by step, the separation line and isoclines, the momentum
/// balance, the stability constant and the exact checks.  Headings start at `level`.
doc::Document derivation_document(const CaseDerivation& derivation, const EquationTags& tags = {}, int level = 2);

/// The general solutions (one per pole-structure branch) as document blocks.
doc::Document general_document(const std::vector<GeneralBranch>& branches, int level = 2);

/// The model's numbers as the thesis writes them: a terminating decimal ("0.48")
/// when it has one of at most 8 digits, else a fraction.
std::string model_number_latex(const GiNaC::ex& value);

}  // namespace backlash::symbolic
