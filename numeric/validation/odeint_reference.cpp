// The only translation unit that includes Boost.Odeint (slow to compile).
#include "backlash/numeric/reference.hpp"

#include <boost/numeric/odeint.hpp>

#include <array>
#include <stdexcept>

namespace backlash::numeric {

namespace odeint = boost::numeric::odeint;

namespace {

using FreeVector = std::array<double, 4>;    // θm, θm', θL, θL'
using ContactVector = std::array<double, 2>;  // θo, θo'

struct FreeSystem {
  Parameters p;
  void operator()(const FreeVector& x, FreeVector& dx, double /*t*/) const {
    const double drive = p.measured_at == model::MeasuredAt::Load ? p.K * (p.theta_R - x[2]) : p.K * (p.theta_R - x[0]);
    dx[0] = x[1];
    dx[1] = (drive - p.Fm * x[1]) / p.Jm;
    dx[2] = x[3];
    dx[3] = -(p.FL / p.JL) * x[3];
  }
};

struct ContactSystem {
  Parameters p;
  void operator()(const ContactVector& x, ContactVector& dx, double /*t*/) const {
    dx[0] = x[1];
    dx[1] = (p.K * (p.theta_R - x[0]) - (p.Fm + p.FL) * x[1]) / (p.Jm + p.JL);
  }
};

void check_times(const std::vector<double>& times) {
  for (std::size_t i = 0; i < times.size(); ++i)
    if (!(times[i] >= 0) || (i > 0 && times[i] < times[i - 1]))
      throw std::invalid_argument("reference trajectory: times must be non-negative and non-decreasing");
}

double initial_step(const std::vector<double>& times) {
  const double end = times.empty() ? 1.0 : times.back();
  return end > 0 ? std::min(1e-3, end * 1e-4) : 1e-3;
}

template <class Vector, class System, class Out>
std::vector<Out> integrate(const System& system, Vector x0, const std::vector<double>& times, double tolerance,
                           Out (*convert)(const Vector&)) {
  check_times(times);
  std::vector<Out> out;
  out.reserve(times.size());
  if (times.empty()) return out;
  // integrate_times starts at the first time: begin at 0 and drop that sample if not asked for.
  std::vector<double> grid;
  grid.reserve(times.size() + 1);
  const bool prepend = times.front() > 0;
  if (prepend) grid.push_back(0.0);
  grid.insert(grid.end(), times.begin(), times.end());
  auto stepper = odeint::make_dense_output(tolerance, tolerance, odeint::runge_kutta_dopri5<Vector>());
  bool skip = prepend;
  odeint::integrate_times(stepper, system, x0, grid.begin(), grid.end(), initial_step(times),
                          [&](const Vector& x, double) {
                            if (skip) {
                              skip = false;
                              return;
                            }
                            out.push_back(convert(x));
                          });
  return out;
}

FreeState free_from(const FreeVector& x) { return FreeState{x[0], x[1], x[2], x[3], x[2] - x[0]}; }
ContactState contact_from(const ContactVector& x) { return ContactState{x[0], x[1]}; }

}  // namespace

std::vector<FreeState> reference_free_trajectory(const Parameters& p, double v0, const std::vector<double>& times,
                                                 double tolerance) {
  const double theta0 = p.theta_R + cot_phi(p) * v0;
  return integrate<FreeVector>(FreeSystem{p}, FreeVector{theta0, v0, theta0, v0}, times, tolerance, &free_from);
}

std::vector<ContactState> reference_contact_trajectory(const Parameters& p, double theta_o0, double dtheta_o0,
                                                       const std::vector<double>& times, double tolerance) {
  return integrate<ContactVector>(ContactSystem{p}, ContactVector{theta_o0, dtheta_o0}, times, tolerance,
                                  &contact_from);
}

FreeState reference_free_state(const Parameters& p, double v0, double t, double tolerance) {
  return reference_free_trajectory(p, v0, {t}, tolerance).front();
}

ContactState reference_contact_state(const Parameters& p, double theta_o0, double dtheta_o0, double t,
                                     double tolerance) {
  return reference_contact_trajectory(p, theta_o0, dtheta_o0, {t}, tolerance).front();
}

std::vector<SmallVector> reference_linear_trajectory(const LinearSegment& segment, const SmallVector& z0,
                                                     const std::vector<double>& times, double tolerance) {
  using Vector = std::vector<double>;
  const auto n = segment.A.rows();
  auto system = [&segment, n](const Vector& z, Vector& dz, double /*t*/) {
    for (Eigen::Index i = 0; i < n; ++i) {
      double sum = segment.c(i);
      for (Eigen::Index j = 0; j < n; ++j) sum += segment.A(i, j) * z[j];
      dz[i] = sum;
    }
  };
  auto convert = [n](const Vector& z) {
    SmallVector out(n);
    for (Eigen::Index i = 0; i < n; ++i) out(i) = z[i];
    return out;
  };
  check_times(times);
  std::vector<SmallVector> out;
  if (times.empty()) return out;
  std::vector<double> grid;
  const bool prepend = times.front() > 0;
  if (prepend) grid.push_back(0.0);
  grid.insert(grid.end(), times.begin(), times.end());
  Vector x(z0.data(), z0.data() + n);
  auto stepper = odeint::make_dense_output(tolerance, tolerance, odeint::runge_kutta_dopri5<Vector>());
  bool skip = prepend;
  odeint::integrate_times(stepper, system, x, grid.begin(), grid.end(), initial_step(times), [&](const Vector& z, double) {
    if (skip) {
      skip = false;
      return;
    }
    out.push_back(convert(z));
  });
  return out;
}

}  // namespace backlash::numeric
