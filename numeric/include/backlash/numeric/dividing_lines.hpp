// backlash/numeric/dividing_lines.hpp — the thesis's dividing lines, exactly.
//
// From a point of the separation line, θm(0) = θL(0) = θR + cot φ·θ̇m0 and
// θ̇m(0) = θ̇L(0) = θ̇m0 (the thesis's convention, eqs. 19–23), the bodies move
// freely until the gap θL − θm (0 at separation) first reaches the opposite
// face, b·sign(θ̇m0) ("recombination"), or returns to 0, the face it left
// ("recontact").  At that time the four dividing lines are the loci of
//   (θm, θ̇m)  motor just before the impact,
//   (θL, θ̇L)  load just before the impact,
//   (θo, θ̇o)  recombined state just after it: θo = the measured shaft, and
//             (Jm + JL) θ̇o = Jm θ̇m + JL θ̇L  (eq. 24),
// plus the separation line itself.  The impact time is the first zero of a
// certified witness (first_crossing.hpp) on the validated closed form: no
// crossing can be skipped.  Where the gap per unit θ̇m0 is bounded (output at
// the motor) small θ̇m0 never recombine: the threshold b / sup(gap/θ̇m0) is
// reported, and those points come back with status NoRecombination.
//
// The searches run in error coordinates (θR = 0, in_error_coordinates; the angles are shifted
// back by θR): with angles of size θR the witness's derivatives recompute K(θR − θm)/Jm, whose
// rounding (an ulp of K·θR/Jm, exactly 0 only when θR's products round alike, e.g. θR = 1) is a
// floor that does not decay with the flight's motion — near the horizon the gap's slope is
// ~1e-29 against it, and the certified search, whose intervals shrink as (|w|/sup|w'''|)^(1/3),
// ran out of intervals.  A point its search cannot decide within CrossingOptions::max_intervals
// comes back with status Unresolved ("work_limit", DividingLines::work_limit says why), never an
// exception; what the search certified before it stopped still decides the points it covers
// (docs/design.md, "The JSON contract").  The line's searches stop where the gap per unit θ̇m0
// and its slope are certified to keep one sign up to the horizon (a nearly frictionless load:
// horizons of 40·JL/FL; docs/design.md, "The event loop"): the same points, bit for bit, at
// the cost of the motor's own time scale.
#pragma once

#include "backlash/numeric/validation.hpp"

#include <optional>
#include <string>
#include <vector>

namespace backlash::numeric {

/// Unresolved: the certified search ran out of its budget before deciding this point (a work
/// limit, "work_limit" in the outputs).
enum class RecombinationStatus { Recombination, Recontact, NoRecombination, Unresolved };
const char* to_string(RecombinationStatus status);
/// Whether the point has an impact (Recombination or Recontact): its time and states are set.
inline bool has_impact(RecombinationStatus status) {
  return status == RecombinationStatus::Recombination || status == RecombinationStatus::Recontact;
}

struct DividingLinePoint {
  double dtheta_m0 = 0;
  RecombinationStatus status = RecombinationStatus::NoRecombination;
  bool grazing = false;  ///< the gap touched the face tangentially
  double t = 0;
  double theta_m = 0, dtheta_m = 0, theta_L = 0, dtheta_L = 0;  ///< before the impact
  double theta_o = 0, dtheta_o = 0;                              ///< after the impact (eq. 24)
};

struct DividingLines {
  double cot_phi = 0;
  double horizon = 0;                      ///< the search horizon used
  /// |θ̇m0| below which no recombination occurs within the horizon (null when every θ̇m0 > 0 recombines).
  std::optional<double> threshold;
  std::vector<DividingLinePoint> points;
  /// Why some points are Unresolved (the search's budget), empty when none is; `threshold` is
  /// then null (the profile stops short of the horizon).
  std::string work_limit;
};

struct TraceOptions {
  double horizon = 0;  ///< 0 → 40 of the slowest time scales (segment_dynamics.hpp)
};

/// One point (any sign of θ̇m0; θ̇m0 = 0 gives NoRecombination).
DividingLinePoint dividing_line_point(const ValidatedEvaluator& evaluator, double dtheta_m0, const TraceOptions& options = {});

/// The dividing lines on a grid of θ̇m0 (threshold included).
DividingLines trace_dividing_lines(const ValidatedEvaluator& evaluator, const std::vector<double>& dtheta_m0,
                                   const TraceOptions& options = {});

/// The default grid: the thesis's values 1 … .02 and a log-spaced sweep.
std::vector<double> default_dividing_line_grid();

}  // namespace backlash::numeric
