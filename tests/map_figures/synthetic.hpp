// Synthetic maps for the map-figure tests: points fed to MapFigures as the engine would,
// from functions whose answers are known in closed form (no backlash physics involved).
#pragma once

#include "backlash/map/figures.hpp"

#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace backlash::test {

/// Uniform on [0, 1) from the top 53 bits (the same numbers on every standard library).
inline double uniform(std::mt19937_64& generator) { return static_cast<double>(generator() >> 11) * 0x1.0p-53; }

/// A point with a limit cycle of swing `magnitude` (rad) at x.
inline map::figures::MapPoint cycle_point(std::int64_t index, std::vector<double> x, double magnitude) {
  map::figures::MapPoint p;
  p.index = index;
  p.x = std::move(x);
  p.status = "limit_cycle";
  p.peak_to_peak = magnitude;
  p.period = 1;
  p.multiplier = 0.5;
  p.settle_time = 10;
  return p;
}

/// A point without a cycle at x.
inline map::figures::MapPoint rest_point(std::int64_t index, std::vector<double> x) {
  map::figures::MapPoint p;
  p.index = index;
  p.x = std::move(x);
  p.status = "none";
  p.peak_to_peak = p.period = p.multiplier = std::numeric_limits<double>::quiet_NaN();
  p.settle_time = 5;
  return p;
}

}  // namespace backlash::test
