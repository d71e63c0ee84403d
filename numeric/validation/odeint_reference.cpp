// The only translation unit that includes Boost.Odeint (slow to compile).
#include "backlash/numeric/reference.hpp"

#include <boost/numeric/odeint.hpp>

#include <array>
#include <iterator>
#include <string>
#include <functional>
#include <stdexcept>
#include <type_traits>

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
  double K, theta_R, F, J;
  explicit ContactSystem(const Parameters& p) : K(p.K), theta_R(p.theta_R), F(p.Fm + p.FL), J(p.Jm + p.JL) {}
  void operator()(const ContactVector& x, ContactVector& dx, double /*t*/) const {
    dx[0] = x[1];
    dx[1] = (K * (theta_R - x[0]) - F * x[1]) / J;
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

// odeint's integrate_times compares times with an absolute epsilon, 2.2e-16
// (odeint/util/detail/less_with_sign.hpp): grid times below it count as reached before the
// first step, where the dense output holds no state yet — a read through a null pointer (a
// mesh of stiffness 1e40 is validated over 2e-18 s).  A grid that ends before 1 is therefore
// integrated in the time s = t/u, u the power of two that puts its end in [1, 2): scaling by
// a power of two is exact, so every product of the stepper keeps its bits.
double time_unit(const std::vector<double>& times) {
  const double end = times.empty() ? 0.0 : times.back();
  if (!(end > 0) || end >= 1) return 1.0;
  int exponent = 0;
  (void)std::frexp(end, &exponent);  // end = m·2^exponent, m in [0.5, 1)
  return std::ldexp(1.0, exponent - 1);
}

// The grid in units of u, from 0 (integrate_times starts at its first time): 0 is prepended
// when the first time is later, and `prepended` says so.
std::vector<double> scaled_grid(const std::vector<double>& times, double unit, bool& prepended) {
  std::vector<double> grid;
  grid.reserve(times.size() + 1);
  prepended = times.front() > 0;
  if (prepended) grid.push_back(0.0);
  for (const double t : times) grid.push_back(t / unit);
  return grid;
}

// Thrown by the observer once the caller's `until` holds: the integration ends at that sample.
struct Reached {};

void check_complete(std::size_t computed, const std::vector<double>& times) {
  if (computed != times.size())
    throw std::runtime_error("reference trajectory: odeint stopped after " + std::to_string(computed) + " of " +
                             std::to_string(times.size()) + " times");
}

// The states at `times`; with `until`, only up to the first state for which it holds (the
// samples before it are the same bits: the stepper's path does not depend on where it stops).
template <class Vector, class System, class Convert, class Until = std::nullptr_t>
auto integrate(const System& system, Vector x0, const std::vector<double>& times, double tolerance,
               const Convert& convert, const Until& until = nullptr) {
  using Out = decltype(convert(x0));
  check_times(times);
  std::vector<Out> out;
  out.reserve(times.size());
  if (times.empty()) return out;
  // integrate_times starts at the first time: begin at 0 and drop that sample if not asked for.
  const double unit = time_unit(times);
  bool skip = false;
  const std::vector<double> grid = scaled_grid(times, unit, skip);
  auto scaled = [&system, unit](const Vector& x, Vector& dx, double s) {
    system(x, dx, s * unit);
    for (double& d : dx) d *= unit;
  };
  auto stepper = odeint::make_dense_output(tolerance, tolerance, odeint::runge_kutta_dopri5<Vector>());
  try {
    odeint::integrate_times(stepper, scaled, x0, grid.begin(), grid.end(), initial_step(grid),
                            [&](const Vector& x, double) {
                              if (skip) {
                                skip = false;
                                return;
                              }
                              out.push_back(convert(x));
                              if constexpr (!std::is_null_pointer_v<Until>)
                                if (until && until(out.back())) throw Reached{};
                            });
  } catch (const Reached&) {
    return out;
  }
  check_complete(out.size(), times);
  return out;
}

FreeState free_from(const FreeVector& x) { return FreeState{x[0], x[1], x[2], x[3], x[2] - x[0]}; }
ContactState contact_from(const ContactVector& x) { return ContactState{x[0], x[1]}; }

}  // namespace

std::vector<FreeState> reference_free_trajectory(const Parameters& p, double v0, const std::vector<double>& times,
                                                 double tolerance) {
  return reference_free_trajectory(p, v0, times, tolerance, {});
}

std::vector<FreeState> reference_free_trajectory(const Parameters& p, double v0, const std::vector<double>& times,
                                                 double tolerance, const std::function<bool(const FreeState&)>& until) {
  const double theta0 = p.theta_R + cot_phi(p) * v0;
  return integrate<FreeVector>(FreeSystem{p}, FreeVector{theta0, v0, theta0, v0}, times, tolerance, &free_from, until);
}

std::vector<ContactState> reference_contact_trajectory(const Parameters& p, double theta_o0, double dtheta_o0,
                                                       const std::vector<double>& times, double tolerance) {
  // Kept per thread by the whole input: a map's gate validates many parameter sets with the same
  // K, θR, Fm + FL and Jm + JL (JL_over_Jm and FL_over_F keep the sums), and four of its seven
  // contact starts are then the same runs.
  thread_local KeptByBits<std::vector<ContactState>> kept(8);
  const ContactSystem system(p);
  const double numbers[] = {system.K, system.theta_R, system.F, system.J, theta_o0, dtheta_o0, tolerance};
  std::string key;
  append_bits(key, numbers, std::size(numbers));
  append_bits(key, times.data(), times.size());
  return kept.get(std::move(key), [&] {
    return integrate<ContactVector>(system, ContactVector{theta_o0, dtheta_o0}, times, tolerance, &contact_from);
  });
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
  return integrate<Vector>(system, Vector(z0.data(), z0.data() + n), times, tolerance, convert);
}

}  // namespace backlash::numeric
