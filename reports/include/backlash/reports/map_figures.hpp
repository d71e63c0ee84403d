// backlash/reports/map_figures.hpp — figures and summary of a design-space map
// (`backlash map`): limit cycles over several parameters at once.
//
// A map varies d parameters (the names `sweep` knows — Jm Fm JL FL K backlash reference
// JL_over_Jm FL_over_F — and the effects' parameters) over boxes [from, to], on a grid
// or by Sobol / Latin-hypercube sampling; each point carries the limit cycle of the case
// at those parameters (status, peak-to-peak swing of θo in rad, period in s, the return
// map's multiplier) and the time to settle from the case's step (s).
//
// MapFigures accumulates the points as they stream past, in point order, into fixed bins
// per pair of varied parameters (memory flat in the number of points), and then writes:
//   - for every pair (p, q) of varied parameters, a heat map of the mean peak-to-peak over
//     the bins (points without a cycle count as 0 in it), with the cycle/no-cycle boundary
//     drawn as the 1/2-contour of the fraction of points with a cycle, and the exact
//     boundary crossings (add_boundary) overlaid as markers: figures/map_P_Q.svg (+ .pdf);
//   - summary.md: the counts per status, the range of the magnitude, and a sensitivity
//     ranking of the varied parameters (which moves the magnitude most: the first-order
//     index Var(E[magnitude | parameter]) / Var(magnitude), estimated from the bins of each
//     parameter), each figure linked.
// Same points in the same order give the same bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace backlash::reports {

/// One varied parameter of a map.
struct MapAxis {
  std::string name;      ///< as given to --vary, e.g. "JL_over_Jm"
  double from = 0, to = 0;
  int bins = 0;          ///< grid: the number of grid values N (one bin per value); sampled: bins per axis (e.g. 40)
  bool log_scale = false;
};

/// One computed point of the map.
struct MapPoint {
  std::int64_t index = 0;      ///< the point's index in the map (0, 1, ...)
  std::vector<double> x;       ///< the varied parameters' values, in the order of the axes
  std::string status;          ///< "limit_cycle" | "none" | "divergent" | "unvalidated" | "refused" | "error"
  double peak_to_peak = 0;     ///< rad (NaN without a cycle)
  double period = 0;           ///< s (NaN without a cycle)
  double multiplier = 0;       ///< (NaN without a cycle)
  double settle_time = 0;      ///< s, from the case's step to the cycle or to rest (NaN when not computed)
};

/// A point of the cycle/no-cycle boundary found exactly along a grid line: `x` in the
/// order of the axes; the line runs along axis `along` (the others are grid values).
struct MapBoundaryPoint {
  std::vector<double> x;
  int along = 0;
};

struct MapSensitivity {
  std::string name;
  double first_order_index = 0;  ///< Var(E[magnitude | parameter]) / Var(magnitude), in [0, 1]
};

class MapFigures {
 public:
  /// `sampling` is "grid", "sobol" or "lhs"; `case_id` names the case in titles.
  MapFigures(std::string case_id, std::vector<MapAxis> axes, std::string sampling);

  /// Adds a point; points must come in index order (the output does not depend on threads).
  void add(const MapPoint& point);
  void add_boundary(const MapBoundaryPoint& point);

  std::vector<MapSensitivity> sensitivities() const;  ///< ranked, largest first
  std::string summary_markdown() const;

  /// Writes figures/map_P_Q.svg (+ .pdf when gnuplot can) for every pair and summary.md
  /// into `directory` (which exists).  Returns the reason when figures could not be drawn
  /// (gnuplot missing), else an empty string; summary.md is always written.
  std::string write(const std::filesystem::path& directory) const;

 private:
  struct Accumulators;
  std::string case_id_;
  std::vector<MapAxis> axes_;
  std::string sampling_;
  std::vector<MapBoundaryPoint> boundary_;
  // per-pair and per-axis bins (count, count with a cycle, sum and sum of squares of the magnitude)
  struct Bin { std::int64_t n = 0, cycles = 0; double sum = 0, sum_sq = 0; };
  std::vector<std::vector<Bin>> pair_bins_;  ///< pair (p<q) in lexicographic order, bins row-major
  std::vector<std::vector<Bin>> axis_bins_;
  std::int64_t points_ = 0;
  std::vector<std::int64_t> status_counts_;
  std::vector<std::string> status_names_;
  double magnitude_min_ = 0, magnitude_max_ = 0;
};

}  // namespace backlash::reports
