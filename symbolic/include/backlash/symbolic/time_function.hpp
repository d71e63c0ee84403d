// backlash/symbolic/time_function.hpp — exact solutions of linear segments.
//
// The inverse Laplace transform of a proper rational function is a finite sum
// of exponential-polynomial terms
//     c · t^k · e^{r t} · {1, cos ω t, sin ω t}
// (thesis eqs. 51–55, 62–65, 70–73, 77–79, 92–94, 102–105, 114–117, 126–129
// are all of this form).  A TimeFunction keeps that structure — coefficients,
// powers, rates and frequencies stay exact and separately addressable — so a
// solution can be differentiated, checked against its ODE term by term,
// compared with the thesis coefficient by coefficient, and emitted as code.
#pragma once

#include "backlash/symbolic/exact.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace backlash::symbolic {

enum class Oscillation { None, Cos, Sin };

/// coefficient · t^t_power · e^{rate·t} · (1 | cos(frequency·t) | sin(frequency·t))
struct ExpTerm {
  GiNaC::ex coefficient;
  unsigned t_power = 0;
  GiNaC::ex rate = 0;
  Oscillation oscillation = Oscillation::None;
  GiNaC::ex frequency = 0;  ///< a radical symbol (or 0 when oscillation is None)
};

class TimeFunction {
 public:
  TimeFunction() = default;
  explicit TimeFunction(std::vector<ExpTerm> terms) : terms_(std::move(terms)) {}
  static TimeFunction constant(const GiNaC::ex& value);

  const std::vector<ExpTerm>& terms() const { return terms_; }

  TimeFunction derivative() const;
  TimeFunction operator+(const TimeFunction& other) const;
  TimeFunction operator-(const TimeFunction& other) const;
  TimeFunction operator*(const GiNaC::ex& factor) const;

  /// Like terms merged, coefficients simplified, zero terms dropped, terms in a
  /// stable order (non-oscillating before oscillating, slower decay first, then
  /// power of t).
  TimeFunction combined(const RadicalList& radicals) const;
  /// Exactly the zero function (after combining like terms).
  bool is_zero(const RadicalList& radicals) const;

  /// Value at t = 0 (exact).
  GiNaC::ex at_zero() const;
  /// Coefficient of t^k e^{rate t} {1,cos,sin}; 0 if absent (after combining).
  GiNaC::ex coefficient(unsigned t_power, const GiNaC::ex& rate, Oscillation oscillation,
                        const RadicalList& radicals) const;

  /// The expression in t (radicals stay symbols).
  GiNaC::ex to_ex(const GiNaC::ex& t) const;
  /// Apply a substitution to coefficients, rates and frequencies.
  TimeFunction subs(const GiNaC::exmap& substitution) const;

 private:
  std::vector<ExpTerm> terms_;
};

}  // namespace backlash::symbolic
