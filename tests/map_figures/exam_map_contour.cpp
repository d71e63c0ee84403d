// The cycle/no-cycle boundary of a map (MapField::contour_x/y, the 1/2-contour of the bin
// fraction with a cycle) for a synthetic disk-shaped cycle region: every contour vertex lies
// within one bin of the true circle, and the contour goes all the way round it (every 10°
// sector of the circle has a vertex).  On a grid with linear axes, on a grid with a log axis
// (the circle drawn in the binned coordinates, log10 of the value), and from sampled points.
#include "synthetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

namespace {

using backlash::map::figures::MapAxis;
using backlash::map::figures::MapField;
using backlash::map::figures::MapFigures;

// A coordinate in bins: (u(value) − origin) / width, u the value or its log10.
struct BinCoordinate {
  double origin, width;
  bool log = false;
  double operator()(double v) const { return ((log ? std::log10(v) : v) - origin) / width; }
};

// `mean_tolerance`: how far the contour may lie inside or outside the circle on average (bins;
// NaN: not checked).
void expect_circle(const MapField& f, BinCoordinate cx, BinCoordinate cy, double centre_x, double centre_y, double radius,
                   const std::string& what, double mean_tolerance) {
  std::vector<bool> sector(36, false);
  std::size_t vertices = 0;
  double worst = 0, signed_sum = 0;
  for (std::size_t k = 0; k < f.contour_x.size(); ++k) {
    if (std::isnan(f.contour_x[k])) continue;
    const double dx = cx(f.contour_x[k]) - centre_x, dy = cy(f.contour_y[k]) - centre_y;
    const double off = std::abs(std::hypot(dx, dy) - radius);
    worst = std::max(worst, off);
    signed_sum += std::hypot(dx, dy) - radius;
    EXPECT_LE(off, 1.0) << what << ": contour vertex (" << f.contour_x[k] << ", " << f.contour_y[k] << ") lies " << off
                        << " bins from the circle instead of at most 1";
    const double angle = std::atan2(dy, dx) + std::numbers::pi;
    sector[std::min<std::size_t>(35, static_cast<std::size_t>(angle / (2 * std::numbers::pi) * 36))] = true;
    ++vertices;
  }
  EXPECT_GT(vertices, 36u) << what << ": " << vertices << " contour vertices";
  for (std::size_t s = 0; s < sector.size(); ++s)
    EXPECT_TRUE(sector[s]) << what << ": no contour vertex between " << 10 * s << "° and " << 10 * (s + 1) << "°";
  const double mean = signed_sum / static_cast<double>(std::max<std::size_t>(vertices, 1));
  if (!std::isnan(mean_tolerance)) {
    EXPECT_LE(std::abs(mean), mean_tolerance) << what << ": the contour lies " << mean << " bins outside the circle on average "
                                              << "instead of within ±" << mean_tolerance;
  }
  std::cout << what << ": " << vertices << " vertices, farthest " << worst << " bins from the circle, " << mean
            << " bins outside it on average\n";
}

// On a grid the cycle fraction is 0 or 1 at the nodes, so every contour vertex lies halfway
// between two neighbouring grid nodes (one coordinate an integer, the other one half off it,
// in bins), one node inside the disk and the other outside.
void expect_midpoints(const MapField& f, BinCoordinate cx, BinCoordinate cy, double centre_x, double centre_y, double radius) {
  for (std::size_t k = 0; k < f.contour_x.size(); ++k) {
    if (std::isnan(f.contour_x[k])) continue;
    const double X = cx(f.contour_x[k]), Y = cy(f.contour_y[k]);
    const bool x_on_node = std::abs(X - std::round(X)) < 1e-9, y_on_node = std::abs(Y - std::round(Y)) < 1e-9;
    const bool x_half = std::abs(X - std::floor(X) - 0.5) < 1e-9, y_half = std::abs(Y - std::floor(Y) - 0.5) < 1e-9;
    ASSERT_TRUE((x_on_node && y_half) || (y_on_node && x_half))
        << "contour vertex at (" << X << ", " << Y << ") bins instead of halfway between two grid nodes";
    const double ax = std::floor(X + (x_half ? 0 : 0.5)), ay = std::floor(Y + (y_half ? 0 : 0.5));  // the two nodes
    const double bx = x_half ? ax + 1 : ax, by = y_half ? ay + 1 : ay;
    const bool a_in = std::hypot(ax - centre_x, ay - centre_y) < radius, b_in = std::hypot(bx - centre_x, by - centre_y) < radius;
    EXPECT_NE(a_in, b_in) << "contour vertex at (" << X << ", " << Y << ") between two nodes on the same side of the circle";
  }
}

// A grid map over two axes (n values each) with a cycle inside the circle, in bins.
MapField grid_disk(const MapAxis& ax, const MapAxis& ay, BinCoordinate cx, BinCoordinate cy, double x0, double y0, double r) {
  MapFigures map("disk", {ax, ay}, "grid");
  std::int64_t index = 0;
  const auto value = [](const MapAxis& a, int k) {
    const double t = k / double(a.bins - 1);
    return a.log_scale ? std::pow(10.0, std::log10(a.from) + t * (std::log10(a.to) - std::log10(a.from))) : a.from + t * (a.to - a.from);
  };
  for (int j = 0; j < ay.bins; ++j)
    for (int i = 0; i < ax.bins; ++i) {
      const double x = value(ax, i), y = value(ay, j);
      const double rr = std::hypot(cx(x) - x0, cy(y) - y0);
      map.add(rr < r ? backlash::test::cycle_point(index++, {x, y}, 0.1 * (1 - rr / r)) : backlash::test::rest_point(index++, {x, y}));
    }
  return map.field(0, 1);
}

TEST(MapContour, DiskOnALinearGrid) {
  // x: 81 values on [0, 4] (bins 0.05 wide), y: 41 values on [10, 30] (0.5 wide); in bins the
  // grid value k sits at k, the disk is centred at (40, 20) with radius 14.7 bins (no node
  // lies on the circle: 14.7² is not a sum of two squares of integers).
  const BinCoordinate cx{0, 0.05}, cy{10, 0.5};
  const MapField f = grid_disk({"Jm", 0, 4, 81}, {"K", 10, 30, 41}, cx, cy, 40, 20, 14.7);
  expect_circle(f, cx, cy, 40, 20, 15, "linear grid", std::nan(""));
  expect_midpoints(f, cx, cy, 40, 20, 14.7);
}

TEST(MapContour, DiskOnAGridWithALogAxis) {
  // x: 81 values from 0.01 to 100 on a log scale (0.05 decade apart), y: 41 values on [1, 3]
  const BinCoordinate cx{-2, 0.05, true}, cy{1, 0.05};
  const MapField f = grid_disk({"JL_over_Jm", 0.01, 100, 81, true}, {"FL_over_F", 1, 3, 41}, cx, cy, 40, 20, 14.7);
  expect_circle(f, cx, cy, 40, 20, 15, "log grid", std::nan(""));
  expect_midpoints(f, cx, cy, 40, 20, 14.7);
  for (double x : f.contour_x) {
    if (!std::isnan(x)) {
      EXPECT_TRUE(x > 0.01 && x < 100) << "contour x " << x << " outside the log axis";
    }
  }
}

TEST(MapContour, DiskFromSampledPoints) {
  // 30 × 30 bins on [0, 1]², 90 000 random points (100 per bin); the disk: centre (0.5, 0.5),
  // radius 0.3.  In bins (bin b's centre at b + 1/2): centre (15, 15), radius 9.
  MapFigures map("disk", {{"backlash", 0, 1, 30}, {"reference", 0, 1, 30}}, "sobol");
  std::mt19937_64 generator(99);
  for (std::int64_t i = 0; i < 90000; ++i) {
    const double x = backlash::test::uniform(generator), y = backlash::test::uniform(generator);
    const double rr = std::hypot(x - 0.5, y - 0.5);
    map.add(rr < 0.3 ? backlash::test::cycle_point(i, {x, y}, 0.3 - rr) : backlash::test::rest_point(i, {x, y}));
  }
  const BinCoordinate c{0, 1.0 / 30};
  expect_circle(map.field(0, 1), c, c, 15, 15, 9, "sampled", 0.1);
}

}  // namespace

namespace {

// A saddle cell: corners (0,0), (1,0), (1,1), (0,1) with cycle fractions 1, 1/4, 1, 0 (four
// values of a third axis).  The corners' mean, 9/16, is above 1/2, so the two cycle corners
// join across the centre and the line cuts off the other two: segments (2/3, 0)–(1, 1/3)
// and (1/2, 1)–(0, 1/2) (linear interpolation of the fraction along each edge).
TEST(MapContour, SaddleJoinsTheSideOfTheCellMean) {
  MapFigures map("saddle", {{"x", 0, 1, 2}, {"y", 0, 1, 2}, {"z", 0, 3, 4}}, "grid");
  const int cycles[2][2] = {{4, 0}, {1, 4}};  // [x][y]: how many of the four z values have a cycle
  std::int64_t index = 0;
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 4; ++z) {
        const std::vector<double> v = {double(x), double(y), double(z)};
        map.add(z < cycles[x][y] ? backlash::test::cycle_point(index++, v, 0.01) : backlash::test::rest_point(index++, v));
      }
  const MapField f = map.field(0, 1);
  const std::vector<double> x = {2.0 / 3, 1, NAN, 0.5, 0, NAN}, y = {0, 1.0 / 3, NAN, 1, 0.5, NAN};
  ASSERT_EQ(f.contour_x.size(), x.size()) << "returned " << f.contour_x.size() / 3 << " segments instead of 2";
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (std::isnan(x[k])) {
      EXPECT_TRUE(std::isnan(f.contour_x[k])) << "no break after segment " << k / 3;
      continue;
    }
    EXPECT_NEAR(f.contour_x[k], x[k], 1e-12) << "vertex " << k << ": x returned " << f.contour_x[k] << " instead of " << x[k];
    EXPECT_NEAR(f.contour_y[k], y[k], 1e-12) << "vertex " << k << ": y returned " << f.contour_y[k] << " instead of " << y[k];
  }
}

}  // namespace
