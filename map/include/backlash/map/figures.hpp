// backlash/map/figures.hpp — figures and summary of a design-space map
// (`backlash map`): limit cycles over several parameters at once.  Target backlash::map_figures:
// no facade, no GiNaC, gnuplot at run time (backlash/reports/plot.hpp, target backlash::plot).
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
//     the bins (points without a cycle, status "none", count as 0 in it; points whose
//     answer is unknown — divergent, unvalidated, refused, error — are counted per status
//     but left out of the bins), with the cycle/no-cycle boundary drawn as the 1/2-contour
//     of the fraction of points with a cycle (marching squares through the bin centres),
//     and the exact boundary crossings (add_boundary) along p or q overlaid as markers:
//     figures/map_P_Q.svg (+ .pdf);
//   - summary.md: the counts per status, the range of the magnitude, and a sensitivity
//     ranking of the varied parameters (which moves the magnitude most: the first-order
//     index Var(E[magnitude | parameter]) / Var(magnitude), estimated from the bins of each
//     parameter), each figure linked.
// Bins: a grid axis has one bin per grid value (consecutive values share a bin beyond
// max_bins_per_axis); a sampled axis has `bins` equal bins (at most max_bins_per_axis), in
// log10 of the value when log_scale (grid values: from + (to − from)·k/(N − 1), or
// geometric on a log axis).
// Same points in the same order give the same bytes.  docs/map-figures.md: the figures,
// the contour and the estimator (with its bias for few points per bin).
#pragma once

#include <cstdint>
#include <filesystem>
#include <utility>
#include <string>
#include <vector>

namespace backlash::map::figures {

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
  /// The index's expected excess from the sampling noise of the bin means (sampled maps):
  /// (B − 1)·MS_within / SS_total for B non-empty bins — about (B − 1)/N of the variance
  /// the parameter does not explain; 0 for a full grid, where the bin means are exact.
  double bias = 0;
};

/// What the heat map of the pair (p, q), p < q, draws (MapFigures::field).
struct MapField {
  int p = 0, q = 0;
  std::vector<double> x_edges, y_edges;      ///< nx + 1 and ny + 1 bin edges (values of p, of q)
  std::vector<std::int64_t> count;           ///< points per bin (decided ones), index ix + nx·iy
  std::vector<double> mean_peak_to_peak;     ///< rad, 0 for "none"; NaN in an empty bin
  std::vector<double> cycle_fraction;        ///< fraction of the bin's points with a cycle; NaN if empty
  std::vector<double> contour_x, contour_y;  ///< the 1/2-contour of cycle_fraction; NaN between pieces
  std::vector<double> boundary_x, boundary_y;  ///< exact crossings along p or q (at most max_boundary_markers)
};

/// Not thread-safe: one thread adds the points (under MPI, the rank that gathers them, in
/// index order — binning per rank and merging would make the sums depend on the rank count).
class MapFigures {
 public:
  static constexpr int max_bins_per_axis = 200;        ///< beyond it, grid values share bins
  static constexpr int max_boundary_markers = 4096;    ///< per pair; thinned evenly, in order
  /// `sampling` is "grid", "sobol" or "lhs"; `case_id` names the case in titles.  Throws
  /// std::invalid_argument (one line naming the axis and field) for an unknown sampling, a
  /// non-finite bound, from = to (except a grid of one value), bins < 1, or a log axis
  /// that reaches 0 or below.  from > to is read as the same box.
  MapFigures(std::string case_id, std::vector<MapAxis> axes, std::string sampling);

  /// Adds a point; points must come in increasing index order (the output does not depend
  /// on threads).  Throws std::invalid_argument, naming the point and the parameter, for
  /// an index that does not increase, a value count other than the axes', or a value
  /// outside its axis's box (or, on a grid, off its grid values).
  void add(const MapPoint& point);
  /// Adds an exact crossing; it marks the pair figures of (along, other axis).  Throws
  /// std::invalid_argument for a value count other than the axes' or `along` out of range.
  void add_boundary(const MapBoundaryPoint& point);

  std::vector<MapSensitivity> sensitivities() const;  ///< ranked, largest first (ties: axis order)
  std::string summary_markdown() const;
  MapField field(int p, int q) const;  ///< p < q, axis indices; std::out_of_range otherwise
  /// "figures/map_P_Q" for the pair (p, q): the stem of its SVG and PDF under write()'s directory.
  std::string figure_stem(int p, int q) const;

  /// Writes figures/map_P_Q.svg (+ .pdf when gnuplot can) for every pair and summary.md
  /// into `directory` (which exists).  Returns the reason when figures could not be drawn
  /// (gnuplot missing), else an empty string; summary.md is always written (staged, then
  /// renamed into place; std::runtime_error when it cannot be written).
  std::string write(const std::filesystem::path& directory) const;

 private:
  /// Count, count with a cycle, mean and sum of squared deviations of the magnitude
  /// (Welford's update: stable for any number of points).
  struct Bin {
    std::int64_t n = 0, cycles = 0;
    double mean = 0, m2 = 0;
    void add(double magnitude, bool cycle);
  };
  /// Boundary markers of one pair, thinned to at most max_boundary_markers: every
  /// stride-th crossing is kept, the stride doubling whenever the list is full.
  struct Markers {
    std::vector<std::pair<double, double>> kept;
    std::int64_t seen = 0, stride = 1;
  };
  int bin_of(std::size_t axis, double x, std::int64_t index) const;
  std::vector<double> edges(std::size_t axis) const;
  std::size_t pair_slot(int p, int q) const;

  std::string case_id_;
  std::vector<MapAxis> axes_;
  std::string sampling_;
  std::vector<int> bins_, group_;             ///< bins per axis; grid values per bin (grid)
  std::vector<std::vector<Bin>> pair_bins_;   ///< pair (p<q) in lexicographic order, bins ix + nx·iy
  std::vector<std::vector<Bin>> axis_bins_;
  std::vector<Markers> markers_;              ///< per pair
  Bin all_;
  std::int64_t points_ = 0, last_index_ = -1, boundary_points_ = 0, periods_ = 0;
  std::vector<std::string> status_names_;     ///< the six known statuses, then others as met
  std::vector<std::int64_t> status_counts_;
  double magnitude_min_ = 0, magnitude_max_ = 0, period_min_ = 0, period_max_ = 0;
};

}  // namespace backlash::map::figures
