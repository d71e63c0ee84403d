// Printing exact GiNaC expressions canonically (codegen-internal).
//
// GiNaC's term order depends on hash values that change from run to run, and
// normal() may return a fraction with either sign, so its own printers do not
// give stable text.  This printer sorts the operands of every sum and product
// by their printed text, and canonical_fraction() fixes a rational function's
// numerator/denominator scale, so the same expression always prints the same.
// Styles: C++ (double arithmetic: rationals as "p.0/q.0", never integer
// division; integer powers as products), plain text (GiNaC-like) and LaTeX.
// A floating-point number in the input is an error.
#pragma once

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::codegen::detail {

enum class Style { Cpp, Text, Latex };

/// The expression in `style`, operands sorted.
std::string print(const GiNaC::ex& expression, Style style);

/// A rational function as expanded numerator / expanded denominator, scaled so
/// that the denominator's first monomial (in printed order of its variables)
/// has coefficient 1 — unique whatever form normal() returned.
struct Fraction {
  GiNaC::ex numerator, denominator;
};
Fraction canonical_fraction(const GiNaC::ex& expression);
std::string print(const Fraction& fraction, Style style);

/// Sum of already printed terms, "+ -x" written "- x" (order kept); "0" if none.
std::string join_terms(const std::vector<std::string>& terms);

/// Shortest text that reads back as exactly `value` (≤ 17 significant digits),
/// always a floating literal ("2.0", "0.20000000000000001", "1e-20").
std::string double_literal(double value);

/// An exact rational as C++: "28.0", "(-56.0/3.0)"; when p or q is not exact
/// in a double, the correctly rounded value as a literal.
std::string rational_literal(const GiNaC::numeric& value);

/// True for a rational whose numerator and denominator are exact in a double.
bool fits_double_exactly(const GiNaC::numeric& rational);

/// Correctly rounded double of an exact real expression (evaluated at 40 digits).
double evaluate_to_double(const GiNaC::ex& expression);

/// expand() including function arguments: a canonical sum of monomials.
GiNaC::ex expanded(const GiNaC::ex& expression);

}  // namespace backlash::codegen::detail
