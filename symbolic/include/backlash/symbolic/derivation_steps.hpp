// backlash/symbolic/derivation_steps.hpp — the intermediate steps of an exact
// inverse Laplace transform, for a reader to follow (and checked exactly).
//
// For a segment's transform F(s) (case_derivation.hpp) the steps are
//   1. F as one rational function N(s)/D(s) in lowest terms (pretty.hpp);
//   2. D factored into irreducible factors (inverse_laplace.hpp's find_poles);
//   3. the partial fractions: for each pole p of multiplicity m the
//      coefficients A_r of 1/(s − p)^r, r = 1 … m,
//          A_r = 1/(m−r)! · d^{m−r}/ds^{m−r} [(s − p)^m F(s)] at s = p,
//      complex pairs α ± iω by the coefficient at α + iω (the conjugate
//      pair's is its conjugate);
//   4. the time function they give, Σ A_r t^{r−1}/(r−1)! e^{pt} (complex
//      pairs folded into e^{αt}(P cos ωt + Q sin ωt), P = 2 Re A, Q = −2 Im A).
// Two exact checks close the loop: Σ A_r/(s − p)^r − F(s) ≡ 0, and the time
// function of step 4 equals the derivation's own solution term by term.
#pragma once

#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/inverse_laplace.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <ginac/ginac.h>

#include <string>
#include <utility>
#include <vector>

namespace backlash::symbolic {

struct PoleResidues {
  Pole pole;
  /// Where the coefficients are taken: the pole (Real), each of α ± δ (RealPair),
  /// α + iω (ComplexPair).  `coefficients[r-1]` multiplies 1/(s − at)^r.
  struct Location {
    GiNaC::ex at;
    std::vector<GiNaC::ex> coefficients;
  };
  std::vector<Location> locations;
};

struct SegmentSteps {
  pretty::RationalFunction transform;  ///< N/D in lowest terms
  GiNaC::ex leading_constant;          ///< D = leading_constant · Π factor^multiplicity
  std::vector<std::pair<GiNaC::ex, unsigned>> factors;
  std::vector<PoleResidues> poles;
  TimeFunction from_residues;          ///< step 4
  RadicalList radicals;                ///< the derivation's radicals (and any new ones); i is imaginary_unit()
  bool partial_fractions_sum_to_transform = false;
  bool residues_give_solution = false;
  bool verified() const { return partial_fractions_sum_to_transform && residues_give_solution; }
};

/// The steps for one segment of a derivation (its radicals name ω, δ).
SegmentSteps segment_steps(const Segment& segment, const RadicalList& radicals);

/// LaTeX of a pole: "0", "-\frac{1}{5}", "-\frac{1}{5} \pm \mathrm{i}\,\omega_c".
std::string pole_latex(const Pole& pole, const RadicalList& radicals);
/// The partial-fraction expansion as summands (complex pairs in real quadratic form).
std::vector<pretty::Summand> partial_fraction_terms(const SegmentSteps& steps, const pretty::Format& format);

}  // namespace backlash::symbolic
