// Emitting exact time functions as C++ and text/LaTeX (codegen-internal).
//
// Shared by the case emitter (emit.cpp) and the forced-mode emitter
// (emit_forced.cpp), so both parts of a case header follow one set of
// conventions: a term's coefficient is split into monomials of the runtime
// arguments, every exp/cos/sin is hoisted into a named constant (decaying
// rational rates that are small multiples of a common rate share one exp by
// binary powering), exact rationals print as "p.0/q.0", irrational constants
// are correctly rounded from 40 digits, and terms are sorted (non-oscillating
// first, slower decay first, lower frequency, power of t, cos before sin).
#pragma once

#include "backlash/symbolic/exact.hpp"
#include "backlash/symbolic/time_function.hpp"

#include "printer.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::codegen::detail {

/// `raw` with every character that is not a letter or digit replaced by '_'.
std::string identifier(const std::string& raw);

/// The name of the constant exp(r t) for a rational rate r: "e_m1_5" for r = -1/5.
std::string rate_name(const GiNaC::numeric& r);

/// coefficient × factor, both printed in `style` (a sum coefficient parenthesised).
std::string product_text(const std::string& coefficient, bool coefficient_is_sum, const std::string& factor,
                         Style style);

/// t^k · e^{rate t} · cos/sin(frequency t), exact parts given explicitly; "" for 1.
std::string factor_text(unsigned t_power, const GiNaC::ex& rate, symbolic::Oscillation oscillation,
                        const GiNaC::ex& frequency, Style style);

/// A runtime argument of an emitted function.
struct Input {
  GiNaC::ex sym;  // an ex, not a GiNaC::symbol: slicing a realsymbol would change its identity
  std::string name;
};

/// An exact number times a product of powers of the inputs.
struct Monomial {
  std::vector<unsigned> powers;  // per input
  std::string literal;           // C++; "" for 1, "-" for -1
  GiNaC::ex exact;               // exact value (radicals explicit)
};

/// (sum of monomials) · t^k · e^{rate t} · cos/sin(frequency t).
struct Term {
  std::vector<Monomial> monomials;
  unsigned t_power = 0;
  int rate = -1;  // index into the emitter's rates; -1: rate 0
  symbolic::Oscillation oscillation = symbolic::Oscillation::None;
  int frequency = -1;  // index into the emitter's frequencies
};

/// A rate or a frequency of the emitted code: its exact value and its C++ name and literal.
struct Constant {
  GiNaC::ex exact, value_exact;  // with radical symbols / explicit
  double value = 0;
  std::string name, literal;
};
using Rate = Constant;
using Frequency = Constant;

/// C++ of one monomial: "1.0", "(-1.0)", "x", "-x*y", "2.0*x".
std::string monomial_code(const Monomial& m, const std::vector<Input>& inputs);

/// "double t, double <input>…".
std::string parameter_list(const std::vector<Input>& inputs);

/// "(void)t;" / "(void)<input>;" lines for what none of `all` uses.
std::string unused_markers(const std::vector<const std::vector<Term>*>& all, const std::vector<Input>& inputs);

/// Converts time functions into sorted terms, collecting (and naming) the rates and
/// frequencies they use, and prints them.  One instance per emitted scope: the
/// names of rates and frequencies are unique within it.
class TermEmitter {
 public:
  /// `radicals` must outlive the emitter.
  explicit TermEmitter(const symbolic::RadicalList& radicals) : radicals_(radicals) {}

  /// The expression with the radicals written as square roots, expanded.
  GiNaC::ex explicit_value(const GiNaC::ex& e) const;
  /// C++ literal of an exact number: exact rational as "p.0/q.0", else correctly rounded.
  std::string literal_of(const GiNaC::ex& exact_number) const;

  /// The terms of `f` (combined, split over `inputs`, sorted); registers their rates and frequencies.
  std::vector<Term> convert(const symbolic::TimeFunction& f, const std::vector<Input>& inputs);

  /// C++ of a sum of terms, one term a line after the first (continuation lines start with `indent`).
  std::string sum_code(const std::vector<Term>& terms, const std::vector<Input>& inputs,
                       const std::string& indent) const;
  /// The exact sum in `style` (Text or Latex).
  std::string exact_text(const std::vector<Term>& terms, const std::vector<Input>& inputs, Style style) const;
  /// The hoisted "const double e_… / cos_… / sin_…" lines of a function computing `all`.
  std::string constants_for(const std::vector<const std::vector<Term>*>& all) const;
  /// The "inline constexpr double <frequency> = …;" block ("" if there are no frequencies).
  std::string frequency_constants() const;

  const std::vector<Rate>& rates() const { return rates_; }
  const std::vector<Frequency>& frequencies() const { return frequencies_; }

 private:
  const symbolic::RadicalList& radicals_;
  std::vector<Rate> rates_;
  std::vector<Frequency> frequencies_;

  int find(const std::vector<Constant>& known, const GiNaC::ex& value) const;  // index, or -1
  Constant constant(const GiNaC::ex& value) const;                            // unnamed
  int rate_index(const GiNaC::ex& rate);
  int frequency_index(const GiNaC::ex& frequency);
  void split(const GiNaC::ex& c, const std::vector<Input>& inputs, std::size_t level, std::vector<unsigned>& powers,
             std::vector<Monomial>& out) const;
  std::string term_code(const Term& term, const std::vector<Input>& inputs) const;
};

}  // namespace backlash::codegen::detail
