// Known transforms, every pole structure, and the engine's refusals.
#include "backlash/symbolic/inverse_laplace.hpp"

#include <gtest/gtest.h>

namespace {

using namespace GiNaC;
using namespace backlash::symbolic;

struct Fixture : ::testing::Test {
  symbol s{"s"};
  possymbol t{"t"};
  RadicalList radicals;
  // f(t) from F(s); compare with an expected expression in t (radicals explicit).
  void expect_inverse(const ex& F, const ex& expected) {
    const TimeFunction f = inverse_laplace(F, s, radicals);
    const ex got = with_explicit_radicals(f.to_ex(t), radicals);
    const ex difference = normal(expand(got - expected));
    if (!difference.is_zero()) {
      // compare at a few times at 40 digits (sqrt forms may differ)
      for (int k = 1; k <= 5; ++k) {
        const ex at = evalf(difference.subs(t == numeric(k, 3)));
        ASSERT_TRUE(is_a<numeric>(at)) << at;
        EXPECT_LT(abs(ex_to<numeric>(at)), numeric(1, 1000000000) * numeric(1, 1000000000))
            << "L^-1[" << F << "] returned " << got << " instead of " << expected;
      }
    }
  }
};

TEST_F(Fixture, exam_SimpleRealPoles) { expect_inverse(1 / (s * (s + 1)), 1 - exp(-t)); }

TEST_F(Fixture, exam_TriplePoleAtZeroAsInCaseIII) {
  expect_inverse(1 / (pow(s, 3) * (s + numeric(2, 5))),
                 numeric(125, 8) * 0 + pow(t, 2) * numeric(5, 4) - numeric(25, 4) * t + numeric(125, 8) - numeric(125, 8) * exp(-numeric(2, 5) * t));
}

TEST_F(Fixture, exam_ComplexPairFoldedToRealForm) {
  // 1/((s+a)^2+w^2) = e^{-at} sin(wt)/w with w^2 = 113/75 (case I's motor-alone loop)
  const ex w = sqrt(numeric(113, 75));
  expect_inverse(1 / (pow(s, 2) + numeric(4, 5) * s + numeric(5, 3)), exp(-numeric(2, 5) * t) * sin(w * t) / w);
  ASSERT_EQ(radicals.size(), 1u);
  EXPECT_TRUE(normal(radicals[0].square - numeric(113, 75)).is_zero()) << "returned " << radicals[0].square << " instead of 113/75";
  EXPECT_EQ(canonical_sqrt(radicals[0].square), ex(numeric(1, 15) * sqrt(ex(339))));
}

TEST_F(Fixture, exam_RepeatedComplexPair) { expect_inverse(s / pow(s * s + 1, 2), t * sin(t) / 2); }

TEST_F(Fixture, exam_RepeatedComplexPairWithRadical) {
  // 1/(s^2+2)^2 = (sin(wt) - w t cos(wt))/(2 w^3), w = sqrt 2
  const ex w = sqrt(ex(2));
  expect_inverse(1 / pow(s * s + 2, 2), (sin(w * t) - w * t * cos(w * t)) / (2 * pow(w, 3)));
}

TEST_F(Fixture, exam_IrrationalRealPair) {
  const ex d = sqrt(ex(2));
  expect_inverse(1 / (s * s - 2), (exp(d * t) - exp(-d * t)) / (2 * d));
}

TEST_F(Fixture, exam_DoubleRealPoleCriticalDamping) { expect_inverse(1 / pow(s + 2, 2), t * exp(-2 * t)); }

TEST_F(Fixture, exam_NoFloatsEver) {
  const TimeFunction f = inverse_laplace(1 / (pow(s, 2) + numeric(1, 5) * s + numeric(99, 100) + numeric(1, 100)), s, radicals);
  for (const ExpTerm& term : f.terms()) {
    EXPECT_TRUE(term.coefficient.info(info_flags::rational) || !term.coefficient.is_zero());
    EXPECT_FALSE(is_a<numeric>(term.coefficient) && !ex_to<numeric>(term.coefficient).is_rational());
  }
}

TEST_F(Fixture, exam_ImproperFunctionRefused) { EXPECT_THROW(inverse_laplace(s / (s + 1), s, radicals), std::domain_error); }

TEST_F(Fixture, exam_CubicIrreducibleRefused) {
  EXPECT_THROW(inverse_laplace(1 / (pow(s, 3) + s + 1), s, radicals), std::domain_error);
}

TEST_F(Fixture, exam_UndecidableDiscriminantRefusedNotGuessed) {
  possymbol J("J"), F("F"), K("K");
  EXPECT_THROW(inverse_laplace(1 / (J * s * s + F * s + K), s, radicals), std::domain_error);
}

TEST_F(Fixture, check_RandomRationalQuadraticsVerify) {
  // Property: for random rational a, b, c the inverse of (c s + 1)/(s^2 + a s + b) satisfies
  // y'' + a y' + b y = 0 with y(0) = c, y'(0) = 1 - a c, whatever the pole structure.
  unsigned state = 12345;
  auto next = [&] { state = state * 1103515245u + 12345u; return static_cast<int>((state >> 16) % 19) - 9; };
  for (int trial = 0; trial < 40; ++trial) {
    const numeric a(next(), 4), b(next() == 0 ? 1 : next(), 3), c(next(), 2);
    RadicalList local;
    const TimeFunction y = inverse_laplace((c * s + 1) / (s * s + a * s + b), s, local);
    const TimeFunction dy = y.derivative();
    const TimeFunction residual = dy.derivative() + dy * a + y * b;
    EXPECT_TRUE(residual.is_zero(local)) << "a=" << a << " b=" << b;
    EXPECT_TRUE(is_exactly_zero(y.at_zero() - c, local));
    EXPECT_TRUE(is_exactly_zero(dy.at_zero() - (1 - a * c), local));
  }
}

}  // namespace

namespace {

TEST(CanonicalSqrt, exam_PerfectSquaresWithLargePrimeFactorsAreRational) {
  // 1000003 is prime and above the trial-division bound: its square must still be recognised.
  const GiNaC::numeric p("1000003"), q("999983");
  const GiNaC::ex root = backlash::symbolic::canonical_sqrt(GiNaC::numeric(p * p) / GiNaC::numeric(q * q * 4));
  EXPECT_TRUE(GiNaC::is_a<GiNaC::numeric>(root)) << "returned " << root << " instead of 1000003/1999966";
  EXPECT_EQ(root, GiNaC::ex(p / (q * 2)));
  EXPECT_EQ(backlash::symbolic::canonical_sqrt(GiNaC::numeric(113, 75)), GiNaC::ex(GiNaC::numeric(1, 15) * sqrt(GiNaC::ex(339))));
}

TEST(CanonicalSqrt, exam_HugeRadicandStaysExact) {
  // FL = 1e-14 gives radicands of ~1e30: the result squares back exactly.
  const GiNaC::numeric square("123456789012345678901234567891/100000000000000000000000000000");
  const GiNaC::ex root = backlash::symbolic::canonical_sqrt(square);
  EXPECT_TRUE(GiNaC::normal(GiNaC::expand(root * root) - square).is_zero()) << "returned " << root;
}

}  // namespace
