// Limit cycles of the model with effects (effects_limit_cycle.hpp).
#include "backlash/numeric/effects_limit_cycle.hpp"

#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <optional>
#include <sstream>

namespace backlash::numeric {

namespace {

using Vector = Eigen::VectorXd;

// The section Σ: states just after the gap reaches face +1 from the other side (a
// recombination: a rigid impact, or the compliant mesh engaging), in the coordinates
// (θm, θ̇m, θL, θ̇L).  A limit cycle crosses it once per period; restarting a simulation
// from a crossing is exact (the flags — contact, face, sticking, drive regime — come along).
class Section {
 public:
  /// `silent`: the outcome of a return not seen within the horizon (verdict_of: settling only when
  /// it is the plain "no recombination within the horizon").
  Section(const ValidatedEffectModel& model, double horizon, std::string silent = "no recombination within the horizon")
      : model_(model), horizon_(horizon), silent_(std::move(silent)) {}

  Vector coordinates(const HybridState& s) const {
    Vector x(4);
    x << s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L;
    return x;
  }

  HybridState state(const Vector& x, const HybridState& like) const {
    HybridState s = like;
    s.theta_m = x(0);
    s.dtheta_m = x(1);
    s.theta_L = x(2);
    s.dtheta_L = x(3);
    return s;
  }

  struct Return {
    bool valid = false;
    HybridState state;   ///< on Σ again
    double duration = 0;
    std::string outcome;  ///< why not valid
    double rest_error = 0;
    bool bounced = false;
    Extremes extremes;
    double separation_velocity = NAN, theta_o_separation = NAN;  ///< at the period's separation from face −1
  };

  // P^k(s): the k-th next crossing of Σ; the figures are those of the k returns together (the
  // separation velocity the first return's).
  Return next(const HybridState& s, int k, bool track_extremes = false) const {
    Return out = next(s, track_extremes);
    for (int j = 1; j < k && out.valid; ++j) {
      const Return r = next(out.state, track_extremes);
      if (!r.valid) return r;
      out.state = r.state;
      out.duration += r.duration;
      out.bounced = out.bounced || r.bounced;
      Extremes& x = out.extremes;
      const Extremes& y = r.extremes;
      x.theta_o_min = std::min(x.theta_o_min, y.theta_o_min), x.theta_o_max = std::max(x.theta_o_max, y.theta_o_max);
      x.theta_m_min = std::min(x.theta_m_min, y.theta_m_min), x.theta_m_max = std::max(x.theta_m_max, y.theta_m_max);
      x.theta_L_min = std::min(x.theta_L_min, y.theta_L_min), x.theta_L_max = std::max(x.theta_L_max, y.theta_L_max);
    }
    return out;
  }

  // P(s): the next crossing of Σ.
  Return next(const HybridState& s, bool track_extremes = false) const {
    SimulationOptions o;
    o.t_end = horizon_;
    o.max_events = 20000;
    o.track_extremes = track_extremes;
    EffectsEngineOptions engine;
    engine.general_engine = true;
    engine.stop_at_face = +1;
    engine.stop_at_kind = EventKind::Recombination;
    const SimulationResult r = simulate_effects(model_, s, o, engine);
    Return out;
    for (const SimulationEvent& e : r.events) out.bounced = out.bounced || e.bounce;
    out.extremes = r.extremes;
    if (r.status == SimulationStatus::Rest) {
      out.outcome = "rest";
      out.rest_error = r.theta_o_final - model_.parameters().theta_R;
      return out;
    }
    const SimulationEvent* crossing = nullptr;
    for (const SimulationEvent& e : r.events)
      if (e.kind == EventKind::Recombination && e.after.face == +1 && e.t > 0) crossing = &e;
    if (r.status != SimulationStatus::Completed || crossing == nullptr || r.t_final >= horizon_) {
      out.outcome = r.status == SimulationStatus::Completed ? silent_ : std::string(to_string(r.status));
      return out;
    }
    out.valid = true;
    out.state = crossing->after;
    out.duration = crossing->t;
    // The period's separation from face −1 (else its first separation): the separation velocity.
    bool any = false, from_minus = false;
    for (const SimulationEvent& e : r.events) {
      if (e.kind != EventKind::Separation || from_minus || (any && e.after.face != -1)) continue;
      out.separation_velocity = std::fabs(e.dtheta_o);
      out.theta_o_separation = e.theta_o;
      any = true;
      from_minus = e.after.face == -1;
    }
    return out;
  }

 private:
  const ValidatedEffectModel& model_;
  double horizon_;
  std::string silent_;
};

double scale_of(const Vector& x) { return std::max(1.0, x.cwiseAbs().maxCoeff()); }

void fill_figures(const Parameters& p, double separation_velocity, double theta_o_separation, const Extremes& x,
                  double period, bool bounced, LimitCycle& cycle) {
  cycle.period = period;
  cycle.bounced = bounced;
  cycle.theta_o_max = x.theta_o_max;
  cycle.theta_o_min = x.theta_o_min;
  cycle.amplitude = std::max(x.theta_o_max - p.theta_R, p.theta_R - x.theta_o_min);
  cycle.peak_to_peak = x.theta_o_max - x.theta_o_min;
  cycle.peak_to_peak_motor = x.theta_m_max - x.theta_m_min;
  cycle.peak_to_peak_load = x.theta_L_max - x.theta_L_min;
  cycle.separation_velocity = separation_velocity;
  cycle.theta_o_separation = theta_o_separation;
}

// What one seed's search ended in: a cycle, a motion that settles (rest, or no further
// recombination), one that grows without bound, or one the search could not resolve (the
// return map did not settle at any period up to max_period, or a simulation stopped early).
enum class Verdict { Converged, Settles, Diverges, Unresolved };

struct Iteration {
  Verdict verdict = Verdict::Unresolved;
  bool converged() const { return verdict == Verdict::Converged; }
  std::string outcome;
  HybridState state;   ///< the fixed point of P^k, or where the iteration stopped
  int cycles = 0;
  int period_count = 1;  ///< k
  bool newton = false;   ///< converged by Newton's method (not by the iteration)
  double residual = 0;
  double rest_error = 0;
};

// Up to this many crossings of Σ per period are searched for (docs/design.md, "limit-cycle").
constexpr int max_period = 4;

bool diverges(const Vector& x, double velocity_scale) {
  return !x.allFinite() || x.cwiseAbs().maxCoeff() > 1e8 * velocity_scale;
}

Verdict verdict_of(const Section::Return& r) {
  if (r.outcome == "rest" || r.outcome == "no recombination within the horizon") return Verdict::Settles;
  return Verdict::Unresolved;  // the simulation stopped early (chattering, event limit, …)
}

// Iterates P^k from a seed, accelerated by Steffensen's method (Aitken's Δ² on x, P^k(x),
// P^2k(x) along the section's one contracting direction), until |P^k(x) − x| is at rounding
// level, the motion rests or grows without bound.  At most max_cycles/k iterations.
Iteration iterate(const Section& section, HybridState s, const EffectLimitCycleOptions& o, double velocity_scale,
                  int k = 1) {
  Iteration it;
  it.period_count = k;
  auto fail = [&it](const Section::Return& r) {
    it.outcome = r.outcome;
    it.verdict = verdict_of(r);
    it.rest_error = r.rest_error;
    return it;
  };
  Section::Return r = section.next(s, k);
  if (!r.valid) return fail(r);
  s = r.state;
  bool accelerate = true;
  double previous_residual = INFINITY;
  for (int n = 0; n < o.max_cycles / k; ++n) {
    const Section::Return r1 = section.next(s, k);
    if (!r1.valid) return fail(r1);
    const Vector x0 = section.coordinates(s), x1 = section.coordinates(r1.state);
    if (diverges(x1, velocity_scale)) {
      it.outcome = "divergent: the separation velocity grows without bound";
      it.verdict = Verdict::Diverges;
      return it;
    }
    it.cycles = n + 1;
    it.residual = (x1 - x0).cwiseAbs().maxCoeff();
    // Steffensen only while it helps: a motion decaying toward rest has no fixed point to
    // extrapolate to, and from there on the plain iteration decides.
    if (accelerate && it.residual > 0.9 * previous_residual) accelerate = false;
    previous_residual = it.residual;
    if (it.residual <= o.tolerance * scale_of(x1)) {
      it.verdict = Verdict::Converged;
      it.state = r1.state;
      return it;
    }
    const Section::Return r2 = section.next(r1.state, k);
    if (!r2.valid) return fail(r2);
    const Vector x2 = section.coordinates(r2.state);
    // Aitken along the step direction: x* ≈ x2 − λ/(1 − λ)·(x2 − x1), λ = ⟨d1, d0⟩/⟨d0, d0⟩.
    const Vector d0 = x1 - x0, d1 = x2 - x1;
    const double lambda = d1.dot(d0) / d0.dot(d0);
    s = r2.state;
    if (accelerate && std::isfinite(lambda) && lambda > -0.95 && lambda < 0.95) {
      const Vector accelerated = x2 - lambda / (1 - lambda) * d1;
      // Only a modest extrapolation: a motion decaying toward rest (a Coulomb dead band) has no
      // fixed point to extrapolate to, and its velocities must not be pushed through zero.
      const bool modest = (accelerated - x2).cwiseAbs().maxCoeff() <= 4 * d1.cwiseAbs().maxCoeff() &&
                          accelerated(1) * x2(1) > 0 && std::fabs(accelerated(1)) >= 0.25 * std::fabs(x2(1));
      if (accelerated.allFinite() && modest) s = section.state(accelerated, r2.state);
    }
  }
  it.outcome = "the return map did not settle within " + std::to_string(o.max_cycles) + " cycles";
  it.state = s;
  return it;
}

// The smallest j dividing k with P^j(x*) = x* (to 1e-9 of the state): a fixed point of P^k
// found by the iteration may be one of a lower power (an unstable cycle of period 1, say).
int minimal_period(const Section& section, const HybridState& fixed, int k) {
  const Vector star = section.coordinates(fixed);
  Section::Return r;
  r.valid = true;
  r.state = fixed;
  for (int j = 1; j < k; ++j) {
    r = section.next(r.state);
    if (!r.valid) return k;
    if (k % j == 0 && (section.coordinates(r.state) - star).cwiseAbs().maxCoeff() <= 1e-9 * scale_of(star)) return j;
  }
  return k;
}

Iteration newton(const ValidatedEffectModel& model, const Section& section, HybridState s, int k);
double multiplier_from_jacobian(const ValidatedEffectModel& model, const Section& section, const HybridState& fixed,
                                int k);

// From a seed: P, and when P does not settle, P², P³, P⁴ from where the previous iteration
// stopped (a period-k cycle is a fixed point of P^k); when none settles, Newton's method on
// P, P², … from where each stopped.
Iteration iterate_periods(const ValidatedEffectModel& model, const Section& section, const HybridState& seed,
                          const EffectLimitCycleOptions& o, double velocity_scale) {
  Iteration it = iterate(section, seed, o, velocity_scale);
  // Where the iterations of P, P², … stopped, for Newton's method (a slow or unstable cycle).
  std::vector<HybridState> stops;
  for (int k = 2; k <= max_period && it.verdict == Verdict::Unresolved && it.cycles > 0; ++k) {
    stops.push_back(it.state);
    Iteration next = iterate(section, it.state, o, velocity_scale, k);
    if (next.verdict == Verdict::Unresolved && next.cycles > 0) {
      it.state = next.state;
      continue;
    }
    it = next;
  }
  if (it.verdict == Verdict::Unresolved && it.cycles > 0) stops.push_back(it.state);
  // A stable cycle (the iterations' attractor, converging slowly) is the answer.  An unstable
  // one is not: the motion leaves it for an attractor the search has not resolved, so it is
  // only named in the reason (docs/design.md, "The limit-cycle contract").
  std::optional<Iteration> unstable;
  double unstable_multiplier = NAN;
  for (std::size_t j = 0; j < stops.size() && it.verdict == Verdict::Unresolved && it.cycles > 0; ++j) {
    const int k = static_cast<int>(j) + 1;
    const Iteration polished = newton(model, section, stops[j], k);
    if (!polished.converged()) continue;
    const double m = multiplier_from_jacobian(model, section, polished.state, k);
    if (std::fabs(m) < 1) it = polished;
    else if (!unstable) unstable = polished, unstable_multiplier = m;
  }
  if (it.converged()) it.period_count = minimal_period(section, it.state, it.period_count);
  if (it.verdict == Verdict::Unresolved && it.cycles > 0) {
    it.outcome = "the return map did not settle within " + std::to_string(o.max_cycles) +
                 " returns at any period from 1 to " + std::to_string(max_period) +
                 " (a slowly converging, quasi-periodic or chaotic motion)";
    if (unstable) {
      char text[160];
      std::snprintf(text, sizeof text, "; Newton's method finds an unstable period-%d cycle there (multiplier %.6g), which the motion leaves",
                    minimal_period(section, unstable->state, unstable->period_count), unstable_multiplier);
      it.outcome += text;
    }
  }
  return it;
}

// The multiplier along the one direction the first return picks: x1 = P^k(x* + δe) lies on Σ
// near x*; the ratios q_j = ⟨x_{j+1} − x*, u⟩/⟨x_j − x*, u⟩ of two further returns,
// extrapolated to zero distance (Richardson: q(d) = λ + c·d), give λ.  Exact when P^k's range
// near x* is one-dimensional (rigid gears); with a compliant mesh it need not be.
double multiplier_along_a_ray(const Section& section, const HybridState& fixed, int k) {
  const Vector star = section.coordinates(fixed);
  Vector perturbed = star;
  perturbed(1) += 1e-4 * scale_of(star);  // a velocity: any direction reaches Σ after one return
  Section::Return r = section.next(section.state(perturbed, fixed), k);
  if (!r.valid) return NAN;
  std::vector<Vector> x{section.coordinates(r.state)};
  for (int j = 0; j < 2; ++j) {
    r = section.next(r.state, k);
    if (!r.valid) return NAN;
    x.push_back(section.coordinates(r.state));
  }
  const Vector d0 = x[0] - star;
  if (d0.norm() == 0) return 0;
  const Vector u = d0 / d0.norm();
  const double a0 = d0.dot(u), a1 = (x[1] - star).dot(u), a2 = (x[2] - star).dot(u);
  if (a1 == 0) return 0;
  const double q0 = a1 / a0, q1 = a2 / a1;
  return a1 != a0 ? (q1 * a0 - q0 * a1) / (a0 - a1) : q1;
}

// Directions along Σ at s: both angles together, the common velocity, and — with a compliant
// mesh or after a bounce, where the two velocities are independent — the relative velocity.
std::vector<Vector> tangent_directions(const ValidatedEffectModel& model, const HybridState& s) {
  std::vector<Vector> directions{Vector::Unit(4, 0) + Vector::Unit(4, 2), Vector::Unit(4, 1) + Vector::Unit(4, 3)};
  if (model.effects().compliant() || s.dtheta_m != s.dtheta_L) directions.push_back(Vector::Unit(4, 1) - Vector::Unit(4, 3));
  return directions;
}

// Newton's method on F(x) = P^k(x) − x along Σ, from where an iteration stopped (a slowly
// converging or an unstable cycle): x ← x + D·c with (W − D)·c = −F in least squares, D the
// tangent directions and W = DP^k·D by central differences.  Converged when |F| ≤ 1e-11 of
// the state (the differences' rounding bounds what Newton can reach).
Iteration newton(const ValidatedEffectModel& model, const Section& section, HybridState s, int k) {
  Iteration it;
  it.period_count = k;
  for (int step = 0; step < 8; ++step) {
    const Section::Return r = section.next(s, k);
    if (!r.valid) return it;
    const Vector x = section.coordinates(s), F = section.coordinates(r.state) - x;
    it.residual = F.cwiseAbs().maxCoeff();
    if (it.residual <= 1e-11 * scale_of(x)) {
      it.verdict = Verdict::Converged;
      it.newton = true;
      it.state = s;
      it.cycles = step;
      return it;
    }
    const std::vector<Vector> directions = tangent_directions(model, s);
    const double h = 1e-6 * scale_of(x);
    Eigen::MatrixXd D(4, static_cast<Eigen::Index>(directions.size())), W = D;
    for (Eigen::Index i = 0; i < D.cols(); ++i) {
      D.col(i) = directions[static_cast<std::size_t>(i)];
      const Section::Return plus = section.next(section.state(x + h * D.col(i), s), k);
      const Section::Return minus = section.next(section.state(x - h * D.col(i), s), k);
      if (!plus.valid || !minus.valid) return it;
      W.col(i) = (section.coordinates(plus.state) - section.coordinates(minus.state)) / (2 * h);
    }
    const Vector c = (W - D).completeOrthogonalDecomposition().solve(-F);
    if (!c.allFinite()) return it;
    s = section.state(x + D * c, s);
  }
  return it;
}

// DP^k at the fixed point, by central differences, restricted to Σ's tangent: perturbations
// that keep the state on Σ (both angles together; the common velocity; with a compliant mesh or
// after a bounce also the relative one) return to y± on Σ, and (P^k(y+) − P^k(y−)) =
// DP^k·(y+ − y−) on the span of the (y+ − y−) (an SVD picks its rank).  The eigenvalue of
// largest modulus of that restriction; its modulus when it is a complex pair.
double multiplier_from_jacobian(const ValidatedEffectModel& model, const Section& section, const HybridState& fixed,
                                int k) {
  const Vector star = section.coordinates(fixed);
  const double h = 1e-6 * scale_of(star);
  const std::vector<Vector> directions = tangent_directions(model, fixed);
  const auto columns = static_cast<Eigen::Index>(directions.size());
  Eigen::MatrixXd Y(4, columns), Z(4, columns);
  for (Eigen::Index i = 0; i < columns; ++i) {
    std::array<Vector, 2> y, z;
    for (int side = 0; side < 2; ++side) {
      const Vector x = star + (side == 0 ? h : -h) * directions[static_cast<std::size_t>(i)];
      const Section::Return first = section.next(section.state(x, fixed), k);
      if (!first.valid) return NAN;
      const Section::Return second = section.next(first.state, k);
      if (!second.valid) return NAN;
      y[side] = section.coordinates(first.state), z[side] = section.coordinates(second.state);
    }
    Y.col(i) = y[0] - y[1], Z.col(i) = z[0] - z[1];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Y, Eigen::ComputeThinU);
  const Eigen::VectorXd& sigma = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < sigma.size() && sigma(rank) > 1e-5 * sigma(0)) ++rank;
  if (rank == 0) return 0;
  const Eigen::MatrixXd U = svd.matrixU().leftCols(rank);
  const Eigen::MatrixXd A = (U.transpose() * Z) * (U.transpose() * Y).completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::VectorXcd lambda = A.eigenvalues();
  Eigen::Index dominant = 0;
  for (Eigen::Index i = 1; i < lambda.size(); ++i)
    if (std::abs(lambda(i)) > std::abs(lambda(dominant))) dominant = i;
  const std::complex<double> m = lambda(dominant);
  return std::fabs(m.imag()) <= 1e-9 * std::abs(m) ? m.real() : std::abs(m);
}

// The multiplier of P^k: the ray's Richardson estimate (more digits) when the Jacobian's
// dominant eigenvalue confirms it to the central differences' accuracy, else the Jacobian's.
double multiplier_at(const ValidatedEffectModel& model, const Section& section, const HybridState& fixed, int k) {
  const double ray = multiplier_along_a_ray(section, fixed, k);
  const double jacobian = multiplier_from_jacobian(model, section, fixed, k);
  if (!std::isfinite(jacobian)) return ray;
  return std::fabs(ray - jacobian) <= 1e-3 * std::max(1.0, std::fabs(jacobian)) ? ray : jacobian;
}

// With a delay the state is a whole history: one continuous simulation whose successive
// separations from face −1 converge to the cycle; the multiplier is the ratio of successive
// steps while they are well above rounding.
struct DelayedCycle {
  Iteration iteration;
  double multiplier = NAN;
  double crossing = 0, period = 0;
  HybridState seed;
};

Vector coordinates_after(const SimulationEvent& e) {
  Vector x(4);
  x << e.after.theta_m, e.after.dtheta_m, e.after.theta_L, e.after.dtheta_L;
  return x;
}

// The multiplier of a delayed period-k cycle: the median of the last three ratios of steps k
// crossings apart, |x_n − x_{n−k}| / |x_{n−k} − x_{n−2k}|, while they are well above rounding.
double delayed_multiplier(const std::vector<Vector>& x, std::size_t n, int k) {
  const auto K = static_cast<std::size_t>(k);
  std::vector<double> ratios;
  auto step = [&](std::size_t m) { return (x[m] - x[m - K]).cwiseAbs().maxCoeff(); };
  for (std::size_t m = 2 * K; m <= n; ++m)
    if (step(m - K) > 1e-7 && step(m) > 1e-7) ratios.push_back(step(m) / step(m - K));
  if (ratios.empty()) return NAN;
  std::vector<double> tail(ratios.end() - std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(ratios.size()), 3), ratios.end());
  std::sort(tail.begin(), tail.end());
  return tail[tail.size() / 2];
}

// A crossing n at which the section state repeats every k crossings (k = 2 … max_period, twice
// in a row) with distinct points in between: a period-k cycle of the delayed loop.
int delayed_period(const std::vector<Vector>& x, std::size_t n, double tolerance) {
  auto lag = [&](std::size_t m, std::size_t k) { return (x[m] - x[m - k]).cwiseAbs().maxCoeff(); };
  const double tol = tolerance * scale_of(x[n]);
  for (int k = 2; k <= max_period; ++k) {
    const auto K = static_cast<std::size_t>(k);
    if (n < K + 1 || lag(n, K) > tol || lag(n - 1, K) > tol) continue;
    bool distinct = true;
    for (std::size_t d = 1; d < K; ++d) distinct = distinct && (K % d != 0 || lag(n, d) > 1e-6 * scale_of(x[n]));
    if (distinct) return k;
  }
  return 0;
}

// Why a delayed run that did not converge did not: its crossings grew without bound, or the
// simulation stopped early, or it ran out of cycles.
void delayed_failure(const SimulationResult& r, const std::vector<Vector>& x, double velocity_scale, Iteration& it) {
  for (std::size_t n = 0; n < x.size(); ++n)
    if (diverges(x[n], velocity_scale) || (r.status == SimulationStatus::NonFinite && n + 1 == x.size())) {
      it.verdict = Verdict::Diverges;
      it.outcome = "divergent: the delayed loop's oscillation grows without bound";
      return;
    }
  if (x.size() < 3) {
    it.verdict = r.status == SimulationStatus::Completed ? Verdict::Settles : Verdict::Unresolved;
    it.outcome = std::string("no sustained oscillation (") + to_string(r.status) + ")";
    return;
  }
  it.verdict = Verdict::Unresolved;
  it.outcome = "the oscillation did not settle within the simulated cycles at any period from 1 to " +
               std::to_string(max_period) + " (" + to_string(r.status) + ")";
}

// The period k with which the section states repeat at crossing n (1 … max_period), 0 if none.
int delayed_repeat(const std::vector<Vector>& x, std::size_t n, double tolerance) {
  const double step = (x[n] - x[n - 1]).cwiseAbs().maxCoeff();
  return n >= 2 && step <= tolerance * scale_of(x[n]) ? 1 : delayed_period(x, n, tolerance);
}

// The run ends at the first crossing where the states repeat or grow without bound: what the
// search reads from a longer run ends there too, and the rest would only cost steps of at most τ.
EffectsEngineOptions delayed_run_options(const EffectLimitCycleOptions& o, double velocity_scale,
                                         std::vector<Vector>& seen) {
  EffectsEngineOptions engine{.general_engine = true};
  engine.stop_when = [&o, velocity_scale, &seen](const std::vector<SimulationEvent>& events) {
    const SimulationEvent& e = events.back();
    if (e.kind != EventKind::Recombination || e.after.face != +1) return false;
    seen.push_back(coordinates_after(e));
    const std::size_t n = seen.size() - 1;
    return diverges(seen[n], velocity_scale) || (n >= 1 && delayed_repeat(seen, n, o.tolerance) != 0);
  };
  return engine;
}

DelayedCycle iterate_delayed(const ValidatedEffectModel& model, const HybridState& seed,
                             const EffectLimitCycleOptions& o, double horizon_per_cycle, double velocity_scale) {
  DelayedCycle out;
  out.seed = seed;
  const Parameters& p = model.parameters();
  SimulationOptions so;
  so.t_end = horizon_per_cycle * (o.max_cycles + 2);
  so.max_events = 50 * (o.max_cycles + 2);
  std::vector<Vector> seen;
  const SimulationResult r = simulate_effects(model, seed, so, delayed_run_options(o, velocity_scale, seen));
  if (r.status == SimulationStatus::Rest) {
    out.iteration.outcome = "rest";
    out.iteration.verdict = Verdict::Settles;
    out.iteration.rest_error = r.theta_o_final - p.theta_R;
    return out;
  }
  std::vector<const SimulationEvent*> crossings;
  std::vector<Vector> x;
  for (const SimulationEvent& e : r.events)
    if (e.kind == EventKind::Recombination && e.after.face == +1) crossings.push_back(&e), x.push_back(coordinates_after(e));
  for (std::size_t n = 1; n < x.size() && !diverges(x[n], velocity_scale); ++n) {
    const int k = delayed_repeat(x, n, o.tolerance);
    if (k == 0) continue;
    const auto K = static_cast<std::size_t>(k);
    out.iteration.verdict = Verdict::Converged;
    out.iteration.period_count = k;
    out.iteration.state = crossings[n]->after;
    out.iteration.cycles = static_cast<int>(n);
    out.iteration.residual = (x[n] - x[n - K]).cwiseAbs().maxCoeff();
    out.crossing = crossings[n]->t;
    out.period = crossings[n]->t - crossings[n - K]->t;
    out.multiplier = delayed_multiplier(x, n, k);
    return out;
  }
  delayed_failure(r, x, velocity_scale, out.iteration);
  return out;
}
// The delayed cycle's figures: the same continuous run, extremes over its last period only.
void describe_delayed_cycle(const ValidatedEffectModel& model, const DelayedCycle& d, LimitCycle& cycle) {
  SimulationOptions so;
  so.t_end = d.crossing + d.period;
  so.max_events = 1000000;
  so.track_extremes = true;
  const SimulationResult r = simulate_effects(model, d.seed, so, {.general_engine = true, .extremes_after = d.crossing});
  bool bounced = false;
  double velocity = NAN, theta = NAN;
  bool from_minus = false;
  for (const SimulationEvent& e : r.events) {
    if (e.t < d.crossing) continue;
    bounced = bounced || e.bounce;
    if (e.kind == EventKind::Separation && !from_minus) {
      velocity = std::fabs(e.dtheta_o);
      theta = e.theta_o;
      from_minus = e.after.face == -1;
    }
  }
  fill_figures(model.parameters(), velocity, theta, r.extremes, d.period, bounced, cycle);
}

// One period (k returns) from s on Σ with exact extremes: the cycle's figures.
void describe_cycle(const ValidatedEffectModel& model, const Section& section, const HybridState& s, int k,
                    LimitCycle& cycle) {
  const Section::Return r = section.next(s, k, true);
  fill_figures(model.parameters(), r.separation_velocity, r.theta_o_separation, r.extremes, r.duration, r.bounced, cycle);
}

std::vector<HybridState> seeds(const ValidatedEffectModel& model, const EffectLimitCycleOptions& o) {
  const Parameters& p = model.parameters();
  std::vector<HybridState> out;
  if (o.warm_start) out.push_back(*o.warm_start);
  if (std::isfinite(o.step)) out.push_back(effects_step_start(p, model.effects(), o.step));
  const double scale = std::max(1.0, std::fabs(p.theta_R));
  for (double v : o.seed_velocities) {
    HybridState s = state_on_face(p, -1, p.theta_R + cot_phi(p) * v * scale, v * scale, false);
    s.drive_regime = drive_regime(p, model.effects(), measured(p, s));
    out.push_back(s);
  }
  return out;
}


// A cycle is reported only when its figures are those of a cycle: a positive, finite period
// and swing, an amplitude the section's scale can represent (the divergence bound).  Why not.
std::optional<std::string> inconsistency(const Parameters& p, const LimitCycle& c) {
  const double angle_bound = 1e8 * std::max({1.0, std::fabs(p.theta_R), p.backlash});
  char text[200];
  if (!(c.period > 0) || !std::isfinite(c.period))
    std::snprintf(text, sizeof text, "period %g", c.period);
  else if (!(c.peak_to_peak > 0) || !std::isfinite(c.peak_to_peak))
    std::snprintf(text, sizeof text, "peak-to-peak %g", c.peak_to_peak);
  else if (!(c.amplitude < angle_bound))
    std::snprintf(text, sizeof text, "amplitude %g beyond %g", c.amplitude, angle_bound);
  else
    return std::nullopt;
  return std::string("the return map converged to a state whose cycle is inconsistent (") + text + "), so no cycle is reported";
}

// One seed's search; on convergence the cycle's figures go to `cycle`.
Iteration search_from(const ValidatedEffectModel& model, const Section& section, const HybridState& seed,
                      const EffectLimitCycleOptions& options, double horizon, double velocity_scale, LimitCycle& cycle) {
  if (model.effects().delayed()) {
    const DelayedCycle d = iterate_delayed(model, seed, options, horizon / 10, velocity_scale);
    if (d.iteration.converged()) {
      cycle.method = "return map (iteration of one continuous run)";
      cycle.multiplier = d.multiplier;
      describe_delayed_cycle(model, d, cycle);
    }
    return d.iteration;
  }
  const Iteration it = iterate_periods(model, section, seed, options, velocity_scale);
  if (it.converged()) {
    cycle.method = it.newton ? "return map (Newton's method)" : "return map (Steffensen iteration)";
    cycle.multiplier = multiplier_at(model, section, it.state, it.period_count);
    cycle.section_state = it.state;
    describe_cycle(model, section, it.state, it.period_count, cycle);
  }
  return it;
}

// No cycle from any seed: the status and the reason from what the seeds' searches ended in.
void without_cycle(const ValidatedEffectModel& model, const std::vector<Iteration>& ends, LimitCycle& cycle) {
  const Parameters& p = model.parameters();
  std::vector<std::string> outcomes;
  bool all_rest = true, diverging = false, unresolved = false;
  double rest_error = 0;
  for (const Iteration& it : ends) {
    all_rest = all_rest && it.outcome == "rest";
    diverging = diverging || it.verdict == Verdict::Diverges;
    unresolved = unresolved || it.verdict == Verdict::Unresolved;
    if (it.outcome == "rest") rest_error = it.rest_error;
    if (std::find(outcomes.begin(), outcomes.end(), it.outcome) == outcomes.end()) outcomes.push_back(it.outcome);
  }
  std::ostringstream reason;
  cycle.status = diverging ? CycleStatus::Divergent : unresolved ? CycleStatus::Unresolved : CycleStatus::None;
  if (cycle.status == CycleStatus::None && all_rest) {
    cycle.rest_error = rest_error;
    reason << "every seed comes to rest ("
           << (model.effects().coulomb() || model.effects().stribeck() ? "the Coulomb dead band stops the motion; " : "") << "final error "
           << rest_error << ")";
  } else {
    if (cycle.status == CycleStatus::None) reason << "no stable cycle: ";
    for (std::size_t i = 0; i < outcomes.size(); ++i) reason << (i ? "; " : "") << outcomes[i];
  }
  if (cycle.status == CycleStatus::None && p.measured_at == model::MeasuredAt::Motor)
    reason << "; the backlash is outside the loop, so the system settles with a steady-state error";
  cycle.reason = reason.str();
}

// The slowest time scale of a compliant mesh (0 for a rigid one): the period 2π√(Jr/kc) of the two
// bodies swinging against the mesh (Jr = Jm·JL/(Jm + JL)), or its slow relaxation cc/kc when that is
// longer.  A return to the section can take this long, so the search's horizon covers it (a very
// soft mesh swings for thousands of seconds; the rigid model's scales would call that settling).
double slow_mesh_scale(const Parameters& p, const Effects& e) {
  if (!e.compliant()) return 0;
  const double Jr = p.Jm * p.JL / (p.Jm + p.JL);
  return std::max(2 * M_PI * std::sqrt(Jr / e.mesh_stiffness), e.mesh_damping / e.mesh_stiffness);
}

}  // namespace

LimitCycle find_limit_cycle(const ValidatedEffectModel& model, const EffectLimitCycleOptions& options) {
  const Parameters& p = model.parameters();
  const Effects& e = model.effects();
  if (!e.any() && !options.general) return find_limit_cycle(model.nominal());
  LimitCycle cycle;
  if (p.backlash <= 0) {
    cycle.reason = "no backlash";
    return cycle;
  }
  // 60 slowest time scales, the mesh's included (as limit_cycle.cpp); when double precision cannot
  // time that far, the rigid model's, and a return not seen within them is unresolved, not settling.
  double horizon = options.horizon > 0 ? options.horizon : 60 * std::max(slowest_time_scale(p), slow_mesh_scale(p, e));
  std::string silent = "no recombination within the horizon";
  if (options.horizon <= 0 && time_resolution_problem(p, e, horizon)) {
    horizon = 60 * slowest_time_scale(p);
    char why[200];
    std::snprintf(why, sizeof why, " of %.6g s, where the mesh's own slowest time scale is %.6g s (beyond what "
                  "double precision times)", horizon, slow_mesh_scale(p, e));
    silent += why;
  }
  const Section section(model, horizon, silent);
  const double velocity_scale = std::max(1.0, std::fabs(p.theta_R)) * std::sqrt(p.K / (p.Jm + p.JL));
  std::vector<Iteration> ends;
  for (const HybridState& seed : seeds(model, options)) {
    const Iteration it = search_from(model, section, seed, options, horizon, velocity_scale, cycle);
    if (it.converged()) {
      cycle.iterations = it.cycles;
      cycle.residual = it.residual;
      cycle.period_count = it.period_count;
      if (const std::optional<std::string> problem = inconsistency(p, cycle)) {
        LimitCycle unresolved;
        unresolved.status = CycleStatus::Unresolved;
        unresolved.reason = *problem;
        return unresolved;
      }
      cycle.status = CycleStatus::LimitCycle;
      cycle.stable = std::fabs(cycle.multiplier) < 1;
      cycle.half_map_derivative = NAN;
      return cycle;
    }
    ends.push_back(it);
    // An unresolved seed costs up to max_period × max_cycles returns: the answer is unresolved.
    if (it.verdict == Verdict::Unresolved && it.cycles > 0) break;
  }
  without_cycle(model, ends, cycle);
  return cycle;
}

}  // namespace backlash::numeric
