// backlash/symbolic/inverse_laplace.hpp — exact inverse Laplace transform by
// residues (GiNaC has none).
//
// For a proper rational function F(s) = N(s)/D(s) the engine factors D exactly
// and, for each pole p of multiplicity m with F = H(s)/(s−p)^m near p,
//     f(t) ∋ Σ_{j<m} H^{(j)}(p) / (j! k!) · t^k e^{p t},   k = m−1−j.
// Real poles of any multiplicity (case III's triple pole at s = 0), complex
// pairs α ± iω folded into e^{αt}(P cos ωt + Q sin ωt) (repeated pairs too),
// and irrational real pairs α ± δ are exact: ω and δ are Radicals, the
// imaginary unit is the radical i² = −1, and no float is ever formed.
//
// Pole finding: numeric (rational) denominators are factored over Q; an
// irreducible quadratic gets a new radical from its discriminant, whose sign is
// decided exactly.  Symbolic denominators (the general parametric solutions)
// must be given in a branch parametrisation where every quadratic factor's
// ±discriminant/(4a²) equals the square of a known radical — otherwise the
// sign of the discriminant is undecidable and the engine throws rather than
// guessing.  Irreducible factors of degree > 2 are refused with an error.
#pragma once

#include "backlash/symbolic/exact.hpp"
#include "backlash/symbolic/time_function.hpp"

#include <ginac/ginac.h>

#include <string>
#include <utility>
#include <vector>

namespace backlash::symbolic {

/// One pole (or conjugate pair) of a denominator.
struct Pole {
  enum class Kind { Real, ComplexPair, RealPair };
  Kind kind = Kind::Real;
  GiNaC::ex center;        ///< the real pole, or α of α ± iω / α ± δ
  GiNaC::ex half_width;    ///< ω (ComplexPair) or δ (RealPair): a radical symbol; 0 for Real
  unsigned multiplicity = 1;
  GiNaC::ex factor;        ///< the irreducible factor of D (in s) that carries it
};

/// Factor `denominator` (a polynomial in s) into poles.  New radicals (named
/// `radical_name`, `radical_name`_2, …) are appended to `radicals`.
std::vector<Pole> find_poles(const GiNaC::ex& denominator, const GiNaC::symbol& s, RadicalList& radicals,
                             const std::string& radical_name, const std::string& radical_role);

/// Where the residues are taken, as (p, partner) pairs: (center, 0) for a real pole; both roots
/// of a real pair, each with the other as its partner (center ± half_width, the + root first);
/// only the upper root center + i·half_width of a complex pair (its conjugate's residue is the
/// conjugate: the two are folded into e^{αt}(P cos ωt + Q sin ωt)), `i` the imaginary unit's symbol.
std::vector<std::pair<GiNaC::ex, GiNaC::ex>> pole_locations(const Pole& pole, const GiNaC::symbol& i);

/// Exact inverse Laplace transform of a proper rational function of s.
/// Throws std::domain_error for an improper function, an undecidable
/// discriminant or an unsupported irreducible factor.
TimeFunction inverse_laplace(const GiNaC::ex& transform, const GiNaC::symbol& s, RadicalList& radicals,
                             const std::string& radical_name = "omega", const std::string& radical_role = "");

}  // namespace backlash::symbolic
