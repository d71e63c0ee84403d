// backlash/symbolic/exact.hpp — exact arithmetic on GiNaC expressions with
// square roots kept as symbols.
//
// GiNaC silently turns sqrt(numeric) into a float and does not canonicalise
// square roots (sqrt(X/J²) vs sqrt(X)/J), so every square root in backlash is
// a Radical: a fresh positive symbol r with the defining relation r² = square
// (square free of radicals).  Damped frequencies (ω = sqrt(K/J − F²/4J²)),
// over-damped half-splits (δ) and, internally, the imaginary unit (i² = −1)
// are all radicals.  Expressions are polynomials in the radicals with
// rational-function coefficients; `simplify` reduces every radical to degree
// ≤ 1 in the numerator and rationalises the denominator, so an expression is
// zero exactly when `simplify` returns 0.
#pragma once

#include "backlash/model/case_spec.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::symbolic {

/// r > 0 with r² = square.  `role` says what it is ("ω_c: damped frequency ...").
struct Radical {
  GiNaC::symbol symbol;
  GiNaC::ex square;
  std::string role;
};
using RadicalList = std::vector<Radical>;

/// The imaginary unit as a radical (square −1); used inside residue
/// computations only, never in results.
const Radical& imaginary_unit();

/// Exact conversion of a case file's rational (never through a double).
GiNaC::numeric to_numeric(const model::Rational& value);

/// Reduce every radical of `radicals` to degree ≤ 1 in an expanded polynomial.
GiNaC::ex reduce_radical_powers(const GiNaC::ex& polynomial, const RadicalList& radicals);

/// Canonical exact form: normal form, radicals of degree ≤ 1 in the numerator,
/// no radical in the denominator.
GiNaC::ex simplify(const GiNaC::ex& expression, const RadicalList& radicals);

/// True iff `expression` is exactly zero given the radicals' relations.
/// (Only a genuine zero returns true; radicals are treated as independent.)
bool is_exactly_zero(const GiNaC::ex& expression, const RadicalList& radicals);

/// sqrt of a non-negative rational in canonical form a/q·sqrt(r) (so sqrt(113/75)
/// prints as 1/15*sqrt(339)); r is free of square factors below 2^16 and is not a
/// perfect square, so a rational root is always recognised; a symbolic square
/// gives sqrt(square).
GiNaC::ex canonical_sqrt(const GiNaC::ex& square);

/// Substitute each radical symbol by its canonical square root.
GiNaC::ex with_explicit_radicals(const GiNaC::ex& expression, const RadicalList& radicals);

/// Numerical value (radicals substituted, evaluated with CLN at `digits` digits).
double to_double(const GiNaC::ex& expression, const RadicalList& radicals);

/// Decimal text with `significant` significant digits (exact input evaluated at
/// high precision first).
std::string decimal_text(const GiNaC::ex& expression, const RadicalList& radicals, int significant = 15);

/// GiNaC's text of an expression, as a std::string.
std::string text(const GiNaC::ex& expression);
/// GiNaC's LaTeX of an expression.
std::string latex(const GiNaC::ex& expression);

/// Find a radical whose square equals `square` (exactly), or null.
const Radical* find_radical_with_square(const RadicalList& radicals, const GiNaC::ex& square);

}  // namespace backlash::symbolic
