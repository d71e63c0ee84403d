// exam_phi_functions — the stable building blocks of the parametric layer
// against known values (long-double series and closed forms), and their
// continuity across the switches between series and closed forms.
#include "evaluators/phi_functions.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using backlash::numeric::damped_pair;
using backlash::numeric::exp_divided_difference;
using backlash::numeric::phi;

// φ_n(x) by its series in long double (exact enough for |x| ≤ 40 when x ≤ 0 is summed carefully:
// use the closed form in long double for |x| > 1).
long double phi_reference(int n, long double x) {
  if (std::fabs(static_cast<double>(x)) <= 2) {
    long double sum = 0, term = 1;
    for (int k = 1; k <= n; ++k) term /= k;  // 1/n!
    for (int j = 0; j < 60; ++j) {
      sum += term;
      term *= x / (j + n + 1);
    }
    return sum;
  }
  long double value = std::expm1(x) / x;
  long double factorial = 1;
  for (int k = 1; k < n; ++k) {
    factorial /= k;
    value = (value - factorial) / x;
  }
  return value;
}

double relative(double actual, long double expected) {
  return std::fabs(static_cast<double>((actual - expected) / expected));
}

TEST(Phi, known_values) {
  EXPECT_EQ(phi(1, 0.0), 1.0) << "phi1(0) returned " << phi(1, 0.0) << " instead of 1";
  EXPECT_EQ(phi(2, 0.0), 0.5) << "phi2(0) returned " << phi(2, 0.0) << " instead of 0.5";
  EXPECT_NEAR(phi(3, 0.0), 1.0 / 6, 1e-17);
  EXPECT_NEAR(phi(1, -1.0), 1 - std::exp(-1.0), 1e-16) << "phi1(-1) returned " << phi(1, -1.0);
  EXPECT_NEAR(phi(2, -1.0), std::exp(-1.0), 1e-16) << "phi2(-1) returned " << phi(2, -1.0) << " instead of 1/e";
  EXPECT_NEAR(phi(0, -2.0), std::exp(-2.0), 1e-17);
}

TEST(Phi, matches_long_double_reference_over_the_range) {
  for (int n = 1; n <= 4; ++n)
    for (double x : {-300.0, -50.0, -7.5, -1.5, -1.0000001, -0.9999999, -0.5, -1e-3, -1e-9, 0.0, 1e-9, 0.3, 0.99, 1.01, 3.0}) {
      const long double expected = phi_reference(n, x);
      EXPECT_LE(relative(phi(n, x), expected), 4e-15)
          << "phi" << n << "(" << x << ") returned " << phi(n, x) << " instead of " << static_cast<double>(expected);
    }
}

// exp[0^n, x, y] in long double by its definition for well separated nodes
long double dd_reference(int n, long double x, long double y) {
  if (x == y) {
    // derivative: d/dx phi_n(x) = (phi_{n-1}(x) - n phi_n(x)) / x ... use a tiny symmetric difference in long double
    const long double h = 1e-6L * std::max(1.0L, std::fabs(x));
    return (phi_reference(n, x + h) - phi_reference(n, x - h)) / (2 * h);
  }
  if (n == 0) return (std::exp(x) - std::exp(y)) / (x - y);
  return (phi_reference(n, x) - phi_reference(n, y)) / (x - y);
}

TEST(DividedDifference, well_separated_nodes_match_the_difference_quotient) {
  for (int n = 0; n <= 2; ++n)
    for (auto [x, y] : {std::pair{-3.0, -0.2}, {-40.0, -10.0}, {-0.7, -0.1}, {-2.0, 0.0}, {-120.0, -5.0}}) {
      const long double expected = dd_reference(n, x, y);
      EXPECT_LE(relative(exp_divided_difference(n, x, y), expected), 1e-14)
          << "exp[0^" << n << ", " << x << ", " << y << "] returned " << exp_divided_difference(n, x, y) << " instead of "
          << static_cast<double>(expected);
      EXPECT_EQ(exp_divided_difference(n, x, y), exp_divided_difference(n, y, x)) << "not symmetric";
    }
}

TEST(DividedDifference, merging_nodes_tend_to_the_confluent_value) {
  // exp[0, x, x] = phi1'(x) = (e^x - phi1(x)) / x  and  exp[0,0,x,x] = phi2'(x) = (phi1(x) - 2 phi2(x)) / x
  for (double x : {-0.5, -2.0, -30.0}) {
    const double confluent1 = (std::exp(x) - phi(1, x)) / x;
    const double confluent2 = (phi(1, x) - 2 * phi(2, x)) / x;
    for (double h : {1e-3, 1e-8, 1e-14, 0.0}) {
      EXPECT_LE(std::fabs(exp_divided_difference(1, x + h, x) / confluent1 - 1), 1e-12 + 2 * std::fabs(h))
          << "exp[0, x, x+h] at x = " << x << ", h = " << h << " returned " << exp_divided_difference(1, x + h, x)
          << " instead of ~" << confluent1;
      EXPECT_LE(std::fabs(exp_divided_difference(2, x + h, x) / confluent2 - 1), 1e-12 + 2 * std::fabs(h))
          << "exp[0,0, x, x+h] at x = " << x << ", h = " << h << " returned " << exp_divided_difference(2, x + h, x)
          << " instead of ~" << confluent2;
    }
  }
  EXPECT_NEAR(exp_divided_difference(2, 0.0, 0.0), 1.0 / 6, 1e-17) << "exp[0,0,0,0] is 1/3!";
  EXPECT_NEAR(exp_divided_difference(1, 0.0, 0.0), 1.0 / 2, 1e-17) << "exp[0,0,0] is 1/2!";
}

TEST(DividedDifference, is_accurate_on_both_sides_of_its_method_switches) {
  // max(|x|,|y|) = 1 (series | closed forms) and |x - y| = max/4 (difference quotient | recurrence)
  const double eps = 1e-9;
  for (int n = 0; n <= 2; ++n)
    for (auto [x, y] : {std::pair{-1 + eps, -0.5}, {-1 - eps, -0.5}, {-8.0, -6.0 + eps}, {-8.0, -6.0 - eps},
                        {-1 + eps, -0.95}, {-1 - eps, -0.95}}) {
      const long double expected = dd_reference(n, x, y);
      EXPECT_LE(relative(exp_divided_difference(n, x, y), expected), 1e-14)
          << "exp[0^" << n << ", " << x << ", " << y << "] returned " << exp_divided_difference(n, x, y)
          << " instead of " << static_cast<double>(expected);
    }
}

TEST(DampedPair, critical_damping_is_the_limit_of_both_sides) {
  const double alpha = 0.5, t = 3.0;
  // critical: c = e^{-at}, s = t e^{-at}
  const auto critical = damped_pair(alpha, alpha * alpha, t);
  EXPECT_NEAR(critical.c, std::exp(-alpha * t), 1e-16);
  EXPECT_NEAR(critical.s, t * std::exp(-alpha * t), 1e-16);
  for (double d : {1e-2, 1e-6, 1e-12}) {
    const auto under = damped_pair(alpha, alpha * alpha + d, t);
    const auto over = damped_pair(alpha, alpha * alpha - d, t);
    // c and s change by O(d t^2)
    EXPECT_NEAR(under.c, critical.c, 2 * d * t * t);
    EXPECT_NEAR(over.c, critical.c, 2 * d * t * t);
    EXPECT_NEAR(under.s, critical.s, 2 * d * t * t * t);
    EXPECT_NEAR(over.s, critical.s, 2 * d * t * t * t);
  }
}

TEST(DampedPair, known_values_far_from_critical) {
  // y'' + y = 0: c = cos t, s = sin t
  EXPECT_NEAR(damped_pair(0, 1, 2.0).c, std::cos(2.0), 1e-16);
  EXPECT_NEAR(damped_pair(0, 1, 2.0).s, std::sin(2.0), 1e-16);
  // y'' + 5y' + 4y = 0: poles -1, -4 (alpha 2.5, delta 1.5)
  const double t = 40.0;  // delta t > 20: the two-exponential path
  const auto p = damped_pair(2.5, 4, t);
  EXPECT_LE(std::fabs(p.c / (0.5 * (std::exp(-t) + std::exp(-4 * t))) - 1), 1e-14);
  EXPECT_LE(std::fabs(p.s / ((std::exp(-t) - std::exp(-4 * t)) / 3) - 1), 1e-14);
}

}  // namespace

namespace {

TEST(LoadKernels, agree_with_the_long_double_references_everywhere) {
  const double xs[] = {0.0, -1e-9, -0.01, -0.1, -0.124, -0.126, -0.2, -0.26, -0.5, -0.9, -1.0, -1.1, -3.0, -7.0, -60.0};
  for (double x : xs)
    for (double y : xs)
      for (double shift : {0.0, 1e-12, 1e-6, 1e-2}) {
        const double yy = y - shift;
        const auto k = backlash::numeric::load_kernels(x, yy);
        const auto check = [&](const char* what, double actual, long double expected) {
          const double error = std::fabs(static_cast<double>(actual - expected)) / std::fabs(static_cast<double>(expected));
          EXPECT_LE(error, 5e-14) << what << "(" << x << ", " << yy << ") returned " << actual << " instead of "
                                  << static_cast<double>(expected);
        };
        check("exp_x", k.exp_x, std::exp(static_cast<long double>(x)));
        check("exp_y", k.exp_y, std::exp(static_cast<long double>(yy)));
        check("phi1_x", k.phi1_x, phi_reference(1, x));
        check("phi2_x", k.phi2_x, phi_reference(2, x));
        check("phi1_y", k.phi1_y, phi_reference(1, yy));
        // divided differences: against the independently tested exp_divided_difference
        check("A1", k.a1, exp_divided_difference(1, x, yy));
        check("A2", k.a2, exp_divided_difference(2, x, yy));
      }
}

}  // namespace
