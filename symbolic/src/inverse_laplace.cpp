#include "backlash/symbolic/inverse_laplace.hpp"

#include <stdexcept>

namespace backlash::symbolic {

using namespace GiNaC;

namespace {

numeric factorial_of(unsigned n) { return factorial(numeric(n)); }

// Split a factored expression into (base, exponent) pairs; numeric or s-free
// constants are multiplied into `constant`.
void collect_factors(const ex& factored, const symbol& s, std::vector<std::pair<ex, unsigned>>& factors, ex& constant) {
  if (is_a<mul>(factored)) {
    for (size_t i = 0; i < factored.nops(); ++i) collect_factors(factored.op(i), s, factors, constant);
    return;
  }
  if (!factored.has(s)) { constant *= factored; return; }
  if (is_a<power>(factored) && is_a<numeric>(factored.op(1)) && ex_to<numeric>(factored.op(1)).is_pos_integer()) {
    const unsigned exponent = ex_to<numeric>(factored.op(1)).to_int();
    std::vector<std::pair<ex, unsigned>> inner;
    ex inner_constant = 1;
    collect_factors(factored.op(0), s, inner, inner_constant);
    constant *= pow(inner_constant, exponent);
    for (auto& [base, m] : inner) factors.emplace_back(base, m * exponent);
    return;
  }
  factors.emplace_back(factored, 1u);
}

std::string radical_label(const std::string& name, const RadicalList& radicals) {
  std::string label = name;
  for (int k = 2;; ++k) {
    bool used = false;
    for (const Radical& r : radicals) used = used || r.symbol.get_name() == label;
    if (!used) return label;
    label = name + "_" + std::to_string(k);
  }
}

// Sign of an exact square-candidate; +1, 0, -1, or 2 when undecidable.
int exact_sign(const ex& value) {
  if (!is_a<numeric>(value)) return 2;
  const numeric n = ex_to<numeric>(value);
  if (!n.is_real()) return 2;
  return n.is_zero() ? 0 : (n.is_positive() ? 1 : -1);
}

bool has_fractional_power(const ex& e) {
  if (is_a<power>(e) && is_a<numeric>(e.op(1)) && !ex_to<numeric>(e.op(1)).is_integer()) return true;
  for (size_t i = 0; i < e.nops(); ++i)
    if (has_fractional_power(e.op(i))) return true;
  return false;
}

}  // namespace

std::vector<Pole> find_poles(const ex& denominator, const symbol& s, RadicalList& radicals, const std::string& radical_name,
                             const std::string& radical_role) {
  const ex expanded = expand(denominator);
  if (!expanded.is_polynomial(s)) throw std::domain_error("inverse_laplace: denominator is not a polynomial in s");
  const ex factored = factor(expanded);
  std::vector<std::pair<ex, unsigned>> factors;
  ex constant = 1;
  collect_factors(factored, s, factors, constant);

  std::vector<Pole> poles;
  for (const auto& [base, multiplicity] : factors) {
    const ex f = expand(base);
    const int degree = f.degree(s);
    if (degree == 1) {
      const ex a = f.coeff(s, 1), b = f.coeff(s, 0);
      poles.push_back({Pole::Kind::Real, normal(-b / a), 0, multiplicity, f});
      continue;
    }
    if (degree == 2) {
      const ex a = f.coeff(s, 2), b = f.coeff(s, 1), c = f.coeff(s, 0);
      const ex center = normal(-b / (2 * a));
      const ex quarter_discriminant = normal((b * b - 4 * a * c) / (4 * a * a));  // δ², or −ω²
      int sign = exact_sign(quarter_discriminant);
      const Radical* known = nullptr;
      ex explicit_half_width;  // a half-width that needs no radical
      if (sign == 2) {
        // A branch parametrisation writes ±disc/(4a²) as the square of a positive
        // parameter (ω², δ²): GiNaC's sqrt of it is then free of fractional powers.
        for (int candidate_sign : {-1, 1}) {
          const ex root = sqrt(candidate_sign * quarter_discriminant);
          if (!has_fractional_power(root) && !root.has(I)) { explicit_half_width = root; sign = candidate_sign; break; }
        }
      }
      if (sign != 2 && sign != 0 && explicit_half_width.is_zero()) {
        const ex root = canonical_sqrt(sign < 0 ? ex(-quarter_discriminant) : quarter_discriminant);
        if (is_a<numeric>(root)) explicit_half_width = root;
      }
      if (!explicit_half_width.is_zero()) {
        poles.push_back({sign < 0 ? Pole::Kind::ComplexPair : Pole::Kind::RealPair, center, explicit_half_width, multiplicity, f});
        continue;
      }
      if (sign == 2) {
        if ((known = find_radical_with_square(radicals, -quarter_discriminant))) sign = -1;
        else if ((known = find_radical_with_square(radicals, quarter_discriminant))) sign = 1;
        else
          throw std::domain_error("inverse_laplace: cannot decide the sign of the discriminant of " + text(f) +
                                  " (b^2-4ac)/(4a^2) = " + text(quarter_discriminant) +
                                  "; derive it in a pole-structure branch");
      }
      if (sign == 0) {  // a perfect square that factor() left alone (symbolic): double real pole
        poles.push_back({Pole::Kind::Real, center, 0, 2 * multiplicity, f});
        continue;
      }
      const ex square = sign < 0 ? ex(-quarter_discriminant) : quarter_discriminant;
      if (!known) known = find_radical_with_square(radicals, square);
      if (!known) {
        radicals.push_back({possymbol(radical_label(radical_name, radicals)), square, radical_role});
        known = &radicals.back();
      }
      poles.push_back({sign < 0 ? Pole::Kind::ComplexPair : Pole::Kind::RealPair, center, known->symbol, multiplicity, f});
      continue;
    }
    throw std::domain_error("inverse_laplace: irreducible factor of degree " + std::to_string(degree) + " (" + text(f) +
                            ") is not supported");
  }
  return poles;
}

std::vector<std::pair<ex, ex>> pole_locations(const Pole& pole, const symbol& i) {
  std::vector<std::pair<ex, ex>> locations;
  switch (pole.kind) {
    case Pole::Kind::Real: locations.push_back({pole.center, 0}); break;
    case Pole::Kind::RealPair:
      locations.push_back({pole.center + pole.half_width, pole.center - pole.half_width});
      locations.push_back({pole.center - pole.half_width, pole.center + pole.half_width});
      break;
    case Pole::Kind::ComplexPair:
      locations.push_back({pole.center + i * pole.half_width, pole.center - i * pole.half_width});
      break;
  }
  return locations;
}

TimeFunction inverse_laplace(const ex& transform, const symbol& s, RadicalList& radicals, const std::string& radical_name,
                             const std::string& radical_role) {
  const ex fraction = numer_denom(normal(transform));
  const ex numerator = expand(fraction.op(0));
  const ex denominator = expand(fraction.op(1));
  if (!numerator.is_polynomial(s)) throw std::domain_error("inverse_laplace: numerator is not a polynomial in s");
  if (numerator.is_zero()) return TimeFunction{};
  if (numerator.degree(s) >= denominator.degree(s))
    throw std::domain_error("inverse_laplace: improper rational function (impulsive response): " + text(transform));

  const std::vector<Pole> poles = find_poles(denominator, s, radicals, radical_name, radical_role);
  const Radical& i = imaginary_unit();
  RadicalList with_i = radicals;
  with_i.push_back(i);

  std::vector<ExpTerm> terms;
  for (const Pole& pole : poles) {
    const unsigned m = pole.multiplicity;
    // D = pole.factor^m · rest(s), exactly.
    const ex factor_power = expand(pow(pole.factor, m));
    const ex rest = quo(denominator, factor_power, s, false);
    if (!normal(rem(denominator, factor_power, s, false)).is_zero())
      throw std::logic_error("inverse_laplace: pole factor does not divide the denominator");
    const ex leading = pole.factor.coeff(s, pole.factor.degree(s));

    // (p, partner) with H = N / (lead^m (s-partner)^m rest)
    for (const auto& [p, partner] : pole_locations(pole, i.symbol)) {
      ex H = numerator / (pow(leading, m) * rest);
      if (pole.kind != Pole::Kind::Real) H = H / pow(s - partner, m);
      ex derivative = H;
      for (unsigned j = 0; j < m; ++j) {
        if (j > 0) derivative = derivative.diff(s);
        const unsigned k = m - 1 - j;
        const ex value = simplify(derivative.subs(s == p) / (factorial_of(j) * factorial_of(k)), with_i);
        if (pole.kind == Pole::Kind::ComplexPair) {
          // 2 Re(c e^{iωt}) = 2 Re c cos ωt − 2 Im c sin ωt
          const ex real_part = value.subs(i.symbol == 0);
          const ex imag_part = simplify(value.coeff(i.symbol, 1), with_i);
          if (!simplify(value - real_part - imag_part * i.symbol, with_i).is_zero())
            throw std::logic_error("inverse_laplace: residue not linear in i");
          terms.push_back({2 * real_part, k, pole.center, Oscillation::Cos, pole.half_width});
          terms.push_back({-2 * imag_part, k, pole.center, Oscillation::Sin, pole.half_width});
        } else {
          terms.push_back({value, k, p, Oscillation::None, 0});
        }
      }
    }
  }
  return TimeFunction(std::move(terms)).combined(radicals);
}

}  // namespace backlash::symbolic
