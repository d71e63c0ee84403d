#include "backlash/numeric/linear_flight.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace backlash::numeric {

LinearFlight::LinearFlight(LinearSegment segment, SmallVector x0) : segment_(std::move(segment)), x0_(std::move(x0)) {}

SmallVector LinearFlight::state(double t) const {
  const Eigen::Index n = segment_.A.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = segment_.A * t;
  M.topRightCorner(n, 1) = segment_.c * t;
  const Eigen::MatrixXd E = M.exp();
  return SmallVector(E.topLeftCorner(n, n) * x0_ + E.topRightCorner(n, 1));
}

SmallVector LinearFlight::change(double t) const {
  const Eigen::Index n = segment_.A.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = segment_.A * t;
  M.topRightCorner(n, 1) = (segment_.A * x0_ + segment_.c) * t;
  const Eigen::MatrixXd E = M.exp();
  return SmallVector(E.topRightCorner(n, 1));
}

}  // namespace backlash::numeric
