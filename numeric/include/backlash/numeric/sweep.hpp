// backlash/numeric/sweep.hpp — limit-cycle magnitude over parameters (the
// thesis's figures 31 and 32), on the stable parametric evaluators.
//
// Figure 31: magnitude vs FL/F (load friction over total friction F = Fm + FL),
//   for JL = Jm and JL = 4 Jm.  Figure 32: magnitude vs JL/Jm for three friction
//   distributions (FL = 0, Fm = .2; Fm = 3 FL with F = .4; FL = 3 Fm with F = .4).
//   Common to both (the thesis's cases III–VIII): J = Jm + JL = 1, K = 1,
//   b = .3, θR = 1, output at the load; figure 31 uses F = .4 (cases V–VIII).
// Points run on `threads` threads, each over a contiguous run of points so
// each limit-cycle search starts from its neighbour's cycle (continuation);
// every evaluator comes from a ValidatedParametricFamily (validated_family.hpp),
// validated at `validation_samples` evenly spaced points and at the first point of
// every further branch the sweep enters.
// A point with effects has its effect modes validated (effects_simulation.hpp) and its cycle
// found on the full return map (effects_limit_cycle.hpp), warm-started from its neighbour's
// crossing of the section.
// A point's failure is a status in its row, never an exception.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <functional>
#include <string>
#include <vector>

namespace backlash::numeric {

struct SweepPoint {
  std::string series;  ///< e.g. "JL=Jm"
  double x = 0;        ///< the swept ratio
  Parameters parameters;
  Effects effects;     ///< the effects at this point (effects_limit_cycle.hpp when any)
};

struct SweepRow {
  SweepPoint point;
  std::string status;  ///< "limit_cycle" | "none" | "unvalidated" | "error: …"
  std::string branches;
  LimitCycle cycle;
};

struct SweepOptions {
  int threads = 2;
  int validation_samples = 64;  ///< validate the parametric family at this many evenly spaced points (ends included)
  std::function<void(long done, long total)> progress;  ///< called from worker threads (serialised)
};

struct SweepSummary {
  long validated_samples = 0, failed_samples = 0;
  std::vector<std::string> covered_branches;
};

std::vector<SweepRow> run_sweep(const std::vector<SweepPoint>& points, const SweepOptions& options,
                                SweepSummary* summary = nullptr);

/// Figure 31: `n` values of FL/F in [0, 1] for each of JL = Jm, JL = 4 Jm.
std::vector<SweepPoint> figure31_points(int n);
/// Figure 32: `n` values of JL/Jm in [0.1, 4] for each friction distribution.
std::vector<SweepPoint> figure32_points(int n);

}  // namespace backlash::numeric
