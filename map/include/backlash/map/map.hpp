// backlash/map/map.hpp — design-space maps: limit cycles over several parameters at once, on
// one machine or many (MPI).  `backlash map` is this header (docs/design.md, "Design-space maps").
// The map is a library of its own (map/, target backlash::map, no GiNaC) on top of the facade
// (backlash/api/backlash.hpp: the case, BadInput, status_of); the facade's users reach it as
// backlash/api/map.hpp, which names these in backlash::api.  Its figures: backlash/map/figures.hpp;
// its MPI ranks: backlash/map/mpi.hpp.
//
//   #include "backlash/map/map.hpp"                         // target backlash::map (no GiNaC)
//   backlash::map::MapRequest r;
//   r.target = "V";
//   r.vary = {backlash::map::parse_vary("JL_over_Jm=0.25:4:40"), backlash::map::parse_vary("FL_over_F=0:1:40")};
//   backlash::map::run_map(r, [](const backlash::map::MapRow& row) { ... });   // rows in index order
//   backlash::map::write_map(r, {.out = "map-V"});                             // the files of `backlash map --out`
//
// Each point is the case with the varied parameters set (the names `sweep` knows, api/backlash.hpp
// SweepRequest::vary: Jm Fm JL FL K backlash reference, JL_over_Jm keeping Jm + JL, FL_over_F keeping
// Fm + FL, the effects' parameters); its row holds the limit cycle (numeric/limit_cycle.hpp: status,
// peak-to-peak swing of θo [rad], amplitude max|θo − θR| [rad], period [s], separation velocity
// [rad/s], the return map's multiplier) or its absence with the reason, the contact/free branches
// of the parametric evaluator used, and the settle time [s] of the case's step response
// (numeric/settle.hpp: the first sample time after which θo stays within 2 % of the step of the
// cycle's band or of rest).
//
// The points:
//   grid   the product of the axes, the last --vary fastest; axis value i of N is
//          A + (B − A)·i/(N − 1) in double (A when N = 1) — the expression `sweep` uses, so a
//          one-axis map is the sweep over the same points, bit for bit;
//   sobol  `points` points of Boost.Random's Sobol sequence (boost/random/sobol.hpp, Joe–Kuo
//          direction numbers), point i = the i-th of the sequence, u ∈ [0, 1)^d, x = A + (B − A)·u;
//   lhs    `points` points of a Latin hypercube with a fixed seed: in dimension k, point i lies in
//          stratum π_k(i) of `points` equal strata, π_k a keyed pseudo-random permutation
//          (cycle-walking Feistel network on splitmix64), at a keyed offset inside it — computed
//          from (i, k) alone: no table, memory flat.
// Points are computed in blocks of `block` consecutive points (numeric/sweep.hpp: warm starts
// inside a block, every block cold; fixed by the point count alone), so every row, to the last bit,
// is the same for any number of threads or MPI ranks.
#pragma once

#include "backlash/api/backlash.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace backlash::map {

/// One varied parameter: --vary NAME=FROM:TO:N (N: grid values; ignored by sobol/lhs, which
/// take the range only — give N = 1 or any N there, or leave it out).  A grid needs N: an axis
/// without it (count_given false) is refused by MapPlan, never read as one point.
struct MapAxis {
  std::string name;
  double from = 0, to = 0;
  long count = 1;
  bool count_given = true;  ///< false: "NAME=FROM:TO" (parse_vary), for sobol/lhs only
};

/// "JL_over_Jm=0.25:4:40" (or "NAME=FROM:TO" for sampled maps).  api::BadInput "vary" naming the text.
MapAxis parse_vary(const std::string& text);

struct MapRequest {
  std::string target;              ///< a case: I … VIII or a case file
  std::vector<MapAxis> vary;       ///< 1 … 8 axes, each parameter at most once
  std::string sample = "grid";     ///< grid | sobol | lhs
  long points = 0;                 ///< sobol / lhs: the number of points (>= 1)
  int threads = 2;                 ///< worker threads (per MPI rank), 1 … 256
  std::optional<double> step{};    ///< the step A [rad] for the settle time (default: the case's; none: no settle time)
  int block = 32;                  ///< points per warm-start block
  bool boundary = true;            ///< grid: solve the cycle/no-cycle boundary along grid lines
  std::uint64_t seed = 13;         ///< lhs: the permutations' key
};

/// A request checked and its points made on demand.  api::BadInput "vary" / "sample" / "points" /
/// "threads" / "step" / "block" naming the problem (a parameter range outside its physical range
/// is refused here, before any point is computed); model::CaseFileError for the case.
class MapPlan {
 public:
  explicit MapPlan(const MapRequest& request);
  const MapRequest& request() const { return request_; }
  const api::Case& source() const { return case_; }
  long count() const { return count_; }
  /// The varied values of point `index` (in the order of request().vary).
  std::vector<double> values(long index) const;
  /// The point: the case's parameters and effects with the varied values set.
  numeric::SweepPoint point(long index) const;
  /// Point `index` with axis `axis` set to `value` instead (the boundary search along a grid line).
  numeric::SweepPoint point_at(long index, int axis, double value) const;
  /// Grid only: the stride of axis k in the point index (the last axis has stride 1).
  long stride(int axis) const;
  /// Grid only: axis k's index of point `index`.
  long grid_index(long index, int axis) const;
  /// The settle step used (0: no settle time).
  double step() const { return step_; }
  double t_end() const { return t_end_; }

 private:
  void apply(const std::string& name, double x, numeric::Parameters& p, numeric::Effects& e) const;
  MapRequest request_;
  api::Case case_;
  numeric::Parameters base_;
  numeric::Effects base_effects_;
  long count_ = 0;
  double step_ = 0, t_end_ = 60;
};

/// A computed point.
struct MapRow {
  long index = 0;
  std::vector<double> x;  ///< the varied values
  numeric::SweepRow row;  ///< parameters, status (api::status_of(row)), reason, branches, cycle, settle
};

/// The CSV of `backlash map` (points.csv): its header, and one row (both end in '\n').
/// Columns: index, x_<name> for each varied parameter, Jm, Fm, JL, FL, K, backlash, reference,
/// every effect parameter by its NAME (the table of effects' order: numeric::point_column_names),
/// status, reason, branches, peak_to_peak, amplitude, period, separation_velocity, multiplier,
/// settle_time, settle_status.  Numbers in the shortest text that reads back to the same double
/// (std::to_chars); empty cells for what a row does not have; the reason quoted (RFC 4180).
std::string map_csv_header(const MapPlan& plan);
std::string map_csv_row(const MapRow& row);

/// One point of the cycle/no-cycle boundary on a grid line (boundary.csv).
struct MapBoundaryRow {
  int along = 0;             ///< the axis the line runs along
  long lower = 0, upper = 0; ///< the two consecutive grid points (indices) that differ
  std::vector<double> x;     ///< the boundary point: the grid values, `along` replaced by the root
  double low = 0, high = 0;  ///< the final bracket of the root on axis `along`
  std::string kind;          ///< "appears" (cycle at the upper point) | "dies"
  int evaluations = 0;       ///< limit-cycle searches spent
};
std::string map_boundary_csv_header(const MapPlan& plan);
std::string map_boundary_csv_row(const MapBoundaryRow& row);

/// The map, rows handed to `sink` in index order from the calling thread (memory flat).
void run_map(const MapRequest& request, const std::function<void(const MapRow&)>& sink);

/// The boundary root between grid points `lower` and `upper` (consecutive along `along`, one with
/// a limit cycle, the other "none"): the existence condition bisected (Boost.Math's bisect) to 2^-40
/// relative, each x one cold point of the sweep engine (docs/design.md, "Design-space maps": why
/// not toms748 on the multiplier); the points judged by `family`
/// (the map's: numeric::sweep_family), or each validated on its own when null.
MapBoundaryRow solve_boundary(const MapPlan& plan, int along, long lower, long upper, bool cycle_at_lower,
                              std::shared_ptr<const numeric::ValidatedParametricFamily> family = nullptr);

/// How MPI ranks talk (map/src/map_mpi.cpp makes one over Boost.MPI; nothing else depends on MPI).
class MapTransport {
 public:
  virtual ~MapTransport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Every rank's `piece`, at rank 0 in rank order (other ranks get an empty list).
  virtual std::vector<std::string> gather(const std::string& piece) = 0;
  /// Rank 0's `value` on every rank.
  virtual void broadcast(std::string& value) = 0;
};

struct MapOutput {
  std::filesystem::path out;       ///< the folder (replaced atomically; backlash/output/target.hpp, Target::folder)
  bool resume = false;             ///< continue an interrupted run of the same request
  bool hdf5 = true;                ///< map.h5 beside points.csv
  bool figures = true;             ///< figures/ and summary.md (map/figures.hpp)
  long stop_after = -1;            ///< >= 0: stop (interrupted) once this many points are written (tests)
  MapTransport* transport = nullptr;  ///< MPI: the ranks (null: this process alone)
  std::function<bool()> interrupted{};  ///< polled between blocks: true stops the run (a signal)
  std::function<void(long, long)> progress{};  ///< (points written, total), rank 0
};

/// What write_map did.
struct MapSummary {
  long points = 0, written = 0;  ///< the map's points; rows written by this run (resume: the rest)
  long resumed_from = 0;         ///< the first point computed by this run
  long kept = 0;                 ///< interrupted: the points of complete blocks kept for --resume
  long boundary_points = 0;
  long survey_fallbacks = 0;     ///< points whose limit-cycle search fell back to the grid survey
  bool complete = false;         ///< false: interrupted, the partial folder kept for --resume
  std::string figures_note;      ///< why figures were not drawn (empty: drawn)
};

/// The files of `backlash map --out DIR`: points.csv, boundary.csv (grid), map.h5, map.json (the
/// request), figures/map_P_Q.svg and summary.md — written into ".DIR.map-partial" next to DIR and
/// renamed into place at the end.  Interrupted (stop_after, interrupted()), the partial folder
/// keeps every completed block and a checkpoint; `resume` continues from there (the partial block
/// recomputed) and the final files are byte-identical to an uninterrupted run's.  Every rank of a
/// transport calls it; rank 0 writes.  api::BadInput for a bad request or --out, before anything is written.
MapSummary write_map(const MapRequest& request, const MapOutput& output);
/// Where write_map keeps an unfinished map of --out `out`: ".OUT.map-partial" beside it.
std::filesystem::path map_partial_folder(const std::filesystem::path& out);

}  // namespace backlash::map
