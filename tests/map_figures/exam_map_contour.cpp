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

using backlash::reports::MapAxis;
using backlash::reports::MapField;
using backlash::reports::MapFigures;

// A coordinate in bins: (u(value) − origin) / width, u the value or its log10.
struct BinCoordinate {
  double origin, width;
  bool log = false;
  double operator()(double v) const { return ((log ? std::log10(v) : v) - origin) / width; }
};

void expect_circle(const MapField& f, BinCoordinate cx, BinCoordinate cy, double centre_x, double centre_y, double radius,
                   const std::string& what) {
  std::vector<bool> sector(36, false);
  std::size_t vertices = 0;
  double worst = 0;
  for (std::size_t k = 0; k < f.contour_x.size(); ++k) {
    if (std::isnan(f.contour_x[k])) continue;
    const double dx = cx(f.contour_x[k]) - centre_x, dy = cy(f.contour_y[k]) - centre_y;
    const double off = std::abs(std::hypot(dx, dy) - radius);
    worst = std::max(worst, off);
    EXPECT_LE(off, 1.0) << what << ": contour vertex (" << f.contour_x[k] << ", " << f.contour_y[k] << ") lies " << off
                        << " bins from the circle instead of at most 1";
    const double angle = std::atan2(dy, dx) + std::numbers::pi;
    sector[std::min<std::size_t>(35, static_cast<std::size_t>(angle / (2 * std::numbers::pi) * 36))] = true;
    ++vertices;
  }
  EXPECT_GT(vertices, 36u) << what << ": " << vertices << " contour vertices";
  for (std::size_t s = 0; s < sector.size(); ++s)
    EXPECT_TRUE(sector[s]) << what << ": no contour vertex between " << 10 * s << "° and " << 10 * (s + 1) << "°";
  std::cout << what << ": " << vertices << " vertices, farthest " << worst << " bins from the circle\n";
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
  // grid value k sits at k, the disk is centred at (40, 20) with radius 15 bins.
  const BinCoordinate cx{0, 0.05}, cy{10, 0.5};
  const MapField f = grid_disk({"Jm", 0, 4, 81}, {"K", 10, 30, 41}, cx, cy, 40, 20, 15);
  expect_circle(f, cx, cy, 40, 20, 15, "linear grid");
}

TEST(MapContour, DiskOnAGridWithALogAxis) {
  // x: 81 values from 0.01 to 100 on a log scale (0.05 decade apart), y: 41 values on [1, 3]
  const BinCoordinate cx{-2, 0.05, true}, cy{1, 0.05};
  const MapField f = grid_disk({"JL_over_Jm", 0.01, 100, 81, true}, {"FL_over_F", 1, 3, 41}, cx, cy, 40, 20, 15);
  expect_circle(f, cx, cy, 40, 20, 15, "log grid");
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
  expect_circle(map.field(0, 1), c, c, 15, 15, 9, "sampled");
}

}  // namespace
