// backlash/numeric/parameters.hpp — a case's physical parameters as doubles, the input of
// every evaluator and simulator (docs/physics.md; units rad, s, torques in units of K·rad):
// motor and load inertias Jm, JL and viscous frictions Fm, FL, the loop gain K, the reference
// θR, the total backlash b, and which shaft is measured (θo = θm or θL).
#pragma once

#include "backlash/model/case_spec.hpp"

namespace backlash::numeric {

/// A case's parameters as doubles.
struct Parameters {
  double Jm = 1, Fm = 0, JL = 1, FL = 0, K = 1, theta_R = 0;
  double backlash = 0;  ///< total backlash b (recombination when the gap has changed by b)
  model::MeasuredAt measured_at = model::MeasuredAt::Load;
};
Parameters parameters_of(const model::CaseSpec& spec);

}  // namespace backlash::numeric
