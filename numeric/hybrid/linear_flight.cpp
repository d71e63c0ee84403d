#include "hybrid/linear_flight.hpp"

#include "hybrid/balancing.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace backlash::numeric {

namespace {

// e^M through a balanced M when balancing lowers its norm by more than kBalanceGain:
// e^M = D⁻¹ e^{D M D⁻¹} D exactly (D powers of two).  Scaling and squaring loses accuracy
// in proportion to ‖M‖; a stiff gain (K/J = 1e12 next to entries of order 1, t ~ √(J/K)) has
// ‖M‖₁ ~ 1e6 unbalanced and ~ 1 balanced.  Matrices with entries of one scale (the thesis's
// cases) are exponentiated as given.
constexpr double kBalanceGain = 16;

Eigen::MatrixXd exponential(const Eigen::MatrixXd& M) {
  const Eigen::VectorXd d = detail::balancing(M);
  const Eigen::MatrixXd B = d.asDiagonal() * M * d.cwiseInverse().asDiagonal();
  if (!(B.cwiseAbs().colwise().sum().maxCoeff() * kBalanceGain < M.cwiseAbs().colwise().sum().maxCoeff()))
    return M.exp();
  const Eigen::MatrixXd E = B.exp();
  return d.cwiseInverse().asDiagonal() * E * d.asDiagonal();
}

}  // namespace

LinearFlight::LinearFlight(LinearSegment segment, SmallVector x0) : segment_(std::move(segment)), x0_(std::move(x0)) {}

SmallVector LinearFlight::state(double t) const {
  const Eigen::Index n = segment_.A.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = segment_.A * t;
  M.topRightCorner(n, 1) = segment_.c * t;
  const Eigen::MatrixXd E = exponential(M);
  return SmallVector(E.topLeftCorner(n, n) * x0_ + E.topRightCorner(n, 1));
}

SmallVector LinearFlight::change(double t) const {
  const Eigen::Index n = segment_.A.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = segment_.A * t;
  M.topRightCorner(n, 1) = (segment_.A * x0_ + segment_.c) * t;
  const Eigen::MatrixXd E = exponential(M);
  return SmallVector(E.topRightCorner(n, 1));
}

}  // namespace backlash::numeric
