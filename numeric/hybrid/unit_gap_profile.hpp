// numeric/hybrid/unit_gap_profile.hpp (internal) — the unit flight of the dividing lines
// (dividing_lines.cpp), exposed to the tests that compare its searches.
#pragma once

#include "backlash/numeric/validation.hpp"

#include <string>
#include <vector>

namespace backlash::numeric::detail {

/// The unit flight.  From the separation line the free-mode deviations from θR are linear in
/// θ̇m0 (θR cancels in the gap), so gap(t; θ̇m0) = θ̇m0·f(t) with f = gap(t; 1): one profile
/// serves the whole dividing line.  Its knots are the certified departure t0, the certified
/// zeros of f' (in order), and `end`, the first return of f to 0 (or the horizon); f is
/// monotone between consecutive knots.  A search that runs out of its budget (SearchBudgetExhausted)
/// still certifies the span before where it stopped: the profile then ends there (`complete` false,
/// `work_limit` the reason), and decides the levels it reaches before that end.
struct UnitGapProfile {
  bool valid = false;
  double end = 0;
  bool returns = false;  ///< f returns to 0 at `end` (recontact on the face left)
  bool complete = true;  ///< `end` is the return or the horizon (not where a search stopped)
  std::string work_limit;
  std::vector<double> knots, values;
};

/// The profile over (0, horizon].  With `quiet_tail` (the default) its searches stop where f and
/// f' are certified to keep one sign up to the horizon (quiet_tail.hpp) — the same profile, bit
/// for bit, as the whole searches (`quiet_tail` false), whose cost grows with the horizon.
UnitGapProfile unit_gap_profile(const ValidatedEvaluator& evaluator, double horizon, bool quiet_tail = true);

}  // namespace backlash::numeric::detail
