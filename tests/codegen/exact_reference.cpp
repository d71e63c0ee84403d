#include "exact_reference.hpp"

#include "backlash/symbolic/general_derivation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace backlash::testing {

using namespace GiNaC;

numeric exact_numeric(double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("exact_numeric: not finite");
  if (value == 0) return 0;
  int exponent = 0;
  const double mantissa = std::frexp(value, &exponent);  // value = mantissa·2^exponent, 0.5 ≤ |mantissa| < 1
  const long long integer = static_cast<long long>(std::ldexp(mantissa, 53));
  return numeric(static_cast<long>(integer)) * numeric(2).power(numeric(exponent - 53));
}

model::Rational exact_rational(double value) {
  const numeric q = exact_numeric(value);
  std::ostringstream p, d;
  p << q.numer();
  d << q.denom();
  return model::Rational(boost::multiprecision::cpp_int(p.str()), boost::multiprecision::cpp_int(d.str()));
}

model::Rational decimal_rational(double value) {
  char buffer[64];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*e", digits - 1, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  // buffer = [-]d.ddde[+-]xx
  std::string text(buffer);
  const std::size_t e = text.find('e');
  const int exponent = std::stoi(text.substr(e + 1));
  std::string mantissa = text.substr(0, e);
  const bool negative = !mantissa.empty() && mantissa[0] == '-';
  if (negative) mantissa.erase(0, 1);
  const std::size_t dot = mantissa.find('.');
  int decimals = 0;
  if (dot != std::string::npos) {
    decimals = static_cast<int>(mantissa.size() - dot - 1);
    mantissa.erase(dot, 1);
  }
  boost::multiprecision::cpp_int numerator(mantissa);
  if (negative) numerator = -numerator;
  const int shift = exponent - decimals;
  const boost::multiprecision::cpp_int ten_power = boost::multiprecision::pow(boost::multiprecision::cpp_int(10), std::abs(shift));
  return shift >= 0 ? model::Rational(numerator * ten_power) : model::Rational(numerator, ten_power);
}

model::Rational ratio(long long p, long long q) {
  return model::Rational(boost::multiprecision::cpp_int(p), boost::multiprecision::cpp_int(q));
}

model::Rational ten_to_minus(int k) {
  return model::Rational(boost::multiprecision::cpp_int(1), boost::multiprecision::pow(boost::multiprecision::cpp_int(10), k));
}

model::CaseSpec make_spec(const std::string& id, model::Rational Jm, model::Rational Fm, model::Rational JL,
                          model::Rational FL, model::Rational K, model::Rational theta_R, model::Rational backlash,
                          model::MeasuredAt where) {
  model::CaseSpec spec;
  spec.id = id;
  spec.name = "test " + id;
  spec.measured_at = where;
  spec.Jm = Jm;
  spec.Fm = Fm;
  spec.JL = JL;
  spec.FL = FL;
  spec.K = K;
  spec.reference = theta_R;
  spec.backlash = backlash;
  return spec;
}

ExactCase exact_case(const model::CaseSpec& spec) {
  const symbolic::CaseDerivation d = symbolic::derive_case(spec);
  ExactCase out{symbolic::contact_branch_name(d.contact_branch), symbolic::free_branch_name(d.free_branch), 0, 0, 0, 0, 0, 0, 0, 0};
  const ex& t = symbolic::derivation_symbols().t;
  auto as_ex = [&](const symbolic::TimeFunction& f) { return symbolic::with_explicit_radicals(f.to_ex(t), d.radicals); };
  out.theta_m = as_ex(d.free.motor_position.solution);
  out.dtheta_m = as_ex(d.free.motor_velocity.solution);
  out.theta_L = as_ex(d.free.load_position.solution);
  out.dtheta_L = as_ex(d.free.load_velocity.solution);
  out.gap = as_ex(d.free.gap);
  out.theta_o = as_ex(d.contact.position.solution);
  out.dtheta_o = as_ex(d.contact.velocity.solution);
  out.cot_phi = d.free.cot_phi;
  return out;
}

ExactCase exact_case_from_branches(const model::CaseSpec& spec) {
  static const std::vector<symbolic::GeneralBranch> branches = symbolic::derive_general_branches();
  const symbolic::CaseParameters p = symbolic::exact_parameters(spec);
  ExactCase out{symbolic::contact_branch_name(symbolic::classify_contact(p)),
                symbolic::free_branch_name(symbolic::classify_free(p)), 0, 0, 0, 0, 0, 0, 0, 0};
  const symbolic::GeneralSymbols& g = symbolic::general_symbols();
  const ex& t = symbolic::derivation_symbols().t;
  auto find = [&](const std::string& name) -> const symbolic::GeneralBranch& {
    for (const auto& b : branches)
      if (b.name == name) return b;
    throw std::runtime_error("no general branch " + name);
  };
  auto numbers_for = [&](const symbolic::GeneralBranch& b) {
    exmap numbers{{g.Jm, p.Jm}, {g.Fm, p.Fm}, {g.JL, p.JL}, {g.FL, p.FL}, {g.K, p.K}, {g.theta_R, p.theta_R}};
    for (const symbolic::BranchParameter& bp : b.branch_parameters) {
      const ex square = normal(bp.square_in_physical_parameters.subs(numbers));
      if (!is_a<numeric>(square) || !ex_to<numeric>(square).is_positive())
        throw std::runtime_error("branch parameter square is not positive");
      numbers[bp.symbol] = sqrt(square);  // exact: power(q, 1/2), never a float
    }
    return numbers;
  };
  const symbolic::GeneralBranch& contact = find(out.contact_branch);
  const exmap contact_numbers = numbers_for(contact);
  out.theta_o = contact.contact.position.solution.to_ex(t).subs(contact_numbers);
  out.dtheta_o = contact.contact.velocity.solution.to_ex(t).subs(contact_numbers);
  const symbolic::GeneralBranch& free = find(out.free_branch);
  const exmap free_numbers = numbers_for(free);
  out.theta_m = free.free.motor_position.solution.to_ex(t).subs(free_numbers);
  out.dtheta_m = free.free.motor_velocity.solution.to_ex(t).subs(free_numbers);
  out.theta_L = free.free.load_position.solution.to_ex(t).subs(free_numbers);
  out.dtheta_L = free.free.load_velocity.solution.to_ex(t).subs(free_numbers);
  out.gap = free.free.gap.to_ex(t).subs(free_numbers);
  out.cot_phi = normal(free.free.cot_phi.subs(free_numbers));
  return out;
}

namespace {

double evaluate(const ex& e, const exmap& values, int digits) {
  const long saved = Digits;
  Digits = digits;
  const ex value = evalf(e.subs(values));
  Digits = saved;
  if (!is_a<numeric>(value) || !ex_to<numeric>(value).is_real()) {
    std::ostringstream text;
    text << value;
    throw std::runtime_error("exact reference is not a real number: " + text.str());
  }
  return ex_to<numeric>(value).to_double();
}

}  // namespace

double free_value(const ex& e, double t, double v0, int digits) {
  const symbolic::DerivationSymbols& x = symbolic::derivation_symbols();
  return evaluate(e, {{x.t, exact_numeric(t)}, {x.dtheta_m0, exact_numeric(v0)}}, digits);
}

double contact_value(const ex& e, double t, double theta_o0, double dtheta_o0, int digits) {
  const symbolic::DerivationSymbols& x = symbolic::derivation_symbols();
  return evaluate(e, {{x.t, exact_numeric(t)}, {x.theta_o0, exact_numeric(theta_o0)}, {x.dtheta_o0, exact_numeric(dtheta_o0)}},
                  digits);
}

double scaled_error(double actual, double expected) {
  if (std::isnan(actual)) return INFINITY;
  return std::fabs(actual - expected) / std::max(1.0, std::fabs(expected));
}

}  // namespace backlash::testing
