// Issue 19, a map's contact witnesses kept: kept_witness_mode (hybrid/gap_events.hpp) hands back
// the bits WitnessMode's constructor computes, for random modes of 2 and 4 states, asked again
// and again, interleaved with more modes than it keeps (so kept ones are dropped and rebuilt),
// and for inputs that differ in one bit only (−0 against 0 in c).
#include "backlash/numeric/first_crossing.hpp"
#include "hybrid/gap_events.hpp"

#include <gtest/gtest.h>

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
