#include "printer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace backlash::codegen::detail {

using namespace GiNaC;

std::string double_literal(double value) {
  if (!std::isfinite(value)) throw std::domain_error("codegen: non-finite constant");
  char buffer[64];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  std::string text(buffer);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

bool fits_double_exactly(const numeric& rational) {
  static const numeric limit = numeric(2).power(53);
  return rational.is_rational() && abs(rational.numer()) <= limit && abs(rational.denom()) <= limit;
}

double evaluate_to_double(const ex& expression) {
  const long saved = Digits;
  Digits = 40;
  ex value;
  try {
    value = evalf(expression);
  } catch (...) {
    Digits = saved;
    throw;
  }
  Digits = saved;
  if (!is_a<numeric>(value) || !ex_to<numeric>(value).is_real())
    throw std::domain_error(std::string("codegen: not a real number: ") + print(expression, Style::Text));
  return ex_to<numeric>(value).to_double();
}

ex expanded(const ex& expression) { return expression.expand(expand_options::expand_function_args); }

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

namespace {

std::string integer_text(const numeric& integer) {
  std::ostringstream out;
  out << integer;
  return out.str();
}

std::string join(std::vector<std::string> parts, const std::string& separator, bool sort = true) {
  if (sort) std::sort(parts.begin(), parts.end());
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i) out += separator;
    out += parts[i];
  }
  return out;
}

// Sum text (operands sorted) with "+ -x" written "- x"; an add has at least two operands.
std::string join_sum(std::vector<std::string> parts) {
  std::sort(parts.begin(), parts.end(), [](const std::string& a, const std::string& b) {
    // order by the text without a leading sign, so x and -x sort together
    const std::string ka = a.rfind("-", 0) == 0 ? a.substr(1) : a, kb = b.rfind("-", 0) == 0 ? b.substr(1) : b;
    return ka != kb ? ka < kb : a < b;
  });
  return join_terms(parts);
}

std::string number(const numeric& value, Style style) {
  if (!value.is_rational()) throw std::domain_error("codegen: a floating-point number reached the emitter");
  const numeric p = value.numer(), q = value.denom();
  switch (style) {
    case Style::Cpp: return rational_literal(value);
    case Style::Text: return q == 1 ? integer_text(p) : integer_text(p) + "/" + integer_text(q);
    case Style::Latex:
      if (q == 1) return integer_text(p);
      return (p.is_negative() ? std::string("-") : std::string()) + "\\frac{" + integer_text(abs(p)) + "}{" +
             integer_text(q) + "}";
  }
  return "";
}

bool is_sum(const ex& e) { return is_a<add>(e); }

std::string group(const std::string& text, Style style) {
  return style == Style::Latex ? std::string("\\left(") + text + "\\right)" : std::string("(") + text + ")";
}

std::string print_power(const ex& base, const numeric& n, Style style);

std::string factor_text(const ex& e, Style style) {
  // a factor inside a product: sums are grouped, negative numbers too
  const std::string text = print(e, style);
  if (is_sum(e)) return style == Style::Cpp ? text : group(text, style);
  return text;
}

std::string print_product(const numeric& coefficient, const std::vector<ex>& numerator_factors,
                          const std::vector<ex>& denominator_factors, Style style) {
  std::vector<std::string> top, bottom;
  for (const ex& f : numerator_factors) top.push_back(factor_text(f, style));
  for (const ex& f : denominator_factors) bottom.push_back(factor_text(f, style));
  if (!coefficient.is_rational()) throw std::domain_error("codegen: a floating-point number reached the emitter");
  const numeric p = coefficient.numer(), q = coefficient.denom();
  if (style == Style::Cpp) {
    std::string head;
    if (!fits_double_exactly(coefficient)) {
      head = rational_literal(coefficient);
    } else {
      if (p != 1 || top.empty()) head = p.is_negative() ? std::string("(") + integer_text(p) + ".0)" : integer_text(p) + ".0";
      if (p == -1 && !top.empty()) head = "-1.0";
      if (q != 1) bottom.push_back(integer_text(q) + ".0");
    }
    std::string text = head;
    if (!top.empty()) text += (text.empty() ? std::string() : std::string("*")) + join(top, "*");
    if (!bottom.empty()) text += std::string("/(") + join(bottom, "*") + ")";
    return std::string("(") + text + ")";
  }
  if (style == Style::Text) {
    std::string text;
    const bool negative = p.is_negative();
    const numeric magnitude = abs(coefficient);
    if (magnitude != 1 || top.empty()) text = number(magnitude, style);
    if (!top.empty()) text += (text.empty() ? std::string() : std::string("*")) + join(top, "*");
    if (!bottom.empty()) text += bottom.size() == 1 ? std::string("/") + bottom.front() : std::string("/(") + join(bottom, "*") + ")";
    return negative ? std::string("-") + text : text;
  }
  // LaTeX
  const bool negative = p.is_negative();
  const numeric ap = abs(p);
  std::string num = join(top, " ");
  if (ap != 1 || num.empty()) num = integer_text(ap) + (num.empty() ? std::string() : std::string(" ") + num);
  if (q != 1) bottom.push_back(integer_text(q));
  std::string text = bottom.empty() ? num : std::string("\\frac{") + num + "}{" + join(bottom, " ") + "}";
  return negative ? std::string("-") + text : text;
}

std::string print_power(const ex& base, const numeric& n, Style style) {
  if (n.is_integer() && n.is_positive()) {
    const long k = n.to_long();
    if (style == Style::Cpp) {
      const std::string b = print(base, style);
      if (k == 1) return b;
      std::vector<std::string> copies(static_cast<std::size_t>(k), b);
      return std::string("(") + join(copies, "*") + ")";
    }
    const std::string b = is_sum(base) || is_a<mul>(base) || is_a<power>(base) ? group(print(base, style), style)
                                                                               : print(base, style);
    if (style == Style::Text) return b + "^" + integer_text(n);
    return b + "^{" + integer_text(n) + "}";
  }
  if (n.is_integer() && n.is_negative()) {
    const std::string inverse = print_power(base, -n, style);
    if (style == Style::Latex) return std::string("\\frac{1}{") + inverse + "}";
    return std::string("(1") + (style == Style::Cpp ? ".0" : "") + "/" + inverse + ")";
  }
  if (n == numeric(1, 2)) {
    if (style == Style::Cpp) return std::string("std::sqrt(") + print(base, style) + ")";
    if (style == Style::Text) return std::string("sqrt(") + print(base, style) + ")";
    return std::string("\\sqrt{") + print(base, style) + "}";
  }
  if (n == numeric(-1, 2)) {
    const std::string root = print_power(base, numeric(1, 2), style);
    if (style == Style::Latex) return std::string("\\frac{1}{") + root + "}";
    return std::string("(1") + (style == Style::Cpp ? ".0" : "") + "/" + root + ")";
  }
  if (style == Style::Cpp) return std::string("std::pow(") + print(base, style) + ", " + number(n, style) + ")";
  if (style == Style::Text) return group(print(base, style), style) + "^(" + number(n, style) + ")";
  return group(print(base, style), style) + "^{" + number(n, style) + "}";
}

}  // namespace

std::string print(const ex& e, Style style) {
  if (is_a<numeric>(e)) return number(ex_to<numeric>(e), style);
  if (is_a<symbol>(e)) {
    const symbol& s = ex_to<symbol>(e);
    if (style == Style::Latex) {
      const std::string tex = s.get_TeX_name();
      return tex.empty() ? s.get_name() : tex;
    }
    return s.get_name();
  }
  if (is_a<add>(e)) {
    std::vector<std::string> parts;
    for (const ex& operand : e) parts.push_back(print(operand, style));
    if (style == Style::Cpp) return std::string("(") + join(parts, " + ") + ")";
    return join_sum(parts);
  }
  if (is_a<mul>(e)) {
    numeric coefficient = 1;
    std::vector<ex> top, bottom;
    for (const ex& factor : e) {
      if (is_a<numeric>(factor)) {
        coefficient *= ex_to<numeric>(factor);
      } else if (is_a<power>(factor) && is_a<numeric>(factor.op(1)) && ex_to<numeric>(factor.op(1)).is_integer() &&
                 ex_to<numeric>(factor.op(1)).is_negative()) {
        bottom.push_back(pow(factor.op(0), -factor.op(1)));
      } else {
        top.push_back(factor);
      }
    }
    return print_product(coefficient, top, bottom, style);
  }
  if (is_a<power>(e) && is_a<numeric>(e.op(1))) return print_power(e.op(0), ex_to<numeric>(e.op(1)), style);
  if (is_a<function>(e)) {
    const std::string name = ex_to<function>(e).get_name();
    if (name == "exp" || name == "cos" || name == "sin" || name == "sqrt" || name == "log") {
      const std::string argument = print(e.op(0), style);
      if (style == Style::Cpp) return std::string("std::") + name + "(" + argument + ")";
      if (style == Style::Text) return name + "(" + argument + ")";
      if (name == "exp") return std::string("e^{") + argument + "}";
      if (name == "sqrt") return std::string("\\sqrt{") + argument + "}";
      return std::string("\\") + name + "\\left(" + argument + "\\right)";
    }
  }
  std::ostringstream out;
  out << e;
  throw std::domain_error(std::string("codegen: cannot print: ") + out.str());
}

std::string rational_literal(const numeric& value) {
  if (!value.is_rational()) throw std::domain_error("codegen: a floating-point number reached the emitter");
  if (!fits_double_exactly(value)) return std::string("(") + double_literal(evaluate_to_double(value)) + ")";
  const numeric p = value.numer(), q = value.denom();
  if (q == 1) return value.is_negative() ? std::string("(") + integer_text(p) + ".0)" : integer_text(p) + ".0";
  return std::string("(") + integer_text(p) + ".0/" + integer_text(q) + ".0)";
}

namespace {

// The numeric coefficient of a monomial and the monomial without it.
std::pair<numeric, ex> split_monomial(const ex& term) {
  if (is_a<numeric>(term)) return {ex_to<numeric>(term), 1};
  if (is_a<mul>(term)) {
    numeric c = 1;
    ex rest = 1;
    for (const ex& f : term) {
      if (is_a<numeric>(f)) c *= ex_to<numeric>(f);
      else rest *= f;
    }
    return {c, rest};
  }
  return {1, term};
}

}  // namespace

Fraction canonical_fraction(const ex& expression) {
  const ex nd = normal(expression).numer_denom();
  ex numerator = expanded(nd.op(0)), denominator = expanded(nd.op(1));
  // scale so that the denominator's first monomial (by printed text) has coefficient 1
  std::vector<ex> terms;
  if (is_a<add>(denominator)) {
    for (const ex& t : denominator) terms.push_back(t);
  } else {
    terms.push_back(denominator);
  }
  std::string best_key;
  numeric scale = 1;
  bool first = true;
  for (const ex& t : terms) {
    const auto [c, rest] = split_monomial(t);
    const std::string key = print(rest, Style::Text);
    if (first || key < best_key) {
      best_key = key;
      scale = c;
      first = false;
    }
  }
  if (scale != 1) {
    numerator = expanded(numerator / scale);
    denominator = expanded(denominator / scale);
  }
  return {numerator, denominator};
}

std::string print(const Fraction& f, Style style) {
  if (f.denominator.is_equal(ex(1))) return print(f.numerator, style);
  const std::string top = print(f.numerator, style), bottom = print(f.denominator, style);
  if (style == Style::Latex) return std::string("\\frac{") + top + "}{" + bottom + "}";
  const std::string t = is_a<add>(f.numerator) && style != Style::Cpp ? std::string("(") + top + ")" : top;
  const std::string b = (is_a<add>(f.denominator) || is_a<mul>(f.denominator)) && style != Style::Cpp
                            ? std::string("(") + bottom + ")"
                            : bottom;
  if (style == Style::Cpp) return std::string("(") + t + "/" + b + ")";
  return t + "/" + b;
}

}  // namespace backlash::codegen::detail
