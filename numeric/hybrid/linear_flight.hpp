// numeric/hybrid/linear_flight.hpp (internal) — a linear segment x' = A x + c from any
// initial state, in closed form: x(t) = e^{A t} x0 + ∫₀ᵗ e^{A s} ds c, from the
// exponential of the augmented matrix [[A, c], [0, 0]] (Eigen's
// MatrixFunctions: Padé approximation with scaling and squaring, accurate to a
// few ulps; a stiff matrix is balanced first, e^M = D⁻¹ e^{DMD⁻¹} D).  Used for free flight that does not start on the separation line
// (after a bounce), where the per-case evaluators (t, θ̇m0) do not apply; its
// agreement with Boost.Odeint is tested like every evaluator's.
#pragma once

#include "backlash/numeric/segment_dynamics.hpp"

namespace backlash::numeric {

class LinearFlight {
 public:
  LinearFlight(LinearSegment segment, SmallVector x0);
  SmallVector state(double t) const;
  /// x(t) − x(0) = ∫₀ᵗ e^{As} ds (A x0 + c), from one augmented exponential: no subtraction of
  /// absolute positions, so a gap that has barely left a face keeps its relative accuracy.
  SmallVector change(double t) const;
  const LinearSegment& segment() const { return segment_; }

 private:
  LinearSegment segment_;
  SmallVector x0_;
};

}  // namespace backlash::numeric
