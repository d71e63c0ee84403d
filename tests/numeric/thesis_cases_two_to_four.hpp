// tests/numeric/thesis_cases_two_to_four.hpp — the thesis's cases II–IV (cases/*.toml: K = 1,
// b = 0.3; Jm, JL as the case files) with the load's friction FL set by the test (cases II–IV have
// FL = 0: the tests of nearly frictionless loads move it), for the tests of flights and dividing
// lines that run the numeric core without the facade.
#pragma once

#include "backlash/numeric/segment_dynamics.hpp"

namespace backlash::testing {

/// Case `number` (2, 3 or 4) with FL (N·m·s) and the reference θR (rad: 1 as the case files, 0 in
/// the error coordinates the facade runs the dividing lines in).
inline numeric::Parameters thesis_case_two_to_four(int number, double FL, double theta_R) {
  numeric::Parameters p;
  p.K = 1, p.theta_R = theta_R, p.backlash = 0.3, p.FL = FL;
  p.Jm = number == 4 ? 0.2 : 0.5, p.Fm = 0.2, p.JL = number == 4 ? 0.8 : 0.5;
  p.measured_at = number == 2 ? model::MeasuredAt::Motor : model::MeasuredAt::Load;
  return p;
}

}  // namespace backlash::testing
