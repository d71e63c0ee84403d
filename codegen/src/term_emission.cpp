#include "term_emission.hpp"

#include "backlash/symbolic/case_derivation.hpp"

#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>
#include <stdexcept>

namespace backlash::codegen::detail {

using namespace GiNaC;
using symbolic::ExpTerm;
using symbolic::Oscillation;
using symbolic::TimeFunction;

std::string identifier(const std::string& raw) {
  std::string out;
  for (char c : raw) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

std::string rate_name(const numeric& r) {
  std::ostringstream out;
  out << "e_" << (r.is_negative() ? "m" : "") << abs(r.numer());
  if (r.denom() != 1) out << "_" << r.denom();
  return out.str();
}

std::string product_text(const std::string& coefficient, bool coefficient_is_sum, const std::string& factor,
                         Style style) {
  if (factor.empty()) return coefficient;
  if (coefficient == "1") return factor;
  if (coefficient == "-1") return std::string("-") + factor;
  const std::string c = coefficient_is_sum
                            ? (style == Style::Latex ? std::string("\\left(") + coefficient + "\\right)"
                                                     : std::string("(") + coefficient + ")")
                            : coefficient;
  return c + (style == Style::Latex ? " " : "*") + factor;
}

std::string factor_text(unsigned t_power, const ex& rate, Oscillation oscillation, const ex& frequency, Style style) {
  const ex& t = symbolic::derivation_symbols().t;
  ex factor = pow(t, t_power);
  if (!rate.is_zero()) factor *= exp(rate * t);
  if (oscillation == Oscillation::Cos) factor *= cos(frequency * t);
  if (oscillation == Oscillation::Sin) factor *= sin(frequency * t);
  if (factor.is_equal(ex(1))) return "";
  return print(expanded(factor), style);
}

std::string monomial_code(const Monomial& m, const std::vector<Input>& inputs) {
  std::string variables;
  for (std::size_t i = 0; i < inputs.size(); ++i)
    for (unsigned k = 0; k < m.powers[i]; ++k) variables += (variables.empty() ? std::string() : std::string("*")) + inputs[i].name;
  if (variables.empty()) return m.literal.empty() ? std::string("1.0") : (m.literal == "-" ? std::string("(-1.0)") : m.literal);
  if (m.literal.empty()) return variables;
  if (m.literal == "-") return std::string("-") + variables;
  return m.literal + "*" + variables;
}

namespace {

bool uses_input(const std::vector<Term>& terms, std::size_t input) {
  for (const Term& t : terms)
    for (const Monomial& m : t.monomials)
      if (m.powers[input] > 0) return true;
  return false;
}

bool uses_time(const std::vector<Term>& terms) {
  for (const Term& t : terms)
    if (t.t_power > 0 || t.rate >= 0 || t.oscillation != Oscillation::None) return true;
  return false;
}

}  // namespace

std::string parameter_list(const std::vector<Input>& inputs) {
  std::string out = "double t";
  for (const Input& in : inputs) out += std::string(", double ") + in.name;
  return out;
}

std::string unused_markers(const std::vector<const std::vector<Term>*>& all, const std::vector<Input>& inputs) {
  std::string out;
  bool time = false;
  for (const auto* terms : all) time |= uses_time(*terms);
  if (!time) out += "  (void)t;\n";
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    bool used = false;
    for (const auto* terms : all) used |= uses_input(*terms, i);
    if (!used) out += std::string("  (void)") + inputs[i].name + ";\n";
  }
  return out;
}

// ------------------------------------------------------------------ TermEmitter

ex TermEmitter::explicit_value(const ex& e) const { return expanded(symbolic::with_explicit_radicals(e, radicals_)); }

std::string TermEmitter::literal_of(const ex& exact_number) const {
  const ex value = explicit_value(exact_number);
  if (is_a<numeric>(value) && ex_to<numeric>(value).is_rational()) return rational_literal(ex_to<numeric>(value));
  const double v = evaluate_to_double(value);
  const std::string lit = double_literal(v);
  return v < 0 ? std::string("(") + lit + ")" : lit;
}

int TermEmitter::find(const std::vector<Constant>& known, const ex& value) const {
  for (std::size_t i = 0; i < known.size(); ++i)
    if (symbolic::is_exactly_zero(known[i].exact - value, radicals_)) return static_cast<int>(i);
  return -1;
}

Constant TermEmitter::constant(const ex& value) const {
  Constant c;
  c.exact = value;
  c.value_exact = explicit_value(value);
  c.value = evaluate_to_double(c.value_exact);
  c.literal = literal_of(value);
  return c;
}

int TermEmitter::rate_index(const ex& rate) {
  if (symbolic::is_exactly_zero(rate, radicals_)) return -1;
  if (const int known = find(rates_, rate); known >= 0) return known;
  rates_.push_back(constant(rate));
  // names: rational rates by value (e_m1_5 = exp(-t/5)), irrational ones numbered by decreasing value
  std::vector<std::size_t> irrational;
  for (std::size_t i = 0; i < rates_.size(); ++i) {
    const ex& v = rates_[i].value_exact;
    if (is_a<numeric>(v) && ex_to<numeric>(v).is_rational()) rates_[i].name = rate_name(ex_to<numeric>(v));
    else irrational.push_back(i);
  }
  std::sort(irrational.begin(), irrational.end(),
            [&](std::size_t a, std::size_t b) { return rates_[a].value > rates_[b].value; });
  for (std::size_t k = 0; k < irrational.size(); ++k) rates_[irrational[k]].name = "e_r" + std::to_string(k + 1);
  return static_cast<int>(rates_.size() - 1);
}

int TermEmitter::frequency_index(const ex& frequency) {
  if (const int known = find(frequencies_, frequency); known >= 0) return known;
  Frequency f = constant(frequency);
  const std::string base = is_a<symbol>(frequency) ? identifier(ex_to<symbol>(frequency).get_name()) : "omega";
  std::string name = base;
  for (int k = 2; std::any_of(frequencies_.begin(), frequencies_.end(), [&](const Frequency& o) { return o.name == name; });
       ++k)
    name = base + "_" + std::to_string(k);
  f.name = name;
  frequencies_.push_back(f);
  return static_cast<int>(frequencies_.size() - 1);
}

void TermEmitter::split(const ex& c, const std::vector<Input>& inputs, std::size_t level, std::vector<unsigned>& powers,
                        std::vector<Monomial>& out) const {
  if (level == inputs.size()) {
    if (symbolic::is_exactly_zero(c, radicals_)) return;
    Monomial m;
    m.powers = powers;
    m.exact = explicit_value(c);
    m.literal = literal_of(c);
    if (m.literal == "1.0") m.literal = "";
    if (m.literal == "(-1.0)") m.literal = "-";
    out.push_back(m);
    return;
  }
  const ex& s = inputs[level].sym;
  if (c.ldegree(s) < 0) throw std::domain_error("codegen: negative power of " + inputs[level].name);
  const int degree = c.degree(s);
  for (int k = 0; k <= degree; ++k) {
    powers[level] = static_cast<unsigned>(k);
    split(c.coeff(s, k), inputs, level + 1, powers, out);
  }
  powers[level] = 0;
}

std::vector<Term> TermEmitter::convert(const TimeFunction& f, const std::vector<Input>& inputs) {
  std::vector<Term> out;
  const TimeFunction combined = f.combined(radicals_);
  for (const ExpTerm& term : combined.terms()) {
    Term t;
    t.t_power = term.t_power;
    t.rate = rate_index(term.rate);
    t.oscillation = term.oscillation;
    if (term.oscillation != Oscillation::None) t.frequency = frequency_index(term.frequency);
    std::vector<unsigned> powers(inputs.size(), 0);
    split(term.coefficient.expand(), inputs, 0, powers, t.monomials);
    if (!t.monomials.empty()) out.push_back(t);
  }
  // Stable order: non-oscillating first, slower decay first, lower frequency, power of t, cos before sin.
  std::stable_sort(out.begin(), out.end(), [&](const Term& a, const Term& b) {
    if ((a.oscillation == Oscillation::None) != (b.oscillation == Oscillation::None))
      return a.oscillation == Oscillation::None;
    const double ra = a.rate < 0 ? 0.0 : rates_[a.rate].value, rb = b.rate < 0 ? 0.0 : rates_[b.rate].value;
    if (ra != rb) return ra > rb;
    const double fa = a.frequency < 0 ? 0.0 : frequencies_[a.frequency].value;
    const double fb = b.frequency < 0 ? 0.0 : frequencies_[b.frequency].value;
    if (fa != fb) return fa < fb;
    if (a.t_power != b.t_power) return a.t_power < b.t_power;
    return static_cast<int>(a.oscillation) < static_cast<int>(b.oscillation);
  });
  return out;
}

std::string TermEmitter::term_code(const Term& term, const std::vector<Input>& inputs) const {
  std::string coefficient;
  if (term.monomials.size() == 1) {
    coefficient = monomial_code(term.monomials.front(), inputs);
  } else {
    std::vector<std::string> parts;
    for (const Monomial& m : term.monomials) parts.push_back(monomial_code(m, inputs));
    coefficient = std::string("(") + join_terms(parts) + ")";
  }
  std::vector<std::string> factors;
  for (unsigned k = 0; k < term.t_power; ++k) factors.push_back("t");
  if (term.rate >= 0) factors.push_back(rates_[term.rate].name);
  if (term.oscillation == Oscillation::Cos) factors.push_back(std::string("cos_") + frequencies_[term.frequency].name);
  if (term.oscillation == Oscillation::Sin) factors.push_back(std::string("sin_") + frequencies_[term.frequency].name);
  if (factors.empty()) return coefficient;
  std::string text = coefficient == "1.0" ? std::string() : (coefficient == "(-1.0)" ? std::string("-") : coefficient + "*");
  for (std::size_t i = 0; i < factors.size(); ++i) text += (i ? std::string("*") : std::string()) + factors[i];
  return text;
}

std::string TermEmitter::sum_code(const std::vector<Term>& terms, const std::vector<Input>& inputs,
                                  const std::string& indent) const {
  if (terms.empty()) return "0.0";
  std::string out;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const std::string t = term_code(terms[i], inputs);
    if (i == 0) out = t;
    else if (t.front() == '-') out += std::string("\n") + indent + "- " + t.substr(1);
    else out += std::string("\n") + indent + "+ " + t;
  }
  return out;
}

std::string TermEmitter::exact_text(const std::vector<Term>& terms, const std::vector<Input>& inputs, Style style) const {
  std::vector<std::string> parts;
  for (const Term& term : terms) {
    ex coefficient = 0;
    for (const Monomial& m : term.monomials) {
      ex monomial = m.exact;
      for (std::size_t i = 0; i < inputs.size(); ++i) monomial *= pow(inputs[i].sym, m.powers[i]);
      coefficient += monomial;
    }
    coefficient = expanded(coefficient);
    const ex rate = term.rate >= 0 ? rates_[term.rate].value_exact : ex(0);
    const ex frequency = term.frequency >= 0 ? frequencies_[term.frequency].value_exact : ex(0);
    parts.push_back(product_text(print(coefficient, style), is_a<add>(coefficient),
                                 factor_text(term.t_power, rate, term.oscillation, frequency, style), style));
  }
  return join_terms(parts);
}

std::string TermEmitter::constants_for(const std::vector<const std::vector<Term>*>& all) const {
  std::set<int> rates, cosines, sines;
  for (const auto* terms : all)
    for (const Term& t : *terms) {
      if (t.rate >= 0) rates.insert(t.rate);
      if (t.oscillation == Oscillation::Cos) cosines.insert(t.frequency);
      if (t.oscillation == Oscillation::Sin) sines.insert(t.frequency);
    }
  std::string out;
  std::vector<int> ordered(rates.begin(), rates.end());
  std::sort(ordered.begin(), ordered.end(), [&](int a, int b) { return rates_[a].value > rates_[b].value; });
  // Decaying rational rates that are small multiples (≤ 16) of a common rate g share one
  // exp: e^{-m g t} = (e^{-g t})^m by binary powering (≤ 4 multiplications,
  // relative error ≤ ~m ulp).  Others get their own exp.
  std::vector<int> rational;
  for (int r : ordered) {
    const ex& v = rates_[r].value_exact;
    if (is_a<numeric>(v) && ex_to<numeric>(v).is_rational() && ex_to<numeric>(v).is_negative()) rational.push_back(r);
  }
  std::set<int> shared;
  if (rational.size() >= 2) {
    numeric numerators = 0, denominators = 1;
    for (int r : rational) {
      const numeric v = abs(ex_to<numeric>(rates_[r].value_exact));
      numerators = gcd(numerators, v.numer());
      denominators = lcm(denominators, v.denom());
    }
    const numeric g = numerators / denominators;
    auto multiple = [&](int r) { return (abs(ex_to<numeric>(rates_[r].value_exact)) / g).to_long(); };
    long largest = 0;
    for (int r : rational) largest = std::max(largest, multiple(r));
    if (largest <= 16) {
      const std::string base = rate_name(-g);
      out += std::string("  const double ") + base + " = std::exp(" + rational_literal(-g) + "*t);\n";
      std::vector<std::string> powers{base};  // powers[k] = base^(2^k)
      for (long bit = 2; bit <= largest; bit *= 2) {
        const std::string name = base + "_p" + std::to_string(bit);
        out += std::string("  const double ") + name + " = " + powers.back() + "*" + powers.back() + ";\n";
        powers.push_back(name);
      }
      for (int r : rational) {
        const long m = multiple(r);
        shared.insert(r);
        if (rates_[r].name == base) continue;
        std::string product;
        for (std::size_t k = 0; k < powers.size(); ++k)
          if (m & (1L << k)) product += (product.empty() ? std::string() : std::string("*")) + powers[k];
        out += std::string("  const double ") + rates_[r].name + " = " + product + ";  // exp(" +
               print(rates_[r].value_exact, Style::Text) + "*t)\n";
      }
    }
  }
  for (int r : ordered)
    if (!shared.count(r))
      out += std::string("  const double ") + rates_[r].name + " = std::exp(" + rates_[r].literal + "*t);\n";
  for (int f : cosines)
    out += std::string("  const double cos_") + frequencies_[f].name + " = std::cos(" + frequencies_[f].name + "*t);\n";
  for (int f : sines)
    out += std::string("  const double sin_") + frequencies_[f].name + " = std::sin(" + frequencies_[f].name + "*t);\n";
  return out;
}

std::string TermEmitter::frequency_constants() const {
  if (frequencies_.empty()) return "";
  std::ostringstream h;
  h << "// Frequencies (square roots of exact rationals, correctly rounded).\n";
  for (const Frequency& f : frequencies_)
    h << "inline constexpr double " << f.name << " = " << f.literal << ";  // " << print(f.value_exact, Style::Text) << "\n";
  h << "\n";
  return h.str();
}

}  // namespace backlash::codegen::detail
