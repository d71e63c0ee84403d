#include "backlash/symbolic/time_function.hpp"

#include <algorithm>

namespace backlash::symbolic {

using namespace GiNaC;

TimeFunction TimeFunction::constant(const ex& value) {
  return TimeFunction({ExpTerm{value, 0, 0, Oscillation::None, 0}});
}

TimeFunction TimeFunction::derivative() const {
  std::vector<ExpTerm> out;
  for (const ExpTerm& term : terms_) {
    if (term.t_power > 0)
      out.push_back({term.coefficient * term.t_power, term.t_power - 1, term.rate, term.oscillation, term.frequency});
    if (!term.rate.is_zero())
      out.push_back({term.coefficient * term.rate, term.t_power, term.rate, term.oscillation, term.frequency});
    if (term.oscillation == Oscillation::Cos)
      out.push_back({-term.coefficient * term.frequency, term.t_power, term.rate, Oscillation::Sin, term.frequency});
    if (term.oscillation == Oscillation::Sin)
      out.push_back({term.coefficient * term.frequency, term.t_power, term.rate, Oscillation::Cos, term.frequency});
  }
  return TimeFunction(std::move(out));
}

TimeFunction TimeFunction::operator+(const TimeFunction& other) const {
  std::vector<ExpTerm> out = terms_;
  out.insert(out.end(), other.terms_.begin(), other.terms_.end());
  return TimeFunction(std::move(out));
}

TimeFunction TimeFunction::operator*(const ex& factor) const {
  std::vector<ExpTerm> out = terms_;
  for (ExpTerm& term : out) term.coefficient = term.coefficient * factor;
  return TimeFunction(std::move(out));
}

TimeFunction TimeFunction::operator-(const TimeFunction& other) const { return *this + other * ex(-1); }

namespace {

bool same_shape(const ExpTerm& a, const ExpTerm& b, const RadicalList& radicals) {
  if (a.t_power != b.t_power || a.oscillation != b.oscillation) return false;
  if (a.oscillation != Oscillation::None && !is_exactly_zero(a.frequency - b.frequency, radicals)) return false;
  return is_exactly_zero(a.rate - b.rate, radicals);
}

// Sort key: numeric value of the rate where it has one.
double rate_value(const ex& rate, const RadicalList& radicals) {
  try {
    return to_double(rate, radicals);
  } catch (...) {
    return 0.0;
  }
}

}  // namespace

TimeFunction TimeFunction::combined(const RadicalList& radicals) const {
  std::vector<ExpTerm> out;
  for (const ExpTerm& term : terms_) {
    auto same = std::find_if(out.begin(), out.end(), [&](const ExpTerm& o) { return same_shape(o, term, radicals); });
    if (same == out.end()) out.push_back(term); else same->coefficient += term.coefficient;
  }
  std::vector<ExpTerm> kept;
  for (ExpTerm& term : out) {
    term.coefficient = simplify(term.coefficient, radicals);
    term.rate = simplify(term.rate, radicals);
    if (!term.coefficient.is_zero()) kept.push_back(term);
  }
  std::stable_sort(kept.begin(), kept.end(), [&](const ExpTerm& a, const ExpTerm& b) {
    if ((a.oscillation == Oscillation::None) != (b.oscillation == Oscillation::None))
      return a.oscillation == Oscillation::None;
    const double ra = rate_value(a.rate, radicals), rb = rate_value(b.rate, radicals);
    if (ra != rb) return ra > rb;
    if (text(a.rate) != text(b.rate)) return text(a.rate) < text(b.rate);
    if (a.t_power != b.t_power) return a.t_power < b.t_power;
    return static_cast<int>(a.oscillation) < static_cast<int>(b.oscillation);
  });
  return TimeFunction(std::move(kept));
}

bool TimeFunction::is_zero(const RadicalList& radicals) const { return combined(radicals).terms_.empty(); }

ex TimeFunction::at_zero() const {
  ex value = 0;
  for (const ExpTerm& term : terms_)
    if (term.t_power == 0 && term.oscillation != Oscillation::Sin) value += term.coefficient;
  return value;
}

ex TimeFunction::coefficient(unsigned t_power, const ex& rate, Oscillation oscillation, const RadicalList& radicals) const {
  ex sum = 0;
  for (const ExpTerm& term : terms_)
    if (term.t_power == t_power && term.oscillation == oscillation && is_exactly_zero(term.rate - rate, radicals))
      sum += term.coefficient;
  return simplify(sum, radicals);
}

ex TimeFunction::to_ex(const ex& t) const {
  ex sum = 0;
  for (const ExpTerm& term : terms_) {
    ex piece = term.coefficient * pow(t, term.t_power) * exp(term.rate * t);
    if (term.oscillation == Oscillation::Cos) piece *= cos(term.frequency * t);
    if (term.oscillation == Oscillation::Sin) piece *= sin(term.frequency * t);
    sum += piece;
  }
  return sum;
}

TimeFunction TimeFunction::subs(const exmap& substitution) const {
  std::vector<ExpTerm> out = terms_;
  for (ExpTerm& term : out) {
    term.coefficient = term.coefficient.subs(substitution);
    term.rate = term.rate.subs(substitution);
    term.frequency = term.frequency.subs(substitution);
  }
  return TimeFunction(std::move(out));
}

}  // namespace backlash::symbolic
