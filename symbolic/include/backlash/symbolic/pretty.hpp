// backlash/symbolic/pretty.hpp — canonical printing of exact expressions:
// plain text (GiNaC syntax, parseable) and LaTeX in the thesis's notation.
//
// GiNaC orders the operands of sums and products by hash values that change
// from run to run (address-space randomisation), and normal() may return a
// fraction with either sign, so its own printers give different text for the
// same expression.  This printer never relies on GiNaC's order: an expression
// is brought to one fraction N/D of expanded polynomials, every monomial is
// read into (rational coefficient, atoms with exponents), and monomials and
// atoms are sorted by a fixed key:
//   atoms    s, t, θ̇m0, θo0, θ̇o0, θo, θ̇o (the "variables", collected), then
//            θR, Jm, JL, Fm, FL, K, ω/δ and other symbols, √n, π, functions;
//   sums     by the variables (s: descending powers; the others ascending,
//            constant first), the rest in lexicographic order of exponents;
//   scale    D has integer coefficients with gcd 1 and a positive leading
//            monomial; N/1 is printed as a polynomial with rational coefficients.
// So the same expression always prints the same bytes.
//
// LaTeX: \frac, \sqrt, e^{-3t/5}, \omega_c, \dot\theta_{m0}, \cos, \arctan …;
// long sums can be broken over lines by `display`.
#pragma once

#include "backlash/symbolic/exact.hpp"
#include "backlash/symbolic/time_function.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::symbolic::pretty {

enum class Style { Text, Latex };

struct Format {
  Style style = Style::Latex;
  int significant = 0;  ///< 0: exact; > 0: numbers as decimals with this many significant digits
};
inline constexpr Format latex_exact{Style::Latex, 0};
inline constexpr Format text_exact{Style::Text, 0};

/// The expression, canonically ordered.
std::string print(const GiNaC::ex& expression, const Format& format = latex_exact);
inline std::string text(const GiNaC::ex& e) { return print(e, text_exact); }
inline std::string latex(const GiNaC::ex& e) { return print(e, latex_exact); }

/// LaTeX of a symbol name: "Jm" → "J_m", "omega_c" → "\omega_c", "dtheta_m0" → "\dot\theta_{m0}".
std::string latex_symbol_name(const std::string& name);

/// A double with `significant` significant digits, trailing zeros dropped ("0.4",
/// "-126.311", "1.26e-12" as text; "1.26\times10^{-12}" in LaTeX).
std::string decimal(double value, int significant, Style style = Style::Latex);

/// A term of a sum: its sign and its body (printed without the sign).
struct Summand {
  bool negative = false;
  std::string body;
};
/// Join summands: "a - b + c".
std::string join(const std::vector<Summand>& terms, Style style = Style::Latex);

/// The summands of an expression: a polynomial's monomials (collected by the
/// variables), else the expression as one summand.
std::vector<Summand> summands(const GiNaC::ex& expression, const Format& format = latex_exact);
/// The expression as one factor: a sum in parentheses with its content pulled
/// out ("\frac{\sqrt{6}}{12}\left(\theta_{o0} - 1\right)"), the sign separate.
Summand factor(const GiNaC::ex& expression, const Format& format = latex_exact);

/// The summands of a time function, one per exponential-polynomial term, in a
/// stable order (non-oscillating first, slower decay first, then power of t;
/// cos before sin).  Coefficients with explicit square roots; each
/// oscillation's frequency is printed as the radical's name (\omega_c) when
/// `frequency_names` is true, else as its value.  A coefficient that is a sum
/// of variables is factored: \frac{\sqrt{6}}{12}(\theta_{o0} + 5\dot\theta_{o0} - 1).
std::vector<Summand> time_function_terms(const TimeFunction& f, const RadicalList& radicals, const Format& format,
                                         bool frequency_names = true);
std::string time_function(const TimeFunction& f, const RadicalList& radicals, const Format& format,
                          bool frequency_names = true);

/// The terms of a time function sorted as in time_function_terms (the order
/// used by every printed form, JSON included).
std::vector<ExpTerm> sorted_terms(const TimeFunction& f, const RadicalList& radicals);

/// A rational function of s in lowest terms: numerator and denominator
/// expanded polynomials with integer coefficients (gcd 1), the denominator's
/// leading coefficient positive.  Symbolic coefficients are kept as they come.
struct RationalFunction {
  GiNaC::ex numerator, denominator;
};
RationalFunction rational_function(const GiNaC::ex& expression, const GiNaC::symbol& s);
std::string print(const RationalFunction& f, const Format& format = latex_exact);

/// A polynomial in s written as constant × product of its irreducible factors
/// (from find_poles), e.g. "s^{2}(5s + 1)(5s + 3)"; `factors` are (factor, multiplicity).
std::string factored(const GiNaC::ex& constant, const std::vector<std::pair<GiNaC::ex, unsigned>>& factors,
                     const Format& format = latex_exact);

/// A display equation "lhs = t1 + t2 …", broken after about `width` visible
/// characters into an aligned block; `tag` (e.g. "92") becomes \tag{92}.
std::string display(const std::string& lhs, const std::vector<Summand>& rhs, const std::string& tag = "",
                    std::size_t width = 78);
/// Rough visible width of LaTeX (commands count one character).
std::size_t visible_width(const std::string& latex);

}  // namespace backlash::symbolic::pretty
