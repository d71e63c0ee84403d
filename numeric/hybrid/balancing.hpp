// numeric/hybrid/balancing.hpp (internal) — diagonal balancing of a square matrix, shared by the
// certified event search (first_crossing.cpp) and the flight after a bounce (linear_flight.cpp).
#pragma once

#include <Eigen/Dense>

#include <cmath>

namespace backlash::numeric::detail {

/// D (powers of two, so D A D⁻¹ is exact) that balances the off-diagonal row and column sums
/// of D A D⁻¹ (Osborne's iteration, the LAPACK gebal rule).  A stiff gain gives A entries K/J
/// next to entries of order 1; balanced, they are of order √(K/J).
template <class Matrix>
Eigen::VectorXd balancing(const Matrix& A) {
  const Eigen::Index n = A.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (int sweep = 0; sweep < 64; ++sweep) {
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      double c = 0, r = 0;  // off-diagonal column and row sums of D A D⁻¹
      for (Eigen::Index j = 0; j < n; ++j) {
        if (j == i) continue;
        c += std::fabs(A(j, i)) * d(j) / d(i);
        r += std::fabs(A(i, j)) * d(i) / d(j);
      }
      if (c == 0 || r == 0) continue;
      const double f = std::exp2(std::round(0.5 * std::log2(c / r)));  // d_i·f balances row and column i
      if (f != 1 && c / f + r * f < 0.95 * (c + r)) {
        d(i) *= f;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return d;
}

}  // namespace backlash::numeric::detail
