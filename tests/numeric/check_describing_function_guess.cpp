// check_describing_function_guess — the cold limit-cycle search's first guess
// (describing_function_separation_velocity, describing_function.hpp) gives the same bits as the
// scan it replaced: every one of the 64 grid values of β down from the top until g(β) < 0, then
// 60 bisection steps evaluating g at each (kept below as the reference).  The new rule certifies
// the signs it does not compute (a binary search over the grid, the bisection's steps far from
// Newton's root), so any flaw in its error bound or monotone range shows as a different guess.
// Random drives over 18 decades of c = JK/F², both ends of the grid and roots below β = 0 (where
// g need not increase) among them; plus friction down to 1e-300 (c = ∞) and drives with no guess.
#include "backlash/numeric/describing_function.hpp"
#include "backlash/numeric/parametric.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>

namespace {

using namespace backlash::numeric;

double reference_balance(double beta, double c) {
  const double root = std::sqrt(std::max(0.0, 1 - beta * beta));
  const double re = (M_PI / 2 + std::asin(beta) + beta * root) / M_PI;
  const double im = -(1 - beta * beta) / M_PI;
  return re - c * im * im;
}

// main's describing_function_separation_velocity (6102acc), and the grid index k it stopped at.
double reference_guess(const Parameters& p, int& k_found) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, K = p.K, b = p.backlash;
  k_found = -1;
  if (p.measured_at != backlash::model::MeasuredAt::Load || !(b > 0) || !(F > 0)) return 0;
  const double c = J * K / (F * F);
  const int n = 64;
  double hi = 1 - 1e-12;
  for (int k = n - 1; k >= 0; --k) {
    double lo = -std::cos(M_PI * k / n) * (1 - 1e-12);
    if (reference_balance(lo, c) < 0) {
      for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
        const double mid = 0.5 * (lo + hi);
        (reference_balance(mid, c) < 0 ? lo : hi) = mid;
      }
      k_found = k;
      const double A = b / (1 - 0.5 * (lo + hi));
      const double omega = -K * backlash_describing_function(A, b).imag() / F;
      const double swing = A - b / 2, slope = omega * cot_phi(p);
      return omega * swing / std::sqrt(1 + slope * slope);
    }
    hi = lo;
  }
  return 0;
}

void expect_same_bits(const Parameters& p, std::set<int>* brackets = nullptr) {
  int k = -1;
  const double expected = reference_guess(p, k), got = describing_function_separation_velocity(p);
  if (brackets) brackets->insert(k);
  ASSERT_EQ(std::bit_cast<std::uint64_t>(expected), std::bit_cast<std::uint64_t>(got))
      << "Jm " << p.Jm << " JL " << p.JL << " Fm " << p.Fm << " FL " << p.FL << " K " << p.K << " b " << p.backlash
      << ": " << expected << " vs " << got << " (reference bracket k = " << k << ")";
}

TEST(DescribingFunctionGuess, random_drives_give_the_scans_bits) {
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0, 1);
  std::set<int> brackets;
  for (int i = 0; i < 40000; ++i) {
    Parameters p;
    p.Jm = std::pow(10, -2 + 4 * u(rng));
    p.JL = std::pow(10, -2 + 4 * u(rng));
    p.K = std::pow(10, -1 + 8 * u(rng));
    const double F = std::sqrt((p.Jm + p.JL) * p.K / std::pow(10, -4 + 18 * u(rng)));  // c = JK/F²
    const double share = u(rng);
    p.Fm = share * F;
    p.FL = (1 - share) * F;
    p.backlash = std::pow(10, -3 + 3 * u(rng));
    expect_same_bits(p, &brackets);
    if (HasFatalFailure()) return;
  }
  // Not vacuous: the top bracket, roots below β = 0 (k < 32) and between, and no root at all.
  EXPECT_TRUE(brackets.count(63)) << "no root in the top bracket";
  EXPECT_TRUE(brackets.count(-1)) << "no drive without a root";
  EXPECT_LT(*std::next(brackets.begin()), 32) << "no root below β = 0";
  EXPECT_GE(brackets.size(), 40u) << "the roots fell in few brackets";
}

TEST(DescribingFunctionGuess, edge_drives_give_the_scans_bits) {
  Parameters p;
  p.Jm = 1, p.JL = 2, p.K = 3, p.backlash = 0.1;
  for (double F : {1e-300, 1e-160, 1e-100, 1e-10, 1e-5, 1.0, 1e5, 1e10, 1e100}) {
    p.Fm = 0.25 * F, p.FL = 0.75 * F;
    expect_same_bits(p);
  }
  p.FL = 0, p.Fm = 0;
  expect_same_bits(p);  // no friction: 0
  p.FL = 1, p.measured_at = backlash::model::MeasuredAt::Motor;
  expect_same_bits(p);  // the backlash outside the loop: 0
}

}  // namespace
