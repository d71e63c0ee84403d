// Test helper: exact case solutions (GiNaC/CLN) evaluated at high precision,
// the reference the generated and parametric evaluators are compared with.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"

#include <ginac/ginac.h>

#include <string>

namespace backlash::testing {

/// The exact binary value of a double, as a GiNaC rational / a model rational.
GiNaC::numeric exact_numeric(double value);
model::Rational exact_rational(double value);
/// The shortest decimal that reads back as `value`, as an exact rational (0.1 → 1/10).
model::Rational decimal_rational(double value);
/// p/q as a model rational (q > 0).
model::Rational ratio(long long p, long long q = 1);
/// 10^-k.
model::Rational ten_to_minus(int k);

model::CaseSpec make_spec(const std::string& id, model::Rational Jm, model::Rational Fm, model::Rational JL,
                          model::Rational FL, model::Rational K, model::Rational theta_R, model::Rational backlash,
                          model::MeasuredAt where);

/// Every generated expression of a case as one exact expression in t and the
/// segment's inputs (radicals written as square roots).
struct ExactCase {
  std::string contact_branch, free_branch;  ///< exact classification (symbolic::classify_*)
  GiNaC::ex theta_m, dtheta_m, theta_L, dtheta_L, gap, theta_o, dtheta_o, cot_phi;
};
/// From the case's own derivation (symbolic::derive_case).
ExactCase exact_case(const model::CaseSpec& spec);
/// From the general solution of the case's branch with the exact numbers
/// substituted (equal to the case's own derivation: symbolic::reproduces_case
/// proves it).  Used for the near-degenerate grids, whose huge rationals make
/// derive_case slow (its exact square-root canonicalisation factors the
/// radicands by trial division).
ExactCase exact_case_from_branches(const model::CaseSpec& spec);

/// Value of a free-mode expression at (t, θ̇m0) / a contact expression at
/// (t, θo0, θ̇o0), inputs taken exactly, evaluated with `digits` digits.
double free_value(const GiNaC::ex& e, double t, double dtheta_m0, int digits = 40);
double contact_value(const GiNaC::ex& e, double t, double theta_o0, double dtheta_o0, int digits = 40);

/// |actual − expected| / max(1, |expected|).
double scaled_error(double actual, double expected);

}  // namespace backlash::testing
