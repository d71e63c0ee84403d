#include "backlash/codegen/emit_forced.hpp"

#include "backlash/symbolic/escape.hpp"

#include "printer.hpp"

#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>
#include <stdexcept>

namespace backlash::codegen {

using namespace GiNaC;
using detail::double_literal;
using detail::evaluate_to_double;
using detail::expanded;
using detail::print;
using detail::rational_literal;
using detail::Style;
using symbolic::ExpTerm;
using symbolic::ForcedModes;
using symbolic::ForcedOutput;
using symbolic::ForcedSolution;
using symbolic::Oscillation;
using symbolic::TimeFunction;

namespace {

// The term machinery follows the case emitter's (emit.cpp) so the forced block
// reads like the rest of the header: a coefficient is split into monomials of
// the runtime arguments, exponentials and oscillations are hoisted, terms are
// sorted (non-oscillating first, slower decay first, lower frequency, power of t,
// cos before sin).

struct Input {
  ex sym;  // an ex, not a GiNaC::symbol: slicing a realsymbol would change its identity
  std::string name;
};

struct Monomial {
  std::vector<unsigned> powers;  // per input
  std::string literal;           // C++; "" for 1, "-" for -1
  ex exact;                      // exact value (radicals explicit)
};

struct Term {
  std::vector<Monomial> monomials;
  unsigned t_power = 0;
  int rate = -1;  // index into rates; -1: rate 0
  Oscillation oscillation = Oscillation::None;
  int frequency = -1;
};

struct Rate {
  ex exact, value_exact;
  double value = 0;
  std::string name, literal;
};

struct Frequency {
  ex exact, value_exact;
  double value = 0;
  std::string name, literal;
};

struct Output {
  const ForcedOutput* source;
  std::vector<Term> terms;
};

struct Mode {
  const ForcedSolution* source;
  std::vector<Input> inputs;
  std::vector<Output> outputs;
};

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

// Sum of printed terms, "+ -x" written "- x" (order kept).
std::string join_terms(const std::vector<std::string>& terms) {
  if (terms.empty()) return "0";
  std::string out;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const std::string& t = terms[i];
    if (i == 0) out = t;
    else if (t.rfind("-", 0) == 0) out += std::string(" - ") + t.substr(1);
    else out += std::string(" + ") + t;
  }
  return out;
}

std::string product_text(const std::string& coefficient, bool coefficient_is_sum, const std::string& factor, Style style) {
  if (factor.empty()) return coefficient;
  if (coefficient == "1") return factor;
  if (coefficient == "-1") return std::string("-") + factor;
  const std::string c = coefficient_is_sum ? (style == Style::Latex ? std::string("\\left(") + coefficient + "\\right)"
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

class ForcedEmitter {
 public:
  explicit ForcedEmitter(const ForcedModes& m);
  std::string code() const;
  std::map<std::string, std::string> latex() const;

 private:
  const ForcedModes& m_;
  std::vector<Rate> rates_;
  std::vector<Frequency> frequencies_;
  std::vector<Mode> modes_;

  ex explicit_value(const ex& e) const { return expanded(symbolic::with_explicit_radicals(e, m_.radicals)); }
  std::string literal_of(const ex& exact_number) const;
  int rate_index(const ex& rate);
  int frequency_index(const ex& frequency);
  std::vector<Term> convert(const TimeFunction& f, const std::vector<Input>& inputs);
  void split(const ex& c, const std::vector<Input>& inputs, std::size_t level, std::vector<unsigned>& powers,
             std::vector<Monomial>& out) const;
  std::string term_code(const Term& term, const std::vector<Input>& inputs) const;
  std::string sum_code(const std::vector<Term>& terms, const std::vector<Input>& inputs, const std::string& indent) const;
  std::string constants_for(const Mode& mode) const;
  std::string unused_markers(const Mode& mode) const;
  std::string exact_text(const std::vector<Term>& terms, const std::vector<Input>& inputs, Style style) const;
  std::string function(const Mode& mode) const;
};

ForcedEmitter::ForcedEmitter(const ForcedModes& m) : m_(m) {
  for (const ForcedSolution* s : m_.solutions()) {
    Mode mode;
    mode.source = s;
    for (std::size_t i = 0; i < s->arguments.size(); ++i) mode.inputs.push_back({s->arguments[i], s->argument_names[i]});
    for (const ForcedOutput& o : s->outputs) mode.outputs.push_back({&o, convert(o.segment.solution, mode.inputs)});
    modes_.push_back(std::move(mode));
  }
}

std::string ForcedEmitter::literal_of(const ex& exact_number) const {
  const ex value = explicit_value(exact_number);
  if (is_a<numeric>(value) && ex_to<numeric>(value).is_rational()) return rational_literal(ex_to<numeric>(value));
  const double v = evaluate_to_double(value);
  const std::string lit = double_literal(v);
  return v < 0 ? std::string("(") + lit + ")" : lit;
}

int ForcedEmitter::rate_index(const ex& rate) {
  if (symbolic::is_exactly_zero(rate, m_.radicals)) return -1;
  for (std::size_t i = 0; i < rates_.size(); ++i)
    if (symbolic::is_exactly_zero(rates_[i].exact - rate, m_.radicals)) return static_cast<int>(i);
  Rate r;
  r.exact = rate;
  r.value_exact = explicit_value(rate);
  r.value = evaluate_to_double(r.value_exact);
  r.literal = literal_of(rate);
  rates_.push_back(r);
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

int ForcedEmitter::frequency_index(const ex& frequency) {
  for (std::size_t i = 0; i < frequencies_.size(); ++i)
    if (symbolic::is_exactly_zero(frequencies_[i].exact - frequency, m_.radicals)) return static_cast<int>(i);
  Frequency f;
  f.exact = frequency;
  f.value_exact = explicit_value(frequency);
  f.value = evaluate_to_double(f.value_exact);
  f.literal = literal_of(frequency);
  const std::string base = is_a<symbol>(frequency) ? identifier(ex_to<symbol>(frequency).get_name()) : "omega";
  std::string name = base;
  for (int k = 2; std::any_of(frequencies_.begin(), frequencies_.end(), [&](const Frequency& o) { return o.name == name; });
       ++k)
    name = base + "_" + std::to_string(k);
  f.name = name;
  frequencies_.push_back(f);
  return static_cast<int>(frequencies_.size() - 1);
}

void ForcedEmitter::split(const ex& c, const std::vector<Input>& inputs, std::size_t level, std::vector<unsigned>& powers,
                          std::vector<Monomial>& out) const {
  if (level == inputs.size()) {
    if (symbolic::is_exactly_zero(c, m_.radicals)) return;
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

std::vector<Term> ForcedEmitter::convert(const TimeFunction& f, const std::vector<Input>& inputs) {
  std::vector<Term> out;
  const TimeFunction combined = f.combined(m_.radicals);
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

std::string ForcedEmitter::term_code(const Term& term, const std::vector<Input>& inputs) const {
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

std::string ForcedEmitter::sum_code(const std::vector<Term>& terms, const std::vector<Input>& inputs,
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

std::string ForcedEmitter::exact_text(const std::vector<Term>& terms, const std::vector<Input>& inputs, Style style) const {
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

// Hoisted exponentials and oscillations of one function (as the case emitter does).
std::string ForcedEmitter::constants_for(const Mode& mode) const {
  std::set<int> rates, cosines, sines;
  for (const Output& o : mode.outputs)
    for (const Term& t : o.terms) {
      if (t.rate >= 0) rates.insert(t.rate);
      if (t.oscillation == Oscillation::Cos) cosines.insert(t.frequency);
      if (t.oscillation == Oscillation::Sin) sines.insert(t.frequency);
    }
  std::string out;
  std::vector<int> ordered(rates.begin(), rates.end());
  std::sort(ordered.begin(), ordered.end(), [&](int a, int b) { return rates_[a].value > rates_[b].value; });
  // Decaying rational rates that are small multiples (≤ 16) of a common rate g share one
  // exp: e^{-m g t} = (e^{-g t})^m by binary powering.  Others get their own exp.
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

std::string ForcedEmitter::unused_markers(const Mode& mode) const {
  bool time = false;
  std::vector<bool> used(mode.inputs.size(), false);
  for (const Output& o : mode.outputs)
    for (const Term& t : o.terms) {
      time |= t.t_power > 0 || t.rate >= 0 || t.oscillation != Oscillation::None;
      for (const Monomial& m : t.monomials)
        for (std::size_t i = 0; i < mode.inputs.size(); ++i) used[i] = used[i] || m.powers[i] > 0;
    }
  std::string out = time ? std::string() : std::string("  (void)t;\n");
  for (std::size_t i = 0; i < mode.inputs.size(); ++i)
    if (!used[i]) out += std::string("  (void)") + mode.inputs[i].name + ";\n";
  return out;
}

std::string ForcedEmitter::function(const Mode& mode) const {
  const ForcedSolution& s = *mode.source;
  const std::string type = s.name + "_t";
  std::ostringstream f;
  f << "struct " << type << " {\n";
  for (const Output& o : mode.outputs)
    f << "  double " << o.source->segment.name << ";  ///< " << symbolic::escape::cpp_comment(o.source->meaning) << "\n";
  f << "};\n\n";
  f << "/// " << s.name << ": " << symbolic::escape::cpp_comment(s.meaning) << ".\n";
  f << "/// " << symbolic::escape::cpp_comment(s.equation) << ":\n";
  for (const Output& o : mode.outputs)
    f << "///   " << o.source->segment.name << " = " << exact_text(o.terms, mode.inputs, Style::Text) << "\n";
  std::string parameters = "double t";
  for (const Input& in : mode.inputs) parameters += std::string(", double ") + in.name;
  f << "inline " << type << " " << s.name << "(" << parameters << ") noexcept {\n";
  f << unused_markers(mode) << constants_for(mode);
  f << "  " << type << " s;\n";
  for (const Output& o : mode.outputs)
    f << "  s." << o.source->segment.name << " = " << sum_code(o.terms, mode.inputs, "      ") << ";\n";
  f << "  return s;\n}\n\n";
  return f.str();
}

std::string ForcedEmitter::code() const {
  std::ostringstream h;
  h << "// Forced modes (docs/effects.md): each linear mode with a constant forcing that\n"
       "// Coulomb friction, saturation or a torque offset add, exact for this case\n"
       "// (symbolic/forced_modes.hpp).  Displacements are theta(t) - theta(0); the forcing\n"
       "// and the initial state are runtime arguments.\n";
  h << "namespace forced {\n\n";
  if (!frequencies_.empty()) {
    h << "// Frequencies (square roots of exact rationals, correctly rounded).\n";
    for (const Frequency& f : frequencies_)
      h << "inline constexpr double " << f.name << " = " << f.literal << ";  // " << print(f.value_exact, Style::Text) << "\n";
    h << "\n";
  }
  for (const Mode& mode : modes_) h << function(mode);
  h << "/// LaTeX of every forced output (exact).\n";
  h << "struct latex {\n";
  for (const auto& [name, tex] : latex()) {
    std::string key = name;
    std::replace(key.begin(), key.end(), '.', '_');
    h << "  static constexpr const char* " << key << " = R\"tex(" << tex << ")tex\";\n";
  }
  h << "};\n\n";
  h << "}  // namespace forced\n\n";
  return h.str();
}

std::map<std::string, std::string> ForcedEmitter::latex() const {
  std::map<std::string, std::string> out;
  for (const Mode& mode : modes_) {
    out[mode.source->name] = mode.source->equation_latex;
    for (const Output& o : mode.outputs)
      out[mode.source->name + "." + o.source->segment.name] = exact_text(o.terms, mode.inputs, Style::Latex);
  }
  return out;
}

}  // namespace

std::string emit_forced_namespace(const ForcedModes& modes) { return ForcedEmitter(modes).code(); }

std::string emit_forced_namespace(const symbolic::CaseDerivation& derivation) {
  return emit_forced_namespace(symbolic::derive_forced_modes(derivation));
}

std::map<std::string, std::string> forced_latex(const ForcedModes& modes) { return ForcedEmitter(modes).latex(); }

std::string emit_forced_latex(const symbolic::CaseDerivation& d) {
  const ForcedModes modes = symbolic::derive_forced_modes(d);
  const std::map<std::string, std::string> tex = forced_latex(modes);
  auto escaped = [](const std::string& s) {
    std::string o;
    for (char c : s) o += c == '_' ? std::string("\\_") : std::string(1, c);
    return o;
  };
  std::ostringstream out;
  out << "\\subsection*{" << symbolic::escape::latex_text(d.name) << ": forced modes (effects)}\n";
  out << "Displacements $\\Delta = \\theta - \\theta(0)$ under a constant forcing (docs/effects.md); "
         "namespace \\texttt{forced} of the generated header.\n";
  for (const ForcedSolution* s : modes.solutions()) {
    out << "\\paragraph{\\texttt{" << escaped(s->name) << "}}\n";
    out << "\\begin{equation}\\label{eq:gen:" << d.case_id << ":forced:" << s->name << "}\n"
        << tex.at(s->name) << "\n\\end{equation}\n";
    for (const ForcedOutput& o : s->outputs)
      out << "\\begin{equation}\\label{eq:gen:" << d.case_id << ":forced:" << s->name << ":" << o.segment.name << "}\n"
          << o.lhs_latex << " = " << tex.at(s->name + "." + o.segment.name) << "\n\\end{equation}\n";
  }
  return out.str();
}

}  // namespace backlash::codegen
