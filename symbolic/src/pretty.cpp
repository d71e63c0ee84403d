#include "backlash/symbolic/pretty.hpp"

#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/inverse_laplace.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

namespace backlash::symbolic::pretty {

using namespace GiNaC;

namespace {

// ---------------------------------------------------------------- atoms and monomials

constexpr int variable_ranks = 10;  // atoms of rank < 10 are collected (s, t and the initial states)

struct Atom {
  int rank = 0;
  std::string key;  ///< canonical text, the tie-break and the identity
  ex value;         ///< the atom itself (symbol, √n, π, function, √polynomial)
};

bool atom_less(const Atom& a, const Atom& b) { return a.rank != b.rank ? a.rank < b.rank : a.key < b.key; }

struct Monomial {
  numeric coefficient = 1;
  std::vector<std::pair<Atom, int>> atoms;  ///< sorted by atom_less, exponents non-zero
};

using Poly = std::vector<Monomial>;

int symbol_rank(const std::string& name) {
  static const std::map<std::string, int> ranks{
      {"s", 0},       {"t", 1},   {"dtheta_m0", 2}, {"theta_o0", 3}, {"dtheta_o0", 4}, {"theta_o", 5}, {"dtheta_o", 6},
      {"Theta_L", 7}, {"theta_R", 20}, {"Jm", 21},   {"JL", 22},      {"Fm", 23},        {"FL", 24},     {"K", 25},
      {"omega_c", 26}, {"omega_m", 27}, {"delta_c", 28}, {"delta_m", 29}, {"i_unit", 59}};
  const auto found = ranks.find(name);
  return found == ranks.end() ? 40 : found->second;
}

std::string padded_integer(const numeric& n) {
  std::ostringstream out;
  out << n;
  std::string digits = out.str();
  return std::string(digits.size() < 40 ? 40 - digits.size() : 0, '0') + digits;
}

std::string number_text(const numeric& q) {
  std::ostringstream out;
  out << q;
  return out.str();
}

std::string print_impl(const ex& e, const Format& f);

std::string atom_text_of(const Atom& a, const Format& f);

Atom make_atom(const ex& value) {
  Atom a;
  a.value = value;
  if (is_a<symbol>(value)) {
    a.key = ex_to<symbol>(value).get_name();
    a.rank = symbol_rank(a.key);
    return a;
  }
  if (is_a<power>(value) && is_a<numeric>(value.op(0))) {  // √n
    a.rank = 60;
    a.key = padded_integer(ex_to<numeric>(value.op(0)));
    return a;
  }
  if (is_a<constant>(value)) a.rank = 65;
  else if (is_a<power>(value)) a.rank = 69;  // √(polynomial)
  else if (is_a<function>(value)) {
    const std::string name = ex_to<function>(value).get_name();
    a.rank = name == "exp" ? 70 : (name == "sin" ? 71 : (name == "cos" ? 72 : (name == "atan" ? 73 : 75)));
  } else {
    a.rank = 80;
  }
  a.key = atom_text_of(a, text_exact);
  return a;
}

void multiply_atom(Monomial& m, const ex& base, int exponent) {
  if (exponent == 0) return;
  Atom atom = make_atom(base);
  for (auto& [a, k] : m.atoms)
    if (a.key == atom.key && a.rank == atom.rank) {
      k += exponent;
      return;
    }
  m.atoms.emplace_back(std::move(atom), exponent);
}

void normalise(Monomial& m) {
  // √n to the power k: n^(k div 2) into the coefficient, exponent k mod 2.
  for (auto& [a, k] : m.atoms) {
    if (a.rank != 60) continue;
    const numeric n = ex_to<numeric>(a.value.op(0));
    int whole = k >= 0 ? k / 2 : -((-k + 1) / 2);
    const int rest = k - 2 * whole;
    m.coefficient = m.coefficient * n.power(whole);
    k = rest;
  }
  m.atoms.erase(std::remove_if(m.atoms.begin(), m.atoms.end(), [](const auto& p) { return p.second == 0; }), m.atoms.end());
  std::sort(m.atoms.begin(), m.atoms.end(), [](const auto& x, const auto& y) { return atom_less(x.first, y.first); });
}

void read_factor(Monomial& m, const ex& factor) {
  if (is_a<numeric>(factor)) {
    const numeric n = ex_to<numeric>(factor);
    if (!n.is_rational()) throw std::invalid_argument("pretty: non-rational number " + number_text(n));
    m.coefficient = m.coefficient * n;
    return;
  }
  if (is_a<power>(factor) && is_a<numeric>(factor.op(1))) {
    const numeric exponent = ex_to<numeric>(factor.op(1));
    if (exponent.is_integer()) {
      if (is_a<numeric>(factor.op(0))) {  // not expected (GiNaC evaluates it), but harmless
        m.coefficient = m.coefficient * ex_to<numeric>(factor.op(0)).power(exponent);
        return;
      }
      multiply_atom(m, factor.op(0), exponent.to_int());
      return;
    }
    if (exponent.is_rational()) {  // b^(p/q): the atom b^(1/q) to the power p
      const numeric q = exponent.denom(), p = exponent.numer();
      multiply_atom(m, pow(factor.op(0), numeric(1) / q), p.to_int());
      return;
    }
  }
  multiply_atom(m, factor, 1);
}

Monomial read_monomial(const ex& term) {
  Monomial m;
  if (is_a<mul>(term))
    for (std::size_t i = 0; i < term.nops(); ++i) read_factor(m, term.op(i));
  else
    read_factor(m, term);
  normalise(m);
  return m;
}

bool same_atoms(const Monomial& a, const Monomial& b) {
  if (a.atoms.size() != b.atoms.size()) return false;
  for (std::size_t i = 0; i < a.atoms.size(); ++i)
    if (a.atoms[i].first.key != b.atoms[i].first.key || a.atoms[i].first.rank != b.atoms[i].first.rank ||
        a.atoms[i].second != b.atoms[i].second)
      return false;
  return true;
}

Poly read_poly(const ex& expanded_expression) {
  Poly p;
  auto add_term = [&](const ex& term) {
    Monomial m = read_monomial(term);
    if (m.coefficient.is_zero()) return;
    for (Monomial& o : p)
      if (same_atoms(o, m)) {
        o.coefficient = o.coefficient + m.coefficient;
        return;
      }
    p.push_back(std::move(m));
  };
  if (is_a<add>(expanded_expression))
    for (std::size_t i = 0; i < expanded_expression.nops(); ++i) add_term(expanded_expression.op(i));
  else
    add_term(expanded_expression);
  p.erase(std::remove_if(p.begin(), p.end(), [](const Monomial& m) { return m.coefficient.is_zero(); }), p.end());
  return p;
}

// Lexicographic order over atoms (rank, key), higher exponent first.
bool monomial_less(const Monomial& a, const Monomial& b) {
  std::size_t i = 0, j = 0;
  while (i < a.atoms.size() || j < b.atoms.size()) {
    if (j == b.atoms.size()) return true;   // a has a further atom: a first
    if (i == a.atoms.size()) return false;
    const Atom &x = a.atoms[i].first, &y = b.atoms[j].first;
    if (atom_less(x, y)) return true;        // a has an atom b lacks (earlier in the order)
    if (atom_less(y, x)) return false;
    if (a.atoms[i].second != b.atoms[j].second) return a.atoms[i].second > b.atoms[j].second;
    ++i;
    ++j;
  }
  return a.coefficient < b.coefficient;
}

ex to_ex(const Monomial& m) {
  ex e = m.coefficient;
  for (const auto& [a, k] : m.atoms) e *= pow(a.value, k);
  return e;
}

// ---------------------------------------------------------------- numbers

bool is_decimal(const Format& f) { return f.significant > 0; }

std::string latex_fraction(const std::string& numerator, const std::string& denominator) {
  return "\\frac{" + numerator + "}{" + denominator + "}";
}

// The constant part of a monomial (rational, √n, π) as a double.
double constant_value(const Monomial& m) {
  ex value = m.coefficient;
  for (const auto& [a, k] : m.atoms)
    if (a.rank == 60 || a.rank == 65) value *= pow(a.value, k);
  return to_double(value, {});
}

bool is_constant_atom(const Atom& a) { return a.rank == 60 || a.rank == 65; }

std::string atom_text(const Atom& a, const Format& f);

std::string power_text(const std::string& base, int k, bool needs_parentheses, const Format& f) {
  if (k == 1) return base;
  if (f.style == Style::Text) return (needs_parentheses ? "(" + base + ")" : base) + "^" + (k < 0 ? "(" + std::to_string(k) + ")" : std::to_string(k));
  return (needs_parentheses ? "\\left(" + base + "\\right)" : base) + "^{" + std::to_string(k) + "}";
}

bool atom_needs_parentheses(const Atom& a, const Format& f) {
  if (a.rank == 70 && f.style == Style::Latex) return true;  // e^{x} to a power
  return a.rank >= 69 && f.style == Style::Text ? false : (a.rank == 80);
}

// |monomial| without its sign; `unit_if_empty` prints 1 for the empty product.
std::string monomial_body(const Monomial& m, const Format& f, bool unit_if_empty = true) {
  const numeric c = abs(m.coefficient);
  std::vector<std::string> up, down, constants_up;
  for (const auto& [a, k] : m.atoms) {
    if (is_decimal(f) && is_constant_atom(a)) continue;
    const bool parentheses = atom_needs_parentheses(a, f);
    const std::string base = atom_text(a, f);
    if (k > 0) (is_constant_atom(a) ? constants_up : up).push_back(power_text(base, k, parentheses, f));
    else down.push_back(power_text(base, -k, parentheses, f));
  }
  std::string number_up, number_down;
  if (is_decimal(f)) {
    const double v = std::fabs(constant_value(m));
    const std::string d = decimal(v, f.significant, f.style);
    if (d != "1" || (unit_if_empty && up.empty() && down.empty() && constants_up.empty())) number_up = d;
  } else {
    const numeric p = c.numer(), q = c.denom();
    if (p != 1 || (unit_if_empty && up.empty() && constants_up.empty() && down.empty())) number_up = number_text(p);
    if (q != 1) number_down = number_text(q);
  }
  if (f.style == Style::Text) {
    std::vector<std::string> parts;
    std::string head = number_up;
    if (!number_down.empty()) head = (head.empty() ? "1" : head) + "/" + number_down;
    if (!head.empty()) parts.push_back(head);
    for (const auto& s : constants_up) parts.push_back(s);
    for (const auto& s : up) parts.push_back(s);
    std::string out;
    for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? "*" : "") + parts[i];
    if (out.empty() && (!down.empty() || unit_if_empty)) out = "1";
    if (!down.empty()) {
      std::string d;
      for (std::size_t i = 0; i < down.size(); ++i) d += (i ? "*" : "") + down[i];
      out += "/" + (down.size() > 1 ? "(" + d + ")" : d);
    }
    return out;
  }
  std::string constants;
  for (const auto& s : constants_up) constants += s;
  std::string variables;
  for (const auto& s : up) variables += s;
  if (down.empty()) {
    if (number_down.empty()) {
      std::string out = number_up + constants + variables;
      if (out.empty() && unit_if_empty) out = "1";
      return out;
    }
    // \frac{2\sqrt{6}}{5}\theta
    const std::string top = (number_up.empty() && constants.empty()) ? "1" : number_up + constants;
    return latex_fraction(top, number_down) + variables;
  }
  std::string bottom = number_down;
  for (const auto& s : down) bottom += s;
  std::string top = number_up + constants + variables;
  if (top.empty()) top = "1";
  return latex_fraction(top, bottom);
}

std::vector<Summand> poly_summands(const Poly& p, const Format& f, int level);

std::string join_summands(const std::vector<Summand>& terms, Style style) { return join(terms, style); }

// Summands of a polynomial, collected by its lowest-rank variable (recursively),
// the rest flat in lexicographic order.
std::vector<Summand> poly_summands(const Poly& p, const Format& f, int level) {
  std::vector<Summand> out;
  if (p.empty()) return {{false, "0"}};
  // the variable to collect by
  const Atom* variable = nullptr;
  for (const Monomial& m : p)
    for (const auto& [a, k] : m.atoms)
      if (a.rank < variable_ranks && (!variable || atom_less(a, *variable))) variable = &a;
  if (!variable) {
    Poly sorted = p;
    std::sort(sorted.begin(), sorted.end(), monomial_less);
    for (const Monomial& m : sorted) out.push_back({m.coefficient.is_negative(), monomial_body(m, f)});
    return out;
  }
  const Atom v = *variable;
  std::map<int, Poly> groups;
  for (const Monomial& m : p) {
    Monomial rest;
    rest.coefficient = m.coefficient;
    int exponent = 0;
    for (const auto& [a, k] : m.atoms) {
      if (a.key == v.key && a.rank == v.rank) exponent = k;
      else rest.atoms.emplace_back(a, k);
    }
    groups[exponent].push_back(rest);
  }
  std::vector<int> order;
  for (const auto& [k, g] : groups) order.push_back(k);
  // s: descending powers; the other variables: descending too (constant last), except in a
  // top-level sum (level < 0), where the constant comes first: "1 + \frac{1}{5}\dot\theta_{m0}".
  if (v.key == "s" || level >= 0) std::reverse(order.begin(), order.end());
  for (int k : order) {
    const Poly& c = groups[k];
    if (k == 0) {
      for (const Summand& s : poly_summands(c, f, level)) out.push_back(s);
      continue;
    }
    const std::string power = power_text(atom_text(v, f), k, false, f);
    if (c.size() == 1) {
      const Monomial& m = c.front();
      const bool negative = is_decimal(f) ? constant_value(m) < 0 : m.coefficient.is_negative();
      std::string body = monomial_body(m, f, false);
      if (f.style == Style::Text) body = body.empty() ? power : body + "*" + power;
      else body += power;
      out.push_back({negative, body});
      continue;
    }
    std::vector<Summand> inner = poly_summands(c, f, level < 0 ? 0 : level + 1);
    bool all_negative = true;
    for (const Summand& s : inner) all_negative = all_negative && s.negative;
    if (all_negative)
      for (Summand& s : inner) s.negative = false;
    std::stable_partition(inner.begin(), inner.end(), [](const Summand& t) { return !t.negative; });
    const std::string joined = join_summands(inner, f.style);
    const std::string body = f.style == Style::Text ? "(" + joined + ")*" + power : "\\left(" + joined + "\\right)" + power;
    out.push_back({all_negative, body});
  }
  return out;
}

std::string poly_text(const Poly& p, const Format& f) { return join(poly_summands(p, f, -1), f.style); }

// In a parenthesised group a positive term leads: (θo0 + 5θ̇o0 − 1).
void positive_first(std::vector<Summand>& terms) {
  std::stable_partition(terms.begin(), terms.end(), [](const Summand& t) { return !t.negative; });
}

// ---------------------------------------------------------------- fractions

struct PolyFraction {
  Poly numerator, denominator;  ///< denominator empty or {1}: a polynomial
};

bool is_one(const Poly& p) { return p.size() == 1 && p.front().atoms.empty() && p.front().coefficient == 1; }

numeric content_lcm_of_denominators(const Poly& p) {
  numeric l = 1;
  for (const Monomial& m : p) l = lcm(l, m.coefficient.denom());
  return l;
}
numeric content_gcd_of_numerators(const Poly& p) {
  numeric g = 0;
  for (const Monomial& m : p) g = gcd(g, m.coefficient.numer());
  return g;
}

void scale(Poly& p, const numeric& factor) {
  for (Monomial& m : p) m.coefficient = m.coefficient * factor;
}

// Leading monomial of a polynomial in the printed order.
const Monomial& leading(const Poly& p) {
  return *std::min_element(p.begin(), p.end(), [](const Monomial& a, const Monomial& b) {
    // s descending first, then lexicographic
    int sa = 0, sb = 0;
    for (const auto& [x, k] : a.atoms) if (x.key == "s" && x.rank == 0) sa = k;
    for (const auto& [x, k] : b.atoms) if (x.key == "s" && x.rank == 0) sb = k;
    if (sa != sb) return sa > sb;
    return monomial_less(a, b);
  });
}

PolyFraction fraction_of(const ex& e) {
  const ex normalised = normal(e);
  const ex nd = numer_denom(normalised);
  PolyFraction f{read_poly(expand(nd.op(0))), read_poly(expand(nd.op(1)))};
  if (f.denominator.empty()) throw std::domain_error("pretty: zero denominator");
  if (f.numerator.empty()) return {{}, {}};
  // A monomial denominator divides into the numerator (negative exponents print as fractions).
  if (f.denominator.size() == 1) {
    const Monomial d = f.denominator.front();
    for (Monomial& m : f.numerator) {
      m.coefficient = m.coefficient / d.coefficient;
      for (const auto& [a, k] : d.atoms) {
        bool found = false;
        for (auto& [b, j] : m.atoms)
          if (b.key == a.key && b.rank == a.rank) { j -= k; found = true; }
        if (!found) m.atoms.emplace_back(a, -k);
      }
      normalise(m);
    }
    f.denominator.clear();
    return f;
  }
  // Integer coefficients, gcd 1, positive leading denominator monomial.
  numeric l = lcm(content_lcm_of_denominators(f.numerator), content_lcm_of_denominators(f.denominator));
  scale(f.numerator, l);
  scale(f.denominator, l);
  numeric g = gcd(content_gcd_of_numerators(f.numerator), content_gcd_of_numerators(f.denominator));
  if (leading(f.denominator).coefficient.is_negative()) g = -g;
  scale(f.numerator, numeric(1) / g);
  scale(f.denominator, numeric(1) / g);
  return f;
}

std::string fraction_text(const PolyFraction& f, const Format& format) {
  if (f.numerator.empty()) return "0";
  if (f.denominator.empty()) return poly_text(f.numerator, format);
  const std::string n = poly_text(f.numerator, format), d = poly_text(f.denominator, format);
  if (format.style == Style::Text) return "(" + n + ")/(" + d + ")";
  return latex_fraction(n, d);
}

// ---------------------------------------------------------------- atoms as text

std::string function_latex(const std::string& name, const std::string& argument) {
  const bool big = argument.find("\\frac") != std::string::npos;
  const std::string open = big ? "\\left(" : "(", close = big ? "\\right)" : ")";
  if (name == "sin") return "\\sin" + open + argument + close;
  if (name == "cos") return "\\cos" + open + argument + close;
  if (name == "atan") return "\\arctan" + open + argument + close;
  if (name == "log") return "\\ln" + open + argument + close;
  if (name == "abs") return "\\left|" + argument + "\\right|";
  if (name == "exp") {
    if (visible_width(argument) > 28) return "\\exp\\left(" + argument + "\\right)";
    return "e^{" + argument + "}";
  }
  return "\\operatorname{" + name + "}" + open + argument + close;
}

std::string atom_text_of(const Atom& a, const Format& f) { return atom_text(a, f); }

std::string atom_text(const Atom& a, const Format& f) {
  const ex& v = a.value;
  if (is_a<symbol>(v)) {
    const std::string name = ex_to<symbol>(v).get_name();
    if (f.style == Style::Text) return name == "i_unit" ? "I" : name;
    return latex_symbol_name(name);
  }
  if (is_a<constant>(v)) {
    std::ostringstream out;
    out << v;
    const std::string name = out.str();
    if (f.style == Style::Text) return name;
    return name == "Pi" ? "\\pi" : name;
  }
  if (is_a<power>(v)) {  // b^(1/q)
    const numeric e = ex_to<numeric>(v.op(1));
    const std::string base = print_impl(v.op(0), f);
    if (e == numeric(1, 2)) return f.style == Style::Text ? "sqrt(" + base + ")" : "\\sqrt{" + base + "}";
    if (f.style == Style::Text) return "(" + base + ")^(" + number_text(e) + ")";
    return "\\sqrt[" + number_text(e.denom()) + "]{" + base + "}";
  }
  if (is_a<function>(v)) {
    const std::string name = ex_to<function>(v).get_name();
    std::string arguments;
    for (std::size_t i = 0; i < v.nops(); ++i) arguments += (i ? ", " : "") + print_impl(v.op(i), f);
    if (f.style == Style::Text) return name + "(" + arguments + ")";
    return function_latex(name, arguments);
  }
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string print_impl(const ex& e, const Format& f) {
  if (is_a<numeric>(e)) {
    const numeric n = ex_to<numeric>(e);
    if (is_decimal(f) || !n.is_rational()) return decimal(n.to_double(), f.significant > 0 ? f.significant : 17, f.style);
  }
  return fraction_text(fraction_of(e), f);
}

}  // namespace

// ---------------------------------------------------------------- public

std::string latex_symbol_name(const std::string& name) {
  static const std::map<std::string, std::string> names{
      {"dtheta_m0", "\\dot\\theta_{m0}"}, {"theta_o0", "\\theta_{o0}"}, {"dtheta_o0", "\\dot\\theta_{o0}"},
      {"theta_o", "\\theta_o"},          {"dtheta_o", "\\dot\\theta_o"}, {"theta_R", "\\theta_R"},
      {"Jm", "J_m"},                     {"JL", "J_L"},                 {"Fm", "F_m"},
      {"FL", "F_L"},                     {"i_unit", "\\mathrm{i}"},     {"Theta_L", "\\Theta_L(s)"}};
  const auto found = names.find(name);
  if (found != names.end()) return found->second;
  static const char* greek[] = {"alpha", "beta", "gamma", "delta", "epsilon", "eta", "theta", "lambda",
                                "mu",    "nu",   "xi",    "pi",    "rho",     "sigma", "tau", "phi",
                                "chi",   "psi",  "omega", "Theta", "Omega",   "Delta", "Phi"};
  std::string head = name, tail;
  const auto underscore = name.find('_');
  if (underscore != std::string::npos) {
    head = name.substr(0, underscore);
    tail = name.substr(underscore + 1);
  }
  for (const char* g : greek)
    if (head == g) head = std::string("\\") + g;
  std::string cleaned_tail;
  for (char c : tail) cleaned_tail += (c == '_' ? ',' : c);
  if (tail.empty()) return head;
  return head + (cleaned_tail.size() == 1 ? "_" + cleaned_tail : "_{" + cleaned_tail + "}");
}

std::string decimal(double value, int significant, Style style) {
  if (value == 0 || std::fabs(value) < 1e-300) return "0";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant, value);
  std::string text = buffer;
  const auto e = text.find('e');
  if (e == std::string::npos) return text;
  std::string mantissa = text.substr(0, e);
  int exponent = std::stoi(text.substr(e + 1));
  if (style == Style::Text) return mantissa + "e" + std::to_string(exponent);
  if (mantissa == "1") return "10^{" + std::to_string(exponent) + "}";
  if (mantissa == "-1") return "-10^{" + std::to_string(exponent) + "}";
  return mantissa + "\\times10^{" + std::to_string(exponent) + "}";
}

std::string join(const std::vector<Summand>& terms, Style style) {
  if (terms.empty()) return "0";
  std::string out;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const Summand& t = terms[i];
    if (i == 0) out = (t.negative ? "-" : "") + t.body;
    else if (style == Style::Text) out += (t.negative ? "-" : "+") + t.body;
    else out += (t.negative ? " - " : " + ") + t.body;
  }
  return out;
}

std::string print(const ex& expression, const Format& format) { return print_impl(expression, format); }

std::size_t visible_width(const std::string& latex) {
  std::size_t width = 0;
  for (std::size_t i = 0; i < latex.size(); ++i) {
    const char c = latex[i];
    if (c == '\\') {
      std::size_t j = i + 1;
      while (j < latex.size() && std::isalpha(static_cast<unsigned char>(latex[j]))) ++j;
      const std::string command = latex.substr(i + 1, j - i - 1);
      if (command != "left" && command != "right" && command != "frac" && command != "tfrac" && command != "quad" &&
          command != "qquad")
        ++width;
      i = (j == i + 1) ? i + 1 : j - 1;
      continue;
    }
    if (c == '{' || c == '}' || c == '^' || c == '_' || c == ' ') continue;
    ++width;
  }
  return width;
}

// ---------------------------------------------------------------- time functions

std::vector<ExpTerm> sorted_terms(const TimeFunction& f, const RadicalList& radicals) {
  struct Keyed {
    ExpTerm term;
    int oscillating;
    bool numeric_rate;
    double rate;
    std::string rate_text;
  };
  std::vector<Keyed> keyed;
  for (const ExpTerm& term : f.terms()) {
    Keyed k{term, term.oscillation == Oscillation::None ? 0 : 1, false, 0.0, text(term.rate)};
    try {
      k.rate = to_double(term.rate, radicals);
      k.numeric_rate = true;
    } catch (...) {
    }
    keyed.push_back(std::move(k));
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    if (a.oscillating != b.oscillating) return a.oscillating < b.oscillating;
    if (a.numeric_rate != b.numeric_rate) return a.numeric_rate;
    if (a.numeric_rate && a.rate != b.rate) return a.rate > b.rate;
    if (!a.numeric_rate && a.rate_text != b.rate_text) return a.rate_text < b.rate_text;
    if (a.term.t_power != b.term.t_power) return a.term.t_power < b.term.t_power;
    return static_cast<int>(a.term.oscillation) < static_cast<int>(b.term.oscillation);
  });
  std::vector<ExpTerm> out;
  for (const Keyed& k : keyed) out.push_back(k.term);
  return out;
}

namespace {

std::string exponent_latex(const ex& rate, const Format& f) {
  if (is_a<numeric>(rate) && ex_to<numeric>(rate).is_rational() && !is_decimal(f)) {
    const numeric q = ex_to<numeric>(rate);
    const numeric p = q.numer(), d = q.denom();
    if (f.style == Style::Text) return print(rate * derivation_symbols().t, f);
    std::string s = p.is_negative() ? "-" : "";
    const numeric ap = abs(p);
    if (ap != 1) s += number_text(ap);
    s += "t";
    if (d != 1) s += "/" + number_text(d);
    return s;
  }
  if (is_decimal(f)) {
    try {
      const double v = to_double(rate, {});
      return f.style == Style::Text ? decimal(v, f.significant, f.style) + "*t" : decimal(v, f.significant, f.style) + "t";
    } catch (...) {
    }
  }
  return print(rate * derivation_symbols().t, f);
}

std::string oscillation_argument(const ex& frequency, const RadicalList& radicals, const Format& f, bool names) {
  if (names && is_a<symbol>(frequency) && !is_decimal(f)) {
    const std::string name = atom_text(make_atom(frequency), f);
    return f.style == Style::Text ? name + "*t" : name + " t";
  }
  if (is_decimal(f)) {
    try {
      const double w = to_double(frequency, radicals);
      return f.style == Style::Text ? decimal(w, f.significant, f.style) + "*t" : decimal(w, f.significant, f.style) + "t";
    } catch (...) {  // symbolic (a general branch's ω)
    }
  }
  return print(with_explicit_radicals(frequency, radicals) * derivation_symbols().t, f);
}

std::string basis_text(const ExpTerm& term, const RadicalList& radicals, const Format& f, bool names) {
  std::vector<std::string> parts;
  if (term.t_power == 1) parts.push_back("t");
  if (term.t_power > 1)
    parts.push_back(f.style == Style::Text ? "t^" + std::to_string(term.t_power) : "t^{" + std::to_string(term.t_power) + "}");
  if (!term.rate.is_zero()) {
    const std::string x = exponent_latex(with_explicit_radicals(term.rate, radicals), f);
    if (f.style == Style::Text) parts.push_back("exp(" + x + ")");
    else parts.push_back(visible_width(x) > 28 ? "\\exp\\left(" + x + "\\right)" : "e^{" + x + "}");
  }
  if (term.oscillation != Oscillation::None) {
    const std::string x = oscillation_argument(term.frequency, radicals, f, names);
    const char* name = term.oscillation == Oscillation::Cos ? "cos" : "sin";
    if (f.style == Style::Text) parts.push_back(std::string(name) + "(" + x + ")");
    else {
      const bool big = x.find("\\frac") != std::string::npos;
      parts.push_back(std::string("\\") + name + (big ? "\\left(" + x + "\\right)" : "(" + x + ")"));
    }
  }
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i && f.style == Style::Text ? "*" : "") + parts[i];
  return out;
}

// A common positive rational factor and a common √n of all monomials.
Monomial content(const Poly& p) {
  Monomial c;
  numeric g = 0, l = 1;
  for (const Monomial& m : p) {
    g = gcd(g, m.coefficient.numer());
    l = lcm(l, m.coefficient.denom());
  }
  // pull out a rational factor only when it simplifies: an integer > 1, or a denominator all share
  bool common_denominator = true;
  numeric largest = 0;
  for (const Monomial& m : p) {
    common_denominator = common_denominator && m.coefficient.denom() == l;
    largest = std::max(largest, abs(m.coefficient * l / g));
  }
  // …or one that leaves small integers inside: √21/42 (2 − 2θo0 − 5θ̇o0)
  const bool small_inside = largest <= 60;
  c.coefficient = (g > 1 ? g : numeric(1)) / (common_denominator || small_inside ? l : numeric(1));
  // a √n (rank 60) present in every monomial with exponent 1
  if (!p.empty())
    for (const auto& [a, k] : p.front().atoms) {
      if (a.rank != 60 || k != 1) continue;
      bool everywhere = true;
      for (const Monomial& m : p) {
        bool found = false;
        for (const auto& [b, j] : m.atoms) found = found || (b.key == a.key && b.rank == a.rank && j == 1);
        everywhere = everywhere && found;
      }
      if (everywhere) c.atoms.emplace_back(a, 1);
    }
  return c;
}

Poly divided(const Poly& p, const Monomial& c) {
  Poly out = p;
  for (Monomial& m : out) {
    m.coefficient = m.coefficient / c.coefficient;
    for (const auto& [a, k] : c.atoms)
      for (auto& [b, j] : m.atoms)
        if (b.key == a.key && b.rank == a.rank) j -= k;
    normalise(m);
  }
  return out;
}

}  // namespace

namespace {

// coefficient × basis as one summand (the coefficient factored when it is a sum);
// with an empty basis and `spread`, a polynomial coefficient gives its own summands.
std::vector<Summand> coefficient_summands(const PolyFraction& c, const std::string& basis, const Format& format, bool spread) {
  if (c.numerator.empty()) return {};
  const std::string glue = format.style == Style::Text ? "*" : "";
  const auto with_basis = [&](const std::string& body) {
    if (basis.empty()) return body;
    return body.empty() ? basis : body + glue + basis;
  };
  if (!c.denominator.empty()) return {{false, with_basis(fraction_text(c, format))}};
  if (c.numerator.size() == 1) {
    const Monomial& m = c.numerator.front();
    const std::string body = monomial_body(m, format, basis.empty());
    return {{m.coefficient.is_negative(), with_basis(body)}};
  }
  if (basis.empty() && spread) return poly_summands(c.numerator, format, -1);
  if (is_decimal(format)) {  // decimals: the plain sum, no factoring
    const std::string joined = join(poly_summands(c.numerator, format, 0), format.style);
    return {{false, with_basis(format.style == Style::Text ? "(" + joined + ")" : "\\left(" + joined + "\\right)")}};
  }
  const Monomial common = content(c.numerator);
  std::vector<Summand> inner = poly_summands(divided(c.numerator, common), format, 0);
  bool all_negative = true;
  for (const Summand& s : inner) all_negative = all_negative && s.negative;
  if (all_negative)
    for (Summand& s : inner) s.negative = false;
  positive_first(inner);
  const std::string factor = monomial_body(common, format, false);
  const std::string joined = join(inner, format.style);
  const std::string group = format.style == Style::Text ? "(" + joined + ")" : "\\left(" + joined + "\\right)";
  return {{all_negative, with_basis(factor + (factor.empty() ? "" : glue) + group)}};
}

}  // namespace

std::vector<Summand> summands(const ex& e, const Format& format) {
  std::vector<Summand> out = coefficient_summands(fraction_of(e), "", format, true);
  if (out.empty()) out.push_back({false, "0"});
  return out;
}

Summand factor(const ex& e, const Format& format) {
  std::vector<Summand> out = coefficient_summands(fraction_of(e), "", format, false);
  if (out.empty()) return {false, "0"};
  return out.front();
}

std::vector<Summand> time_function_terms(const TimeFunction& f, const RadicalList& radicals, const Format& format,
                                         bool frequency_names) {
  std::vector<Summand> out;
  for (const ExpTerm& term : sorted_terms(f, radicals)) {
    const std::string basis = basis_text(term, radicals, format, frequency_names);
    const PolyFraction c = fraction_of(with_explicit_radicals(term.coefficient, radicals));
    for (const Summand& s : coefficient_summands(c, basis, format, true)) out.push_back(s);
  }
  if (out.empty()) out.push_back({false, "0"});
  return out;
}

std::string time_function(const TimeFunction& f, const RadicalList& radicals, const Format& format, bool frequency_names) {
  return join(time_function_terms(f, radicals, format, frequency_names), format.style);
}

// ---------------------------------------------------------------- rational functions and factors

RationalFunction rational_function(const ex& expression, const symbol& s) {
  (void)s;
  const PolyFraction f = fraction_of(expression);
  RationalFunction r;
  ex n = 0, d = 1;
  for (const Monomial& m : f.numerator) n += to_ex(m);
  if (!f.denominator.empty()) {
    d = 0;
    for (const Monomial& m : f.denominator) d += to_ex(m);
  } else {
    // negative powers (of s, or of parameters) back into a denominator
    ex common = 1;
    for (const Monomial& m : f.numerator)
      for (const auto& [a, k] : m.atoms)
        if (k < 0) common = lcm(common, pow(a.value, -k));
    n = expand(n * common);
    d = common;
    const PolyFraction g = fraction_of(n / d);
    if (!g.denominator.empty()) {
      n = 0;
      for (const Monomial& m : g.numerator) n += to_ex(m);
      d = 0;
      for (const Monomial& m : g.denominator) d += to_ex(m);
    }
  }
  // integer coefficients throughout
  const Poly pn = read_poly(expand(n)), pd = read_poly(expand(d));
  const numeric l = lcm(content_lcm_of_denominators(pn), content_lcm_of_denominators(pd));
  r.numerator = expand(n * l);
  r.denominator = expand(d * l);
  return r;
}

std::string print(const RationalFunction& f, const Format& format) {
  const Poly n = read_poly(f.numerator), d = read_poly(f.denominator);
  if (is_one(d)) return poly_text(n, format);
  const std::string top = poly_text(n, format), bottom = poly_text(d, format);
  if (format.style == Style::Text) return "(" + top + ")/(" + bottom + ")";
  return latex_fraction(top, bottom);
}

std::string factored(const ex& constant, const std::vector<std::pair<ex, unsigned>>& factors, const Format& format) {
  struct Item {
    ex factor;
    unsigned multiplicity;
    int degree;
    double root;
    std::string key;
  };
  const symbol& s = derivation_symbols().s;
  std::vector<Item> items;
  for (const auto& [factor, m] : factors) {
    Item item{factor, m, factor.degree(s), 0.0, text(factor)};
    if (item.degree == 1) {
      try {
        item.root = to_double(-factor.coeff(s, 0) / factor.coeff(s, 1), {});
      } catch (...) {
      }
    }
    items.push_back(item);
  }
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (a.degree != b.degree) return a.degree < b.degree;
    if (a.root != b.root) return a.root > b.root;
    return a.key < b.key;
  });
  std::string out;
  const bool text_style = format.style == Style::Text;
  if (!(is_a<numeric>(constant) && ex_to<numeric>(constant) == 1)) {
    const std::string c = print(constant, format);
    if (c == "-1") out += "-";
    else out += (c.find_first_of("+-", 1) != std::string::npos) ? (text_style ? "(" + c + ")" : "\\left(" + c + "\\right)") : c;
  }
  for (const Item& item : items) {
    const std::string body = print(item.factor, format);
    const bool bare = is_a<symbol>(item.factor) || (items.size() == 1 && item.multiplicity == 1 && out.empty());
    std::string piece = bare ? body : (text_style ? "(" + body + ")" : "(" + body + ")");
    if (item.multiplicity > 1)
      piece += text_style ? "^" + std::to_string(item.multiplicity) : "^{" + std::to_string(item.multiplicity) + "}";
    if (text_style && !out.empty() && out != "-") out += "*";
    out += piece;
  }
  return out.empty() ? "1" : out;
}

std::string display(const std::string& lhs, const std::vector<Summand>& rhs, const std::string& tag, std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t used = visible_width(lhs) + 3;
  for (std::size_t i = 0; i < rhs.size(); ++i) {
    const Summand& t = rhs[i];
    std::string piece = (i == 0) ? std::string(t.negative ? "-" : "") + t.body : std::string(t.negative ? " - " : " + ") + t.body;
    const std::size_t w = visible_width(piece);
    if (i > 0 && used + w > width && !line.empty()) {
      lines.push_back(line);
      line.clear();
      used = 8;
    }
    line += piece;
    used += w;
  }
  lines.push_back(line);
  const std::string tag_text = tag.empty() ? "" : " \\tag{" + tag + "}";
  if (lines.size() == 1) return lhs + " = " + lines.front() + tag_text;
  std::string out = "\\begin{aligned}" + lhs + " &= " + lines.front();
  for (std::size_t i = 1; i < lines.size(); ++i) out += " \\\\\n&\\quad " + lines[i];
  return out + "\\end{aligned}" + tag_text;
}

}  // namespace backlash::symbolic::pretty
