// Issue 19, a map's contact witnesses kept: kept_witness_mode (hybrid/gap_events.hpp) hands back
// the bits WitnessMode's constructor computes, for random modes of 2 and 4 states, asked again
// and again, interleaved with more modes than it keeps (so kept ones are dropped and rebuilt),
// and for inputs that differ in one bit only (−0 against 0 in c).  And the constants a witness
// takes from its matrix alone (kept per thread by A's bits, first_crossing.cpp) are those computed
// from that matrix alone — the constructor's formulas as they were, kept here verbatim — for
// modes on more matrices than are kept, sharing matrices, and on matrices one bit apart.
#include "backlash/numeric/first_crossing.hpp"
#include "hybrid/balancing.hpp"
#include "hybrid/gap_events.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

using namespace backlash::numeric;

template <class M>
bool same_bits(const M& a, const M& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same(const WitnessMode& kept, const WitnessMode& built, int at) {
  EXPECT_TRUE(same_bits(kept.A, built.A) && same_bits(kept.c, built.c) && same_bits(kept.e, built.e)) << at;
  EXPECT_TRUE(same_bits(kept.eA, built.eA) && same_bits(kept.eA2, built.eA2) && same_bits(kept.eA3, built.eA3)) << at;
  EXPECT_TRUE(same_bits(kept.scale, built.scale)) << at;
  const double k[] = {kept.ec, kept.eAc, kept.eA2c, kept.mu_A, kept.norm_e, kept.norm_eA2, kept.norm_eA3,
                      kept.norm_e_plain, kept.norm_eA, kept.norm_A, kept.norm_A_plain, kept.norm_c,
                      kept.inverse_scale, kept.time_unit, kept.first_window};
  const double b[] = {built.ec, built.eAc, built.eA2c, built.mu_A, built.norm_e, built.norm_eA2, built.norm_eA3,
                      built.norm_e_plain, built.norm_eA, built.norm_A, built.norm_A_plain, built.norm_c,
                      built.inverse_scale, built.time_unit, built.first_window};
  for (std::size_t i = 0; i < std::size(k); ++i) EXPECT_TRUE(same_bits(k[i], b[i])) << at << " constant " << i;
}

struct Inputs {
  SmallMatrix A;
  SmallVector c;
  SmallRow e;
  double time_unit;
};

}  // namespace

TEST(KeptWitnessModes, AlwaysTheBitsOfBuildingThem) {
  std::mt19937_64 random(19);
  std::uniform_real_distribution<double> entry(-50, 50);
  std::vector<Inputs> modes;
  for (int m = 0; m < 9; ++m) {
    const int n = m % 2 == 0 ? 2 : 4;
    Inputs in{SmallMatrix(n, n), SmallVector(n), SmallRow::Zero(n), 1};
    for (int i = 0; i < n; ++i) {
      in.c(i) = entry(random);
      for (int j = 0; j < n; ++j) in.A(i, j) = entry(random) * (i == j ? 1e3 : 1);  // some stiff: balanced
    }
    in.e(m % n) = 1;
    in.time_unit = m % 3 == 0 ? 1 : 1e-3;
    modes.push_back(in);
  }
  Inputs negative_zero = modes[0];
  negative_zero.c(0) = 0.0;
  modes.push_back(negative_zero);
  negative_zero.c(0) = -0.0;
  modes.push_back(negative_zero);
  std::uniform_int_distribution<std::size_t> pick(0, modes.size() - 1);
  for (int at = 0; at < 400; ++at) {
    const Inputs& in = modes[at < 40 ? at % 2 : pick(random)];  // first the same two again and again
    expect_same(detail::kept_witness_mode(in.A, in.c, in.e, in.time_unit), WitnessMode(in.A, in.c, in.e, in.time_unit), at);
  }
}

namespace {

// WitnessMode's matrix constants as the constructor computed them before they were kept (int37).
double old_log_norm(const SmallMatrix& A) {
  double mu = -INFINITY;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    double row = A(i, i);
    for (Eigen::Index j = 0; j < A.cols(); ++j)
      if (j != i) row += std::fabs(A(i, j));
    mu = std::max(mu, row);
  }
  return A.rows() > 0 ? mu : 0.0;
}
double old_window(const SmallMatrix& A) {
  double diagonal = 0, coupling = 0;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    diagonal = std::max(diagonal, std::fabs(A(i, i)));
    for (Eigen::Index j = 0; j < i; ++j) coupling = std::max(coupling, std::sqrt(std::fabs(A(i, j) * A(j, i))));
  }
  const double rate = diagonal + coupling;
  return rate > 0 ? 4 / rate : INFINITY;
}
void expect_matrix_constants(const WitnessMode& m, const SmallMatrix& A, int at) {
  double mu = old_log_norm(A);
  SmallVector scale = SmallVector::Ones(A.rows());
  if (mu > 0) {
    const SmallVector d = detail::balancing(A);
    const SmallMatrix balanced = d.asDiagonal() * A * d.cwiseInverse().asDiagonal();
    const double mu_balanced = old_log_norm(balanced);
    if (mu_balanced * 16 < mu) {
      scale = d;
      mu = mu_balanced;
    }
  }
  EXPECT_TRUE(same_bits(m.scale, scale)) << at;
  EXPECT_TRUE(same_bits(m.mu_A, mu)) << at;
  EXPECT_TRUE(same_bits(m.first_window, old_window(A))) << at;
  EXPECT_TRUE(same_bits(m.norm_A, (scale.asDiagonal() * A).cwiseAbs().rowwise().sum().maxCoeff())) << at;
  EXPECT_TRUE(same_bits(m.norm_A_plain, A.cwiseAbs().rowwise().sum().maxCoeff())) << at;
  EXPECT_TRUE(same_bits(m.inverse_scale, scale.cwiseInverse().maxCoeff())) << at;
  EXPECT_TRUE(same_bits(m.norm_e, m.e.cwiseQuotient(scale.transpose()).cwiseAbs().sum())) << at;
}

}  // namespace

TEST(KeptWitnessModes, check_matrix_constants_as_built_alone) {
  std::mt19937_64 random(37);
  std::uniform_real_distribution<double> entry(-50, 50);
  std::vector<SmallMatrix> matrices;
  for (int m = 0; m < 12; ++m) {
    const int n = m % 3 == 0 ? 2 : 4;
    SmallMatrix A(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = entry(random) * (i == j && m % 2 ? 1e3 : 1);  // some stiff: balanced
    matrices.push_back(A);
    if (m % 4 == 1) {  // the same matrix one bit apart: the last bit of an entry, −0 against 0
      SmallMatrix B = A;
      B(1, 0) = std::nextafter(B(1, 0), INFINITY);
      matrices.push_back(B);
      B = A;
      B(0, 1) = 0.0;
      matrices.push_back(B);
      B(0, 1) = -0.0;
      matrices.push_back(B);
    }
  }
  std::uniform_int_distribution<std::size_t> pick(0, matrices.size() - 1);
  for (int at = 0; at < 2000; ++at) {
    const SmallMatrix& A = matrices[at < 60 ? at % 3 : pick(random)];  // first a few again and again
    const Eigen::Index n = A.rows();
    SmallVector c(n);
    SmallRow e = SmallRow::Zero(n);
    for (Eigen::Index i = 0; i < n; ++i) c(i) = entry(random);
    e(at % n) = 1;
    expect_matrix_constants(WitnessMode(A, c, e, 1), A, at);
    if (HasFailure()) return;
  }
}
