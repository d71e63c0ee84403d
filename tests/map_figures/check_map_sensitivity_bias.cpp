// The bias the summary states for few points per bin (MapSensitivity::bias): with B bins and
// N points the correlation ratio reads high by about (B − 1)·MS_within / SS_total.  Over R
// independent small Ishigami maps (N = 400, B = 40: 10 points per bin), a parameter without
// influence (x3, S = 0) reads clearly above 0, and the index minus its stated bias averages
// to the binned index, within 4 standard errors of the mean over the R maps.
#include "synthetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace {

using backlash::map::figures::MapFigures;
using backlash::map::figures::MapSensitivity;
using std::numbers::pi;

double ishigami(double x1, double x2, double x3) { return std::sin(x1) + 7 * std::pow(std::sin(x2), 2) + 0.1 * std::pow(x3, 4) * std::sin(x1); }

struct Mean {
  double sum = 0, sum_sq = 0;
  int n = 0;
  void add(double v) { sum += v; sum_sq += v * v; ++n; }
  double mean() const { return sum / n; }
  double standard_error() const { return std::sqrt((sum_sq / n - mean() * mean()) / (n - 1)); }
};

TEST(MapSensitivityBias, FewPointsPerBinReadHighByTheStatedBias) {
  const int bins = 40, n = 400, maps = 300;
  Mean raw3, corrected3, corrected2;
  std::mt19937_64 generator(1313);
  for (int r = 0; r < maps; ++r) {
    MapFigures map("Ishigami", {{"x1", -pi, pi, bins}, {"x2", -pi, pi, bins}, {"x3", -pi, pi, bins}}, "lhs");
    for (int i = 0; i < n; ++i) {
      std::vector<double> x(3);
      for (double& v : x) v = -pi + 2 * pi * backlash::test::uniform(generator);
      map.add(backlash::test::cycle_point(i, x, 11 + ishigami(x[0], x[1], x[2])));
    }
    for (const MapSensitivity& s : map.sensitivities()) {
      if (s.name == "x3") { raw3.add(s.first_order_index); corrected3.add(s.first_order_index - s.bias); }
      if (s.name == "x2") corrected2.add(s.first_order_index - s.bias);
    }
  }
  // x3 has no first-order effect: the raw index is the bias alone, about (B − 1)/(N − 1) ≈ 0.098
  EXPECT_GT(raw3.mean(), 10 * raw3.standard_error()) << "x3 read " << raw3.mean() << " on average instead of clearly above 0";
  EXPECT_NEAR(corrected3.mean(), 0.0, 4 * corrected3.standard_error())
      << "x3: index − bias averaged " << corrected3.mean() << " instead of 0 (± " << 4 * corrected3.standard_error() << ")";
  // x2: E[Y | x2] = 7 sin² x2, binned over 40 bins: Var of the bin means / Var(Y)
  double sum = 0, sum_sq = 0;
  const double h = 2 * pi / bins;
  for (int k = 0; k < bins; ++k) {
    const double l = -pi + k * h, m = 7 * (0.5 - (std::sin(2 * (l + h)) - std::sin(2 * l)) / (4 * h));
    sum += m;
    sum_sq += m * m;
  }
  const double variance = 49.0 / 8 + 0.1 * std::pow(pi, 4) / 5 + 0.01 * std::pow(pi, 8) / 18 + 0.5;
  const double binned = (sum_sq / bins - (sum / bins) * (sum / bins)) / variance;
  EXPECT_NEAR(corrected2.mean(), binned, 4 * corrected2.standard_error())
      << "x2: index − bias averaged " << corrected2.mean() << " instead of " << binned;
}

}  // namespace
