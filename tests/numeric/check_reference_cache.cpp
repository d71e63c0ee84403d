// check_reference_cache — LinearReferenceCache (reference.hpp) hands back what
// reference_linear_trajectory integrates, bit for bit, on varied linear modes, and its key tells
// apart inputs that differ in one bit of A, c, z0, a time or the tolerance, or in the dimension
// (each such input is integrated anew, never served from another's states); an input pushed out
// of a full cache is integrated again, to the same bits.
#include "backlash/numeric/reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

using namespace backlash::numeric;

struct Input {
  LinearSegment segment;
  SmallVector z0;
  std::vector<double> times;
  double tolerance = 1e-12;
};

// A damped linear mode of dimension n (a stable A: diagonal dominance), forcing and start random.
Input random_input(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-1, 1);
  Input in;
  in.segment.A = SmallMatrix::Zero(n, n);
  in.segment.c = SmallVector::Zero(n);
  in.z0 = SmallVector::Zero(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) in.segment.A(i, j) = u(rng);
    in.segment.A(i, i) = -1.5 - std::fabs(u(rng)) * n;
    in.segment.c(i) = u(rng);
    in.z0(i) = u(rng);
  }
  const double horizon = 2 + 3 * std::fabs(u(rng));
  for (int k = 1; k <= 40; ++k) in.times.push_back(horizon * k / 40);
  return in;
}

bool same_bits(const std::vector<SmallVector>& a, const std::vector<SmallVector>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size() ||
        std::memcmp(a[i].data(), b[i].data(), static_cast<std::size_t>(a[i].size()) * sizeof(double)) != 0)
      return false;
  return true;
}

std::vector<SmallVector> fresh(const Input& in) {
  return reference_linear_trajectory(in.segment, in.z0, in.times, in.tolerance);
}
std::vector<SmallVector> kept(LinearReferenceCache& cache, const Input& in) {
  return cache.trajectory(in.segment, in.z0, in.times, in.tolerance);
}

TEST(LinearReferenceCache, hands_back_the_integrations_bits_on_varied_modes) {
  std::mt19937_64 rng(19);
  LinearReferenceCache cache;
  for (int trial = 0; trial < 24; ++trial) {
    const Input in = random_input(rng, 2 + trial % 3);
    const std::vector<SmallVector> reference = fresh(in);
    const long hits = cache.hits(), integrations = cache.integrations();
    EXPECT_TRUE(same_bits(kept(cache, in), reference)) << "trial " << trial << ": integrated";
    EXPECT_EQ(cache.integrations(), integrations + 1);
    EXPECT_TRUE(same_bits(kept(cache, in), reference)) << "trial " << trial << ": kept";
    EXPECT_EQ(cache.hits(), hits + 1) << "trial " << trial << ": the same inputs were integrated again";
  }
}

TEST(LinearReferenceCache, tells_apart_inputs_that_differ_in_one_bit_or_the_dimension) {
  std::mt19937_64 rng(7);
  const Input base = random_input(rng, 4);
  std::vector<std::pair<const char*, Input>> variants;
  auto vary = [&](const char* what, auto change) {
    Input v = base;
    change(v);
    variants.push_back({what, v});
  };
  const auto up = [](double& x) { x = std::nextafter(x, INFINITY); };
  vary("A(2,1)", [&](Input& v) { up(v.segment.A(2, 1)); });
  vary("A(1,2)", [&](Input& v) { up(v.segment.A(1, 2)); });
  vary("c(3)", [&](Input& v) { up(v.segment.c(3)); });
  vary("z0(0)", [&](Input& v) { up(v.z0(0)); });
  vary("a time", [&](Input& v) { up(v.times[17]); });
  vary("one time less", [&](Input& v) { v.times.pop_back(); });
  vary("the tolerance", [&](Input& v) { v.tolerance = 1e-11; });
  vary("A transposed", [&](Input& v) { v.segment.A.transposeInPlace(); });
  vary("c = 0 against -0", [&](Input& v) { v.segment.c(1) = 0.0; });
  vary("c = -0 against 0", [&](Input& v) { v.segment.c(1) = -0.0; });
  vary("dimension 3", [&](Input& v) {
    v.segment.A.conservativeResize(3, 3), v.segment.c.conservativeResize(3), v.z0.conservativeResize(3);
  });
  LinearReferenceCache cache;
  (void)kept(cache, base);
  for (const auto& [what, v] : variants) {
    const long integrations = cache.integrations();
    EXPECT_TRUE(same_bits(kept(cache, v), fresh(v))) << what << ": served another input's states";
    EXPECT_EQ(cache.integrations(), integrations + 1) << what << ": not told apart from an input kept before";
  }
  EXPECT_EQ(cache.hits(), 0);
  EXPECT_TRUE(same_bits(kept(cache, base), fresh(base)));
  EXPECT_EQ(cache.hits(), 1);
}

TEST(LinearReferenceCache, an_input_pushed_out_is_integrated_again_to_the_same_bits) {
  std::mt19937_64 rng(3);
  LinearReferenceCache cache(2);
  const Input a = random_input(rng, 4), b = random_input(rng, 2), c = random_input(rng, 3);
  const std::vector<SmallVector> first = kept(cache, a);
  (void)kept(cache, b), (void)kept(cache, c);  // a, the oldest, pushed out
  EXPECT_EQ(cache.integrations(), 3);
  EXPECT_TRUE(same_bits(kept(cache, a), first));
  EXPECT_EQ(cache.integrations(), 4);
  EXPECT_TRUE(same_bits(kept(cache, c), fresh(c)));  // c still kept
  EXPECT_EQ(cache.hits(), 1);
}

// The input used last stays: a map's gate asks for the same few contact runs between new ones.
TEST(LinearReferenceCache, the_input_used_least_recently_is_the_one_pushed_out) {
  std::mt19937_64 rng(4);
  LinearReferenceCache cache(2);
  const Input a = random_input(rng, 2), b = random_input(rng, 3), c = random_input(rng, 4);
  (void)kept(cache, a), (void)kept(cache, b), (void)kept(cache, a);  // a used after b
  (void)kept(cache, c);                                              // b pushed out, not a
  EXPECT_EQ(cache.integrations(), 3);
  EXPECT_TRUE(same_bits(kept(cache, a), fresh(a)));
  EXPECT_EQ(cache.integrations(), 3) << "a, used after b, was pushed out instead of b";
  EXPECT_TRUE(same_bits(kept(cache, b), fresh(b)));
  EXPECT_EQ(cache.integrations(), 4) << "b, used least recently, was still kept";
}

}  // namespace
