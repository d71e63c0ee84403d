// The only translation unit that includes Boost.Odeint (slow to compile).
#include "backlash/numeric/reference.hpp"

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cstring>
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

// a and b hold the same bits (−0 is not 0 here, and a NaN is its own bits).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Everything the contact mode reads of the parameters: K, θR, F = Fm + FL, J = Jm + JL (the
// sums rounded once, as the expression below always rounded them).
struct ContactSystem {
  double K, theta_R, F, J;
  explicit ContactSystem(const Parameters& p) : K(p.K), theta_R(p.theta_R), F(p.Fm + p.FL), J(p.Jm + p.JL) {}
  void operator()(const ContactVector& x, ContactVector& dx, double /*t*/) const {
    dx[0] = x[1];
    dx[1] = (K * (theta_R - x[0]) - F * x[1]) / J;
  }
  bool same(const ContactSystem& o) const {
    return same_bits(K, o.K) && same_bits(theta_R, o.theta_R) && same_bits(F, o.F) && same_bits(J, o.J);
  }
};

// The contact references computed last on this thread, by their whole input: the system (its
// four numbers), the start, the times and the tolerance.  The reference is a function of that
// input alone (the same stepper, the same operations), so a hit returns the same bits.  A map's
// gate validates many parameter sets with the same Jm + JL, Fm + FL and K (JL_over_Jm and
// FL_over_F keep the sums): four of its seven contact starts (at rest and moving, off θR) are the
// same for all of them.  Bit-for-bit comparisons only.
class ContactMemo {
 public:
  const std::vector<ContactState>* find(const ContactSystem& s, double x0, double v0, const std::vector<double>& times,
                                        double tolerance) {
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      const Entry& e = entries_[i];
      if (e.system.same(s) && same_bits(e.x0, x0) && same_bits(e.v0, v0) && same_bits(e.tolerance, tolerance) &&
          same_bits(e.times, times)) {
        std::rotate(entries_.begin(), entries_.begin() + static_cast<long>(i), entries_.begin() + static_cast<long>(i) + 1);
        return &entries_.front().states;  // the most recently used first
      }
    }
    return nullptr;
  }
  void keep(const ContactSystem& s, double x0, double v0, const std::vector<double>& times, double tolerance,
            const std::vector<ContactState>& states) {
    if (entries_.size() == kEntries) entries_.pop_back();
    entries_.insert(entries_.begin(), Entry{s, x0, v0, tolerance, times, states});
  }

 private:
  static constexpr std::size_t kEntries = 8;
  struct Entry {
    ContactSystem system;
    double x0, v0, tolerance;
    std::vector<double> times;
    std::vector<ContactState> states;
  };
  std::vector<Entry> entries_;
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

void check_complete(std::size_t computed, const std::vector<double>& times) {
  if (computed != times.size())
    throw std::runtime_error("reference trajectory: odeint stopped after " + std::to_string(computed) + " of " +
                             std::to_string(times.size()) + " times");
}

// odeint's integrate_times for a dense-output stepper (Boost 1.74,
// boost/numeric/odeint/integrate/detail/integrate_times.hpp), the same calls in the same order,
// except that `observe` returns false to end the run at that sample: no exception to unwind
// (a map's gate ends most of its free references at recombination).
template <class Stepper, class System, class Vector, class Observe>
void integrate_times_while(Stepper& st, const System& system, Vector& x, const std::vector<double>& grid, double dt,
                           const Observe& observe) {
  using odeint::detail::less_eq_with_sign;
  if (grid.empty()) return;
  const double last = grid.back();
  auto t = grid.begin();
  st.initialize(x, *t, dt);
  if (!observe(x)) return;
  for (++t; t != grid.end();) {
    for (; t != grid.end() && less_eq_with_sign(*t, st.current_time(), st.current_time_step()); ++t) {
      st.calc_state(*t, x);
      if (!observe(x)) return;
    }
    if (less_eq_with_sign(st.current_time() + st.current_time_step(), last, st.current_time_step())) {
      st.do_step(system);
    } else if (t != grid.end()) {  // the last step, ending exactly on the last time
      st.initialize(st.current_state(), st.current_time(), last - st.current_time());
      st.do_step(system);
    }
  }
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
  // The run starts at the first time: begin at 0 and drop that sample if not asked for.
  const double unit = time_unit(times);
  bool skip = false;
  const std::vector<double> grid = scaled_grid(times, unit, skip);
  auto scaled = [&system, unit](const Vector& x, Vector& dx, double s) {
    system(x, dx, s * unit);
    for (double& d : dx) d *= unit;
  };
  auto stepper = odeint::make_dense_output(tolerance, tolerance, odeint::runge_kutta_dopri5<Vector>());
  bool reached = false;
  integrate_times_while(stepper, scaled, x0, grid, initial_step(grid), [&](const Vector& x) {
    if (skip) return !(skip = false);
    out.push_back(convert(x));
    if constexpr (!std::is_null_pointer_v<Until>)
      if (until && until(out.back())) reached = true;
    return !reached;
  });
  if (!reached) check_complete(out.size(), times);
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
  thread_local ContactMemo memo;
  const ContactSystem system(p);
  if (const std::vector<ContactState>* kept = memo.find(system, theta_o0, dtheta_o0, times, tolerance)) return *kept;
  std::vector<ContactState> states =
      integrate<ContactVector>(system, ContactVector{theta_o0, dtheta_o0}, times, tolerance, &contact_from);
  memo.keep(system, theta_o0, dtheta_o0, times, tolerance, states);
  return states;
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
