#include "backlash/symbolic/derivation_steps.hpp"

#include <stdexcept>

namespace backlash::symbolic {

using namespace GiNaC;

namespace {

numeric factorial_of(unsigned n) { return factorial(numeric(n)); }

// The poles of the denominator (new radicals are added to `known`).  factor() returns its factors in
// GiNaC's hash order and with either sign: give each a leading coefficient (in s) whose first printed
// term is positive, and sort them (real poles first, then by value).
std::vector<Pole> ordered_poles(const ex& denominator, const symbol& s, RadicalList& known) {
  std::vector<Pole> poles = find_poles(denominator, s, known, "omega", "");
  for (Pole& p : poles) {
    const ex lc = p.factor.coeff(s, p.factor.degree(s));
    if (pretty::text(lc).rfind("-", 0) == 0) p.factor = expand(-p.factor);
  }
  struct Keyed {
    Pole pole;
    int kind;
    double value;
    std::string text;
  };
  std::vector<Keyed> keyed;
  for (const Pole& p : poles) {
    Keyed k{p, static_cast<int>(p.kind), 0.0, pretty::text(p.center)};
    try {
      k.value = to_double(p.center, known);
    } catch (...) {
      k.value = 0.0;
    }
    keyed.push_back(k);
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    if (a.kind != b.kind) return a.kind < b.kind;
    if (a.value != b.value) return a.value > b.value;
    return a.text < b.text;
  });
  poles.clear();
  for (const Keyed& k : keyed) poles.push_back(k.pole);
  return poles;
}

// Where a pole's residues are taken, each with its partner (the pair's other pole; 0 for a real pole).
// What the residues add up, in order: the partial fractions (to compare with the transform) and the time terms.
struct ResidueSums {
  std::vector<ExpTerm> terms;
  ex partial_sum = 0;
};

// The coefficients A_r = (1/(m−r)!) d^{m−r}/ds^{m−r}[H](p) at one location p of a pole of multiplicity m, where
// H = N/(rest · leading^m) (÷ (s − partner)^m for a pair); each adds its partial fraction and time terms to `sums`.
PoleResidues::Location location_residues(const Pole& pole, const ex& p, const ex& partner, const ex& H0, const symbol& s,
                                         const RadicalList& with_i, ResidueSums& sums) {
  const symbol& i = imaginary_unit().symbol;
  const unsigned m = pole.multiplicity;
  PoleResidues::Location location{p, {}};
  ex H = H0;
  if (pole.kind != Pole::Kind::Real) H = H / pow(s - partner, m);
  std::vector<ex> derivatives{H};
  for (unsigned j = 1; j < m; ++j) derivatives.push_back(derivatives.back().diff(s));
  location.coefficients.resize(m);
  for (unsigned r = 1; r <= m; ++r) {
    const unsigned j = m - r;
    const ex A = simplify(derivatives[j].subs(s == p) / factorial_of(j), with_i);
    location.coefficients[r - 1] = A;
    const ex time_coefficient = A / factorial_of(r - 1);
    if (pole.kind == Pole::Kind::ComplexPair) {
      const ex conjugate_A = A.subs(i == -i), conjugate_p = p.subs(i == -i);
      sums.partial_sum += A / pow(s - p, r) + conjugate_A / pow(s - conjugate_p, r);
      const ex real_part = simplify(time_coefficient.subs(i == 0), with_i);
      const ex imag_part = simplify(time_coefficient.coeff(i, 1), with_i);
      sums.terms.push_back({2 * real_part, r - 1, pole.center, Oscillation::Cos, pole.half_width});
      sums.terms.push_back({-2 * imag_part, r - 1, pole.center, Oscillation::Sin, pole.half_width});
    } else {
      sums.partial_sum += A / pow(s - p, r);
      sums.terms.push_back({time_coefficient, r - 1, p, Oscillation::None, 0});
    }
  }
  return location;
}

// One pole's residues at each of its locations.
PoleResidues pole_residues(const Pole& pole, const ex& numerator, const ex& denominator, const symbol& s, const RadicalList& with_i,
                           ResidueSums& sums) {
  PoleResidues row;
  row.pole = pole;
  const unsigned m = pole.multiplicity;
  const ex factor_power = expand(pow(pole.factor, m));
  const ex rest = quo(expand(denominator), factor_power, s, false);
  const ex leading = pole.factor.coeff(s, pole.factor.degree(s));
  for (const auto& [p, partner] : pole_locations(pole, imaginary_unit().symbol))
    row.locations.push_back(location_residues(pole, p, partner, numerator / (pow(leading, m) * rest), s, with_i, sums));
  return row;
}

}  // namespace

SegmentSteps segment_steps(const Segment& segment, const RadicalList& radicals) {
  SegmentSteps steps;
  const symbol& s = derivation_symbols().s;
  steps.transform = pretty::rational_function(segment.laplace, s);
  const ex numerator = steps.transform.numerator, denominator = steps.transform.denominator;

  RadicalList known = radicals;
  const std::vector<Pole> poles = ordered_poles(denominator, s, known);
  RadicalList with_i = known;
  with_i.push_back(imaginary_unit());
  steps.radicals = known;

  ex product = 1;
  for (const Pole& p : poles) {
    steps.factors.emplace_back(p.factor, p.multiplicity);
    product *= pow(p.factor, p.multiplicity);
  }
  steps.leading_constant = normal(denominator / expand(product));

  ResidueSums sums;
  for (const Pole& pole : poles) steps.poles.push_back(pole_residues(pole, numerator, denominator, s, with_i, sums));
  steps.from_residues = TimeFunction(std::move(sums.terms)).combined(known);
  steps.partial_fractions_sum_to_transform = is_exactly_zero(sums.partial_sum - segment.laplace, with_i);
  steps.residues_give_solution = (steps.from_residues - segment.solution).is_zero(known);
  return steps;
}

std::string pole_latex(const Pole& pole, const RadicalList& radicals) {
  const std::string center = pretty::latex(with_explicit_radicals(pole.center, radicals));
  if (pole.kind == Pole::Kind::Real) return center;
  const std::string width =
      is_a<symbol>(pole.half_width) ? pretty::latex_symbol_name(ex_to<symbol>(pole.half_width).get_name())
                                    : pretty::latex(with_explicit_radicals(pole.half_width, radicals));
  const std::string prefix = center == "0" ? "" : center + " ";
  if (pole.kind == Pole::Kind::ComplexPair) return prefix + "\\pm \\mathrm{i}\\," + width;
  return prefix + "\\pm " + width;
}

std::vector<pretty::Summand> partial_fraction_terms(const SegmentSteps& steps, const pretty::Format& format) {
  const symbol& s = derivation_symbols().s;
  std::vector<pretty::Summand> out;
  for (const PoleResidues& row : steps.poles) {
    const Pole& pole = row.pole;
    if (pole.kind == Pole::Kind::ComplexPair && pole.multiplicity == 1) {
      // A/(s − p) + Ā/(s − p̄) = (P (s − α) + Q ω)/((s − α)² + ω²), P = 2 Re A, Q = −2 Im A
      const symbol& i = imaginary_unit().symbol;
      const ex A = row.locations.front().coefficients.front();
      const ex P = simplify(2 * A.subs(i == 0), steps.radicals);
      const ex Q = simplify(-2 * A.coeff(i, 1), steps.radicals);
      const std::string shifted = pretty::latex(s - with_explicit_radicals(pole.center, steps.radicals));
      const std::string omega = is_a<symbol>(pole.half_width)
                                    ? pretty::latex_symbol_name(ex_to<symbol>(pole.half_width).get_name())
                                    : pretty::latex(with_explicit_radicals(pole.half_width, steps.radicals));
      const std::string quadratic = "\\left(" + shifted + "\\right)^{2} + " + omega + "^{2}";
      for (const auto& [coefficient, top] : {std::pair{P, shifted}, std::pair{Q, omega}}) {
        if (coefficient.is_zero()) continue;
        const pretty::Summand c = pretty::factor(with_explicit_radicals(coefficient, steps.radicals), format);
        const std::string body = (c.body == "1" ? "" : c.body) + "\\frac{" + top + "}{" + quadratic + "}";
        out.push_back({c.negative, body});
      }
      continue;
    }
    for (const PoleResidues::Location& location : row.locations) {
      const std::string base = pretty::latex(s - with_explicit_radicals(location.at, steps.radicals));
      for (std::size_t r = location.coefficients.size(); r >= 1; --r) {
        const ex& A = location.coefficients[r - 1];
        if (A.is_zero()) continue;
        std::string denominator = base == "s" ? "s" : (r > 1 ? "\\left(" + base + "\\right)" : base);
        if (r > 1) denominator += "^{" + std::to_string(r) + "}";
        const pretty::Summand c = pretty::factor(with_explicit_radicals(A, steps.radicals), format);
        out.push_back({c.negative, (c.body == "1" ? "" : c.body) + "\\frac{1}{" + denominator + "}"});
      }
    }
  }
  if (out.empty()) out.push_back({false, "0"});
  return out;
}

}  // namespace backlash::symbolic
