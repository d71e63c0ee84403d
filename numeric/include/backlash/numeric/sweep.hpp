// backlash/numeric/sweep.hpp — limit-cycle magnitude over parameters (the
// thesis's figures 31 and 32), on the stable parametric evaluators.
//
// Figure 31: magnitude vs FL/F (load friction over total friction F = Fm + FL),
//   for JL = Jm and JL = 4 Jm.  Figure 32: magnitude vs JL/Jm for three friction
//   distributions (FL = 0, Fm = .2; Fm = 3 FL with F = .4; FL = 3 Fm with F = .4).
//   Common to both (the thesis's cases III–VIII): J = Jm + JL = 1, K = 1,
//   b = .3, θR = 1, output at the load; figure 31 uses F = .4 (cases V–VIII).
// The points are cut into blocks of `block` consecutive points, fixed by the point count
// alone; inside a block each limit-cycle search starts from its neighbour's cycle
// (continuation), and every block starts cold.  Threads take whole blocks, so every row —
// to the last bit — is the same for any thread count.  Rows are delivered in order as soon
// as their block and every block before it are done (run_sweep_streamed): memory stays
// bounded by a few blocks per thread, whatever the number of points.
// Every evaluator comes from a ValidatedParametricFamily (validated_family.hpp), validated
// at `validation_samples` evenly spaced points; a point whose branches were not covered by a
// passing sample, or whose branch failed at some sample, is validated itself and judged on
// its own merit (a refused row says why).  A point whose parameters double precision cannot
// handle (scales.hpp) is refused with the reason, before any work.
// The numerics run in error coordinates (θR = 0: nothing depends on θR) and the angles of
// the cycle are shifted back.
// A point with effects has its effect modes validated (effects_simulation.hpp) and its cycle
// found on the full return map (effects_limit_cycle.hpp), warm-started from its neighbour's
// crossing of the section.
// A point's failure is a status in its row, never an exception.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/settle.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace backlash::numeric {

struct SweepPoint {
  std::string series;  ///< e.g. "JL=Jm"
  double x = 0;        ///< the swept ratio
  Parameters parameters;
  Effects effects;     ///< the effects at this point (effects_limit_cycle.hpp when any)
};

/// A sweep point's outcome: the limit-cycle search's (CycleStatus), or why it was not searched:
/// unvalidated (its evaluators failed their gate), refused (double precision cannot handle its
/// parameters: scales.hpp), error (an exception, its text in the reason).
enum class SweepStatus { LimitCycle, None, Divergent, Unvalidated, Refused, Error, Unresolved };
/// "limit_cycle", "none", "divergent", "unvalidated", "refused", "error", "unresolved": the CSV's `status`.
const char* to_string(SweepStatus status);
std::ostream& operator<<(std::ostream& out, SweepStatus status);  ///< as to_string (test messages)
/// The row status of a point whose search ran.
SweepStatus sweep_status(CycleStatus status);

struct SweepRow {
  SweepPoint point;
  SweepStatus status = SweepStatus::Error;
  std::string reason;  ///< for every status but "limit_cycle": why, in words
  std::string branches;
  LimitCycle cycle;
  Settle settle;       ///< the step response's settle time (settle.hpp) when SweepOptions::settle.step != 0
};

class ValidatedParametricFamily;

struct SweepOptions {
  int threads = 2;
  int validation_samples = 64;  ///< validate the parametric family at this many evenly spaced points (ends included)
  int block = 32;               ///< points per warm-start block (the result does not depend on `threads`)
  std::function<void(long done, long total)> progress;  ///< called from worker threads (serialised)
  /// Maps (api/map.hpp): the step response's settle time of every row (settle.hpp; step 0: none).
  SettleOptions settle{};
  /// Compute only the points [first, last) of the `count` (last < 0: to the end); `first` must
  /// start a block.  With `family` (sweep_family of the same count and points) the rows are
  /// those of the whole run, bit for bit: how a map splits its points over ranks and resumes.
  long first = 0, last = -1;
  std::shared_ptr<const ValidatedParametricFamily> family{};
};

struct SweepSummary {
  long validated_samples = 0, failed_samples = 0;
  std::vector<std::string> covered_branches;
  long survey_fallbacks = 0;  ///< rows whose limit-cycle search fell back to the grid survey (LimitCycle::survey_fallback)
};

std::vector<SweepRow> run_sweep(const std::vector<SweepPoint>& points, const SweepOptions& options,
                                SweepSummary* summary = nullptr);

/// The same for `count` points made on demand by `point(i)` (called from any thread), each row
/// handed to `row(…)` in index order from the calling thread as soon as it and all before it are
/// done.  An exception thrown by `row` stops the workers and is rethrown.
void run_sweep_streamed(long count, const std::function<SweepPoint(long)>& point, const SweepOptions& options,
                        const std::function<void(const SweepRow&)>& row, SweepSummary* summary = nullptr);

/// The validated family of a sweep of `count` points (validated at `options.validation_samples`
/// evenly spaced points, the same for any split of the run): computed once, shared by the calls
/// of run_sweep_streamed over parts of the points (SweepOptions::family).
std::shared_ptr<const ValidatedParametricFamily> sweep_family(long count, const std::function<SweepPoint(long)>& point,
                                                              const SweepOptions& options);

/// Figure 31: `n` values of FL/F in [0, 1] for each of JL = Jm, JL = 4 Jm (2n points).
std::vector<SweepPoint> figure31_points(int n);
SweepPoint figure31_point(long n, long index);  ///< index < 2n, in the order of figure31_points
/// Figure 32: `n` values of JL/Jm in [0.1, 4] for each friction distribution (3n points).
std::vector<SweepPoint> figure32_points(int n);
SweepPoint figure32_point(long n, long index);  ///< index < 3n, in the order of figure32_points

}  // namespace backlash::numeric
