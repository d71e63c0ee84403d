#include "backlash/symbolic/exact.hpp"

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace backlash::symbolic {

using namespace GiNaC;

const Radical& imaginary_unit() {
  static const Radical unit{realsymbol("i_unit", "\\mathrm{i}"), ex(-1), "imaginary unit"};
  return unit;
}

numeric to_numeric(const model::Rational& value) {
  const std::string exact = model::to_string(value);
  return numeric(exact.c_str());
}

ex reduce_radical_powers(const ex& polynomial, const RadicalList& radicals) {
  ex result = expand(polynomial);
  for (const Radical& radical : radicals) {
    if (!result.has(radical.symbol)) continue;
    const int high = result.degree(radical.symbol);
    const int low = result.ldegree(radical.symbol);
    if (low < 0) throw std::logic_error("reduce_radical_powers: negative power of " + text(radical.symbol));
    if (high < 2) continue;
    ex even = 0;
    ex odd = 0;
    for (int k = low; k <= high; ++k) {
      const ex coefficient = result.coeff(radical.symbol, k);
      if (coefficient.is_zero()) continue;
      const ex factor = pow(radical.square, k / 2);
      if (k % 2 == 0) even += coefficient * factor; else odd += coefficient * factor;
    }
    result = expand(even + odd * radical.symbol);
  }
  return result;
}

namespace {

// Radicals appearing in `e` (in list order), plus i if present.
RadicalList present_radicals(const ex& e, const RadicalList& radicals) {
  RadicalList present;
  for (const Radical& r : radicals) if (e.has(r.symbol)) present.push_back(r);
  if (e.has(imaginary_unit().symbol)) {
    bool listed = false;
    for (const Radical& r : present) listed = listed || r.symbol == imaginary_unit().symbol;
    if (!listed) present.push_back(imaginary_unit());
  }
  return present;
}

}  // namespace

ex simplify(const ex& expression, const RadicalList& radicals) {
  ex normalised = normal(expression);
  const RadicalList present = present_radicals(normalised, radicals);
  if (present.empty()) return normalised;
  ex fraction = numer_denom(normalised);
  ex numerator = reduce_radical_powers(fraction.op(0), present);
  ex denominator = reduce_radical_powers(fraction.op(1), present);
  for (int pass = 0; pass < 4; ++pass) {
    bool changed = false;
    for (const Radical& r : present) {
      if (!denominator.has(r.symbol)) continue;
      const ex conjugate = denominator.subs(r.symbol == -r.symbol);
      numerator = reduce_radical_powers(numerator * conjugate, present);
      denominator = reduce_radical_powers(denominator * conjugate, present);
      changed = true;
    }
    if (!changed) break;
  }
  // Squares may carry denominators: bring to one fraction, then reduce again.
  ex result = normal(numerator / denominator);
  fraction = numer_denom(result);
  numerator = reduce_radical_powers(fraction.op(0), present);
  denominator = fraction.op(1);
  for (const Radical& r : present)
    if (denominator.has(r.symbol)) return simplify(numerator / denominator, radicals);
  return normal(numerator / denominator);
}

bool is_exactly_zero(const ex& expression, const RadicalList& radicals) {
  return simplify(expression, radicals).is_zero();
}

namespace {

/// The primes below 2^16 in packs whose product fits in 63 bits: one big remainder per pack,
/// then each prime of the pack tested on that remainder in native arithmetic.
struct PrimePack {
  std::uint64_t product = 1;
  std::vector<std::uint64_t> primes;
};

const std::vector<PrimePack>& trial_primes() {
  static const std::vector<PrimePack> packs = [] {
    constexpr std::uint64_t limit = 65536;
    std::vector<bool> composite(limit + 1, false);
    std::vector<PrimePack> result(1);
    for (std::uint64_t p = 2; p <= limit; ++p) {
      if (composite[p]) continue;
      for (std::uint64_t q = p * p; q <= limit; q += p) composite[q] = true;
      if (result.back().product > (std::uint64_t{1} << 63) / p) result.emplace_back();
      result.back().product *= p;
      result.back().primes.push_back(p);
    }
    return result;
  }();
  return packs;
}

}  // namespace

ex canonical_sqrt(const ex& square) {
  if (!is_a<numeric>(square)) return sqrt(square);
  const numeric value = ex_to<numeric>(square);
  if (!value.is_rational()) throw std::invalid_argument("canonical_sqrt: square is not rational: " + text(square));
  if (value.is_negative()) throw std::invalid_argument("canonical_sqrt: negative square " + text(square));
  if (value.is_zero()) return 0;
  // sqrt(p/q) = sqrt(p q)/q; p q = a² r.  Square factors below 2^16 are extracted by trial
  // division and a remaining perfect square exactly (isqrt), so r is square-free for every
  // radicand met in practice and the cost stays bounded for huge ones (FL = 1e-14 gives ~1e30).
  // Only primes are tried (a composite's factors are gone by its turn), a pack of them per
  // big-number remainder: a 17-digit parameter's radicands (~1e70) take microseconds.
  numeric outside = 1;
  numeric inside = 1;
  numeric remaining = value.numer() * value.denom();
  for (const PrimePack& pack : trial_primes()) {
    const std::uint64_t first = pack.primes.front();
    if (numeric(static_cast<long>(first * first)) > remaining) break;
    const auto residue = static_cast<std::uint64_t>(irem(remaining, numeric(static_cast<long>(pack.product))).to_long());
    for (const std::uint64_t prime : pack.primes) {
      if (residue % prime != 0) continue;
      const numeric d(static_cast<long>(prime));
      while (irem(remaining, d * d).is_zero()) { remaining = remaining / (d * d); outside = outside * d; }
      if (irem(remaining, d).is_zero()) { remaining = remaining / d; inside = inside * d; }
    }
  }
  if (const numeric root = isqrt(remaining); root * root == remaining) {
    outside = outside * root;
    remaining = 1;
  }
  inside = inside * remaining;
  const numeric coefficient = outside / value.denom();
  if (inside == 1) return coefficient;
  return coefficient * sqrt(ex(inside));
}

ex with_explicit_radicals(const ex& expression, const RadicalList& radicals) {
  exmap substitution;
  for (const Radical& r : radicals) substitution[r.symbol] = canonical_sqrt(r.square);
  return expression.subs(substitution);
}

namespace {
struct DigitsGuard {
  long saved;
  explicit DigitsGuard(long digits) : saved(Digits) { Digits = digits; }
  ~DigitsGuard() { Digits = saved; }
};
}  // namespace

double to_double(const ex& expression, const RadicalList& radicals) {
  DigitsGuard guard(40);
  const ex value = evalf(with_explicit_radicals(expression, radicals));
  if (!is_a<numeric>(value) || !ex_to<numeric>(value).is_real())
    throw std::invalid_argument("to_double: not a real number: " + text(expression));
  return ex_to<numeric>(value).to_double();
}

std::string decimal_text(const ex& expression, const RadicalList& radicals, int significant) {
  const double value = to_double(expression, radicals);
  std::ostringstream out;
  out.precision(significant);
  out << value;
  return out.str();
}

std::string text(const ex& expression) {
  std::ostringstream out;
  out << expression;
  return out.str();
}

std::string latex(const ex& expression) {
  std::ostringstream out;
  out << GiNaC::latex << expression;
  return out.str();
}

const Radical* find_radical_with_square(const RadicalList& radicals, const ex& square) {
  for (const Radical& r : radicals)
    if (normal(r.square - square).is_zero()) return &r;
  return nullptr;
}

}  // namespace backlash::symbolic
