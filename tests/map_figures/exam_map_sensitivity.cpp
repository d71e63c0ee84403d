// First-order sensitivity indices from the map's bins (MapFigures::sensitivities) against
// functions whose indices are known in closed form:
//   - an additive function on a full grid: the bin means are exact, so the index is that of
//     the grid's discrete uniform distribution, S_i = a_i² Var_N(x) / Σ a_j² Var_N(x), with
//     Var_N of N equally spaced values on [0, 1] = (N + 1) / (12 (N − 1));
//   - the Ishigami function Y = sin x1 + a sin² x2 + b x3⁴ sin x1 on [−π, π]³ (a = 7,
//     b = 0.1), S = (0.3139, 0.4424, 0) — from N random points in B bins per axis, compared
//     with the index of the *binned* conditional mean (closed form below), the estimator's
//     upward bias (B − 1)/N·(1 − S) and 6 standard deviations of the correlation ratio,
//     sqrt(4 S (1 − S)² / N + 2 (B − 1) / N²) (its large-N spread);
//   - Y = X1 + X2 with X1 = U² (non-uniform: the bins hold unequal counts, so the weighting
//     by counts matters; unweighted bin means would read 0.500 instead of 0.516).
#include "synthetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

using backlash::map::figures::MapAxis;
using backlash::map::figures::MapFigures;
using backlash::map::figures::MapSensitivity;
using std::numbers::pi;

const char* const kNames[] = {"x1", "x2", "x3"};

double index_of(const std::vector<MapSensitivity>& ranked, const std::string& name) {
  for (const MapSensitivity& s : ranked)
    if (s.name == name) return s.first_order_index;
  ADD_FAILURE() << "no index for " << name;
  return -1;
}

double bias_of(const std::vector<MapSensitivity>& ranked, const std::string& name) {
  for (const MapSensitivity& s : ranked)
    if (s.name == name) return s.bias;
  return -1;
}

TEST(MapSensitivity, AdditiveFunctionOnAGridIsExact) {
  const std::vector<int> n = {11, 7, 5};
  const std::vector<double> a = {1, 2, 3};
  MapFigures map("synthetic", {{"x1", 0, 1, n[0]}, {"x2", 0, 1, n[1]}, {"x3", 0, 1, n[2]}}, "grid");
  std::int64_t index = 0;
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        const std::vector<double> x = {i / double(n[0] - 1), j / double(n[1] - 1), k / double(n[2] - 1)};
        map.add(backlash::test::cycle_point(index++, x, 1 + a[0] * x[0] + a[1] * x[1] + a[2] * x[2]));
      }
  double total = 0;
  std::vector<double> part;
  for (std::size_t i = 0; i < n.size(); ++i) {
    part.push_back(a[i] * a[i] * (n[i] + 1) / (12.0 * (n[i] - 1)));
    total += part.back();
  }
  const auto ranked = map.sensitivities();
  ASSERT_EQ(ranked.size(), 3u);
  EXPECT_EQ(ranked[0].name, "x3");
  EXPECT_EQ(ranked[1].name, "x2");
  EXPECT_EQ(ranked[2].name, "x1");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string name = kNames[i];
    const double expected = part[i] / total;
    EXPECT_NEAR(index_of(ranked, name), expected, 1e-12)
        << name << ": returned " << index_of(ranked, name) << " instead of " << expected;
    EXPECT_EQ(bias_of(ranked, name), 0.0) << name << ": a full grid has no sampling bias";
  }
}

struct Ishigami {
  static constexpr double a = 7, b = 0.1;
  static double f(double x1, double x2, double x3) { return std::sin(x1) + a * std::pow(std::sin(x2), 2) + b * std::pow(x3, 4) * std::sin(x1); }
  static double variance() { return a * a / 8 + b * std::pow(pi, 4) / 5 + b * b * std::pow(pi, 8) / 18 + 0.5; }
  // Var over B equal bins of [−π, π] of the bin means of E[Y | x1] = c sin x1 and of
  // E[Y | x2] = a sin² x2 (the mean of sin over [l, l + h] is (cos l − cos(l + h)) / h,
  // of sin² it is 1/2 − (sin 2(l + h) − sin 2l) / 4h).
  static double binned_variance(int axis, int bins) {
    const double h = 2 * pi / bins, c = 1 + b * std::pow(pi, 4) / 5;
    double sum = 0, sum_sq = 0;
    for (int k = 0; k < bins; ++k) {
      const double l = -pi + k * h;
      const double m = axis == 1 ? c * (std::cos(l) - std::cos(l + h)) / h
                                 : a * (0.5 - (std::sin(2 * (l + h)) - std::sin(2 * l)) / (4 * h));
      sum += m;
      sum_sq += m * m;
    }
    return sum_sq / bins - (sum / bins) * (sum / bins);
  }
};

TEST(MapSensitivity, IshigamiFromSampledPointsMatchesItsKnownIndices) {
  const int bins = 40;
  const std::int64_t n = 200000;
  MapFigures map("Ishigami", {{"x1", -pi, pi, bins}, {"x2", -pi, pi, bins}, {"x3", -pi, pi, bins}}, "lhs");
  std::mt19937_64 generator(20261126);
  for (std::int64_t i = 0; i < n; ++i) {
    std::vector<double> x(3);
    for (double& v : x) v = -pi + 2 * pi * backlash::test::uniform(generator);
    map.add(backlash::test::cycle_point(i, x, 11 + Ishigami::f(x[0], x[1], x[2])));  // + 11: a swing is ≥ 0
  }
  const auto ranked = map.sensitivities();
  ASSERT_EQ(ranked.size(), 3u);
  EXPECT_EQ(ranked[0].name, "x2");
  EXPECT_EQ(ranked[1].name, "x1");
  EXPECT_EQ(ranked[2].name, "x3");
  // the unbinned indices, for the record: 0.3139, 0.4424, 0
  const double exact[3] = {0.5 * std::pow(1 + Ishigami::b * std::pow(pi, 4) / 5, 2) / Ishigami::variance(),
                           Ishigami::a * Ishigami::a / 8 / Ishigami::variance(), 0.0};
  EXPECT_NEAR(exact[0], 0.3139, 5e-5);
  EXPECT_NEAR(exact[1], 0.4424, 5e-5);
  for (int i = 0; i < 3; ++i) {
    const std::string name = kNames[i];
    const double binned = i < 2 ? Ishigami::binned_variance(i + 1, bins) / Ishigami::variance() : 0.0;
    const double bias = (bins - 1.0) / n * (1 - binned);
    const double sigma = std::sqrt(4 * binned * (1 - binned) * (1 - binned) / n + 2.0 * (bins - 1) / (double(n) * n));
    const double got = index_of(ranked, name);
    EXPECT_NEAR(got, binned + bias, 6 * sigma) << name << ": returned " << got << " instead of " << binned + bias
                                               << " (binned index " << binned << " + bias " << bias << ", σ " << sigma << ")";
    EXPECT_NEAR(bias_of(ranked, name), bias, 0.2 * bias) << name << ": reported bias " << bias_of(ranked, name) << " instead of about " << bias;
  }
}

TEST(MapSensitivity, UnequalBinCountsAreWeighted) {
  const int bins = 40;
  const std::int64_t n = 200000;
  MapFigures map("additive", {{"x1", 0, 1, bins}, {"x2", 0, 1, bins}}, "sobol");
  std::mt19937_64 generator(7);
  for (std::int64_t i = 0; i < n; ++i) {
    const double u = backlash::test::uniform(generator), x2 = backlash::test::uniform(generator);
    map.add(backlash::test::cycle_point(i, {u * u, x2}, u * u + x2));
  }
  // Var(U²) = 1/5 − 1/9 = 4/45, Var(X2) = 1/12.  Binning X1 lowers its part by the mean
  // within-bin variance of X1, at most h²/4 (h = 1/B: X1 confined to a bin of width h).
  const double v1 = 4.0 / 45, v2 = 1.0 / 12, h = 1.0 / bins;
  const double high = v1 / (v1 + v2), low = (v1 - h * h / 4) / (v1 - h * h / 4 + v2);
  const double sigma = std::sqrt(4 * high * (1 - low) * (1 - low) / n);
  const double bias = (bins - 1.0) / n;
  const double got = index_of(map.sensitivities(), "x1");
  EXPECT_GE(got, low - 6 * sigma) << "returned " << got << " instead of " << low << " … " << high + bias;
  EXPECT_LE(got, high + bias + 6 * sigma) << "returned " << got << " instead of " << low << " … " << high + bias;
}

}  // namespace
