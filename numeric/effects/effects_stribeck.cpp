// Stribeck friction (docs/effects.md, "Stribeck friction"): a moving body's friction is
// s·(Tk + (Ts − Tk)·exp(−(v/vs)²)) on top of its Coulomb torque, nonlinear in its velocity, so a
// mode has no closed form at low speeds.  The engine (effects_engine.cpp) keeps its mode logic — static
// rules, impacts, restitution, transitions, rest — and runs with each body's Coulomb torque at
// its STATIC level T + Ts (exact wherever a body is at rest: sticking, break-away, the pair's
// band); a moving body's friction lies below that level by the drop
// (Ts − Tk)·(1 − exp(−(v/vs)²)) (numeric::stribeck_drop), which this file adds:
//   – each mode's motion is its linear system z' = A z + c (effect_modes.hpp, drive folded in,
//     at the static level) plus the drop on the slipping velocities, integrated from the mode's
//     start by runge_kutta_dopri5 with step control (absolute = relative error 1e-13 per
//     step, steps ≤ 0.1/(fastest rate)); the transmitted torque Tc of rigid contact gets the
//     drop as well (Engine::friction_drop);
//   – events: the engine's witnesses (mode_witnesses), sampled at six points inside each
//     accepted step on its cubic Hermite interpolant; a sign change found there is confirmed
//     and refined with Boost.Math's toms748 on exact values — one dopri5 step of the exact
//     length from the accepted step's start, as every state the engine reads (so the state
//     at an event carries the integrator's own error, one step's, not an interpolation's);
//   – a run tries at most kMaxSteps steps, then work_limit (exit 3);
//   – where every slipping Stribeck body's drop has saturated to Ts − Tk in double precision
//     (|v| ≥ √40·vs), and where no Stribeck body slips, the mode IS linear: the engine's
//     closed-form segment at the kinetic level (effects_simulation.cpp) with a Handover guard
//     per body at |v| = √40·vs, whose exit ends the segment (no event); the integration takes
//     over there, up to |v| = √50·vs (StribeckEngine::next_segment).
// The odeint simulator (odeint_effects_simulation.cpp) is an independent implementation.
#include "effects/effects_engine.hpp"

#include "backlash/numeric/scales.hpp"

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace backlash::numeric::detail {

namespace {

namespace odeint = boost::numeric::odeint;
using State = std::array<double, 4>;

constexpr double kTolerance = 1e-13;     // dopri5 absolute = relative error per step
constexpr int kSamplesPerStep = 6;       // witness samples inside each accepted step (its end included)
constexpr long kMaxSteps = 20'000'000;   // steps tried per run (some 30 s), then work_limit

// A run's work budget.
struct Budget {
  long steps = 0;
  void count(double t) {
    if (++steps <= kMaxSteps) return;
    char text[200];
    std::snprintf(text, sizeof text, "the Stribeck model used its budget of %ld integration steps by t = %.6g s",
                  kMaxSteps, t);
    throw SearchBudgetExhausted(text);
  }
};

double root_in(const std::function<double(double)>& f, double a, double b) {
  const double fa = f(a), fb = f(b);
  if (fa <= 0) return a;
  if (fb > 0) return b;  // rounding: the sample that crossed
  std::uintmax_t iterations = 100;
  const auto r = boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(50),
                                                   iterations);
  return 0.5 * (r.first + r.second);
}

// One mode's motion from the engine's state, with its first exit.
class StribeckSegment final : public Segment {
 public:
  StribeckSegment(const Parameters& p, const Effects& level, const Effects& e, const Mode& m, const HybridState& start,
                  double horizon, double t_global, Budget& budget, const std::vector<Witness>& handovers,
                  int left_zone)
      : p_(p), e_(e), flow_(p, level, m, start), n_(static_cast<int>(flow_.segment().A.rows())) {
    duration = horizon;
    if (m.kind == ModeKind::Contact ? m.slip_motor == 0 : (m.slip_motor == 0 && m.slip_load == 0)) {
      rest = true;  // everything stuck and no delay: the drive cannot change
      return;
    }
    ModeFunctionals f = functionals(level);
    f.left_zone = left_zone;
    witnesses_ = mode_witnesses(p, level, m, f, true);
    witnesses_.insert(witnesses_.end(), handovers.begin(), handovers.end());
    integrate(horizon, t_global, budget);
    if (exit) duration = exit->tau;
    if (exit && exit->witness.guard == Guard::Handover) exit.reset();  // the segment ends there, the mode goes on
  }

  HybridState state(double tau) const override { return flow_.state_of(local(z_at(tau))); }
  double measured_at(const Parameters&, double tau) const override { return flow_.measured_of(local(z_at(tau))); }

  void extremes(double until, Extremes& x) const override {
    include_extremes(p_, state(0), x);
    include_extremes(p_, state(until), x);
    const Mode& m = flow_.mode();
    std::vector<int> rows;
    if (m.slip_motor != 0) rows.push_back(1);
    if (m.kind != ModeKind::Contact && m.slip_load != 0) rows.push_back(3);
    for (const Step& step : steps_) {
      const double end = std::min(step.t1, until);
      if (!(end > step.t0)) break;
      for (int row : rows) {
        double a = step.t0, va = step.x0[row];
        for (int k = 1; k <= kSamplesPerStep; ++k) {
          const double b = step.t0 + (end - step.t0) * k / kSamplesPerStep, vb = hermite(step, b)[row];
          if ((va > 0 && vb <= 0) || (va < 0 && vb >= 0)) {
            const double sign = va > 0 ? 1 : -1;
            include_extremes(p_, state(root_in([&](double t) { return sign * advance(step, t)[row]; }, a, b)), x);
          }
          a = b;
          va = vb;
        }
      }
    }
  }

 private:
  struct Step {
    double t0, t1;
    State x0, x1, f0, f1;  // the states at the ends and their derivatives
  };
  enum class Arming { Armed, ExitNow, Departing, Waiting };

  ModeFunctionals functionals(const Effects& level) const {
    auto of = [](const ModeFlow::Functional& f) { return Functional{f.row, f.constant, f.magnitude, 0}; };
    ModeFunctionals f;
    f.theta_o_error = of(flow_.theta_o_error());
    f.gap = of(flow_.gap_functional());
    f.dimension = n_;
    const int regime = flow_.mode().regime;
    f.drive = regime == 0 ? f.theta_o_error.scaled(-p_.K).shifted(drive_constant(level, 0))
                          : Functional{SmallRow::Zero(n_), drive_constant(level, regime), drive_constant_bound(level), 0};
    return f;
  }

  SmallVector local(const State& x) const {
    SmallVector z(n_);
    for (int i = 0; i < n_; ++i) z(i) = x[i];
    return z;
  }

  // The drops' accelerations on the slipping velocities (their Jacobian's diagonal when `rate`).
  void add_drops(const State& x, State& dx, bool rate) const {
    const Mode& m = flow_.mode();
    auto drop = [&](bool motor, double v) { return rate ? stribeck_drop_rate(e_, motor, v) : stribeck_drop(e_, motor, v); };
    if (m.kind == ModeKind::Contact) {
      if (m.slip_motor != 0) dx[1] += m.slip_motor * (drop(true, x[1]) + drop(false, x[1])) / (p_.Jm + p_.JL);
      return;
    }
    if (m.slip_motor != 0) dx[1] += m.slip_motor * drop(true, x[1]) / p_.Jm;
    if (m.slip_load != 0) dx[3] += m.slip_load * drop(false, x[3]) / p_.JL;
  }

  void rhs(const State& x, State& dx) const {
    const LinearSegment& s = flow_.segment();
    dx = State{};
    for (int i = 0; i < n_; ++i) {
      double sum = s.c(i);
      for (int j = 0; j < n_; ++j) sum += s.A(i, j) * x[j];
      dx[i] = sum;
    }
    add_drops(x, dx, false);
  }

  // One dopri5 step of exactly t − step.t0 from the accepted step's start.
  State advance(const Step& step, double t) const {
    if (t == step.t1) return step.x1;
    State x = step.x0;
    if (t > step.t0) {
      odeint::runge_kutta_dopri5<State> single;
      single.do_step([this](const State& y, State& dy, double) { rhs(y, dy); }, x, step.t0, t - step.t0);
    }
    return x;
  }

  // The step's cubic Hermite interpolant (O(h⁴)): where the samples look for sign changes; every
  // crossing found is then refined on advance().
  State hermite(const Step& step, double t) const {
    const double h = step.t1 - step.t0, u = h > 0 ? (t - step.t0) / h : 0;
    const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u), h01 = u * u * (3 - 2 * u),
                 h11 = u * u * (u - 1);
    State x;
    for (int i = 0; i < 4; ++i) x[i] = h00 * step.x0[i] + h10 * h * step.f0[i] + h01 * step.x1[i] + h11 * h * step.f1[i];
    return x;
  }

  State z_at(double tau) const {
    if (steps_.empty() || tau <= steps_.front().t0) return start();
    auto it = std::upper_bound(steps_.begin(), steps_.end(), tau, [](double t, const Step& s) { return t < s.t1; });
    return advance(it == steps_.end() ? steps_.back() : *it, tau);
  }

  State start() const {
    State x{};
    for (int i = 0; i < n_; ++i) x[i] = flow_.local_start()(i);
    return x;
  }

  // Rigid contact's transmitted torque with the drops: Tc = Tc(level) + s·(JL/J·(dm + dL) − dL),
  // the witness −σ·Tc; its rate along the motion when `rate` (x the state, dx its derivative).
  double drop_term(const Witness& w, const State& x, const State& dx, bool rate) const {
    if (w.guard != Guard::ContactTorque) return 0;
    const Mode& m = flow_.mode();
    const double omega = x[1], J = p_.Jm + p_.JL;
    const double dm = rate ? stribeck_drop_rate(e_, true, omega) * dx[1] : stribeck_drop(e_, true, omega);
    const double dL = rate ? stribeck_drop_rate(e_, false, omega) * dx[1] : stribeck_drop(e_, false, omega);
    return -m.face * m.slip_motor * (p_.JL / J * (dm + dL) - dL);
  }

  double value(const Witness& w, const State& x) const {
    double sum = w.f.constant;
    for (int i = 0; i < n_; ++i) sum += w.f.row(i) * x[i];
    return sum + drop_term(w, x, x, false);
  }

  // As the delayed model's (effects_delay.cpp): armed inside, an exit at once outside, else by the
  // first derivative that is not rounding noise (departing: armed from its first positive sample).
  Arming arm(const Witness& w, double t_global, double& tolerance) const {
    const State x = start();
    State dx, ddx{}, jac_diag{};
    rhs(x, dx);
    add_drops(x, jac_diag, true);
    const SmallVector z = local(x), zdot = local(dx);
    const SmallVector zddot = flow_.segment().A * zdot;
    for (int i = 0; i < n_; ++i) ddx[i] = zddot(i) + jac_diag[i] * dx[i];
    const SmallVector& noise = flow_.local_start_noise();
    const double w0 = value(w, x), w1 = w.f.row.dot(zdot) + drop_term(w, x, dx, true);
    constexpr double eps = std::numeric_limits<double>::epsilon();
    tolerance = 64 * eps * (w.f.row.cwiseAbs().dot(z.cwiseAbs().transpose()) + w.f.magnitude) +
                32 * w.f.row.cwiseAbs().dot(noise.transpose()) + std::fabs(w1) * 4e-14 * std::max(1.0, t_global);
    if (w0 > tolerance) return Arming::Armed;
    if (w0 < -tolerance) return Arming::ExitNow;
    const double s1 = w.f.row.cwiseAbs().dot(
        (flow_.segment().A.cwiseAbs() * (z.cwiseAbs() + noise) + flow_.forcing_magnitude()).transpose());
    if (std::fabs(w1) > 1e-9 * s1) return w1 < 0 ? Arming::ExitNow : Arming::Departing;
    double w2 = 0;
    for (int i = 0; i < n_; ++i) w2 += w.f.row(i) * ddx[i];
    if (w2 < 0 && std::fabs(w2) > 1e-9 * s1) return Arming::ExitNow;
    return Arming::Waiting;
  }

  // A departing witness that curves back (w' > 0 > w'') returns after about 2w'/|w''|: the first
  // step is kept well below that, so that its samples see the flight.
  double first_step(double dt_max) const {
    double dt = std::min(dt_max, std::max(1e-6, 1e-3 * dt_max));
    const State x = start();
    State dx, jac_diag{};
    rhs(x, dx);
    add_drops(x, jac_diag, true);
    const SmallVector zddot = flow_.segment().A * local(dx);
    for (const Witness& w : witnesses_) {
      double w1 = 0, w2 = 0;
      for (int i = 0; i < n_; ++i) w1 += w.f.row(i) * dx[i], w2 += w.f.row(i) * (zddot(i) + jac_diag[i] * dx[i]);
      if (std::fabs(value(w, x)) < 1e-12 * (1 + w.f.magnitude) && w1 > 0 && w2 < 0) dt = std::min(dt, 0.25 * w1 / -w2);
    }
    return dt;
  }

  void integrate(double horizon, double t_global, Budget& budget) {
    std::vector<Arming> arming(witnesses_.size());
    std::vector<double> tolerances(witnesses_.size());
    for (std::size_t i = 0; i < witnesses_.size(); ++i) {
      arming[i] = arm(witnesses_[i], t_global, tolerances[i]);
      if (arming[i] == Arming::ExitNow) {
        exit = Exit{0, witnesses_[i], false};
        return;
      }
    }
    const double dt_max = 0.1 / fastest_mode_rate(p_, e_);
    auto stepper = odeint::make_controlled(kTolerance, kTolerance, odeint::runge_kutta_dopri5<State>());
    auto system = [this](const State& y, State& dy, double) { rhs(y, dy); };
    State x = start();
    double tau = 0, dt = first_step(dt_max);
    while (tau < horizon) {
      const double ta = tau;
      const State xa = x;
      double trial = std::min({dt, dt_max, horizon - tau});
      if (horizon - tau - trial < 1e-12 * std::max(1.0, horizon)) trial = horizon - tau;
      budget.count(t_global + tau);  // tries and accepted steps alike: never a hang
      if (stepper.try_step(system, x, tau, trial) != odeint::success) {
        dt = trial;
        continue;
      }
      dt = trial;  // the stepper proposes the next step in `trial`
      if (horizon - tau < 1e-12 * std::max(1.0, horizon)) tau = horizon;
      Step step{ta, tau, xa, x, {}, {}};
      rhs(xa, step.f0);
      rhs(x, step.f1);
      steps_.push_back(step);
      if (scan(arming, tolerances)) return;
    }
  }

  // Witness exits inside the last accepted step: true (and `exit`, the step cut there) if one.
  bool scan(std::vector<Arming>& arming, const std::vector<double>& tolerances) {
    Step& step = steps_.back();
    std::vector<double> wa(witnesses_.size());
    for (std::size_t i = 0; i < witnesses_.size(); ++i) wa[i] = value(witnesses_[i], step.x0);
    double a = step.t0;
    for (int k = 1; k <= kSamplesPerStep; ++k) {
      const double b = k == kSamplesPerStep ? step.t1 : step.t0 + (step.t1 - step.t0) * k / kSamplesPerStep;
      const State xb = hermite(step, b);
      for (std::size_t i = 0; i < witnesses_.size(); ++i) {
        const Witness& w = witnesses_[i];
        const double wb = value(w, xb);
        if (arming[i] == Arming::Armed && wa[i] >= 0 && wb < 0 && value(w, advance(step, b)) < 0) {
          const double t = root_in([&](double s) { return value(w, advance(step, s)); }, a, b);
          if (!exit || t < exit->tau) exit = Exit{t, w, false};
        }
        if ((arming[i] == Arming::Waiting && wb > tolerances[i]) || (arming[i] == Arming::Departing && wb > 0))
          arming[i] = Arming::Armed;
        wa[i] = wb;
      }
      if (exit) {
        step.x1 = advance(step, exit->tau);
        step.t1 = exit->tau;
        return true;
      }
      a = b;
    }
    return false;
  }

  const Parameters& p_;
  const Effects& e_;
  ModeFlow flow_;
  int n_;
  std::vector<Witness> witnesses_;
  std::vector<Step> steps_;
};

// Where the drop saturates (docs/effects.md, "Stribeck friction"): for |v| ≥ kSaturated·vs,
// e^{−(v/vs)²} ≤ e^{−40} < 2^{−54}, so expm1 rounds to −1 and stribeck_drop is exactly Ts − Tk: the
// integrated right-hand side IS the linear mode at the kinetic level T + Tk, which has a closed
// form.  A segment hands over to the closed form when every slipping Stribeck body's speed is
// ≥ kChoose·vs (the integration ends at kEnter·vs), and back when one falls to kSaturated·vs.
const double kSaturated = std::sqrt(40.0), kChoose = std::sqrt(45.0), kEnter = std::sqrt(50.0);

// A slipping body whose friction has a Stribeck drop: its velocity's coordinate and slip sign in
// the mode, and its Stribeck velocity (rigid contact: the larger of the two bodies').
struct SlippingCurve {
  int index = 1, sign = 0;
  double vs = 0;
};

std::vector<SlippingCurve> slipping_curves(const Effects& e, const Mode& m) {
  auto vs_of = [&e](bool motor) {
    const double drop = motor ? e.stribeck_motor_static - e.stribeck_motor_kinetic
                              : e.stribeck_load_static - e.stribeck_load_kinetic;
    return drop > 0 ? (motor ? e.stribeck_motor_velocity : e.stribeck_load_velocity) : 0.0;
  };
  std::vector<SlippingCurve> out;
  if (m.kind == ModeKind::Contact) {
    const double vs = std::max(vs_of(true), vs_of(false));
    if (m.slip_motor != 0 && vs > 0) out.push_back({1, m.slip_motor, vs});
    return out;
  }
  if (m.slip_motor != 0 && vs_of(true) > 0) out.push_back({1, m.slip_motor, vs_of(true)});
  if (m.slip_load != 0 && vs_of(false) > 0) out.push_back({3, m.slip_load, vs_of(false)});
  return out;
}

// The handover guard sign·(sign·v − k·vs) ≥ 0 in the mode's local coordinates (v = z[index]).
Witness handover(const Mode& m, const SlippingCurve& c, double k, int sign) {
  Functional f{SmallRow::Zero(m.kind == ModeKind::Contact ? 2 : 4), -sign * k * c.vs, k * c.vs, 0};
  f.row(c.index) = sign * c.sign;
  return Witness{Guard::Handover, 0, f};
}

// The engine at the static levels, the drops added by its segments; where every slipping body's
// drop has saturated, the mode's closed form at the kinetic levels (effects_simulation.cpp).
class StribeckEngine final : public Engine {
 public:
  StribeckEngine(const Parameters& p, const Effects& level, const Effects& e, const SimulationOptions& options,
                 const EffectsEngineOptions& engine)
      : Engine(p, level, options, engine), stribeck_(e) {}

 protected:
  double drive_now() const override {
    return drive_torque_in_regime(p_, e_, measured(p_, state_), state_.drive_regime);
  }
  std::unique_ptr<Segment> next_segment(const Mode& mode, double remaining) override {
    const std::vector<SlippingCurve> curves = slipping_curves(stribeck_, mode);
    std::vector<Witness> floors, ceilings;
    for (const SlippingCurve& c : curves) {
      const double speed = c.sign * (c.index == 1 ? state_.dtheta_m : state_.dtheta_L);
      if (speed >= kChoose * c.vs)
        floors.push_back(handover(mode, c, kSaturated, 1));
      else
        ceilings.push_back(handover(mode, c, kEnter, -1));
    }
    if (ceilings.empty()) {  // no drop left to integrate (none slipping: the closed form throughout)
      auto closed = closed_form_segment(p_, kinetic_level(mode), mode, state_, remaining, t_, left_zone(), floors);
      if (closed->exit || closed->rest || closed->duration > 0) return closed;
    }
    auto integrated = std::make_unique<StribeckSegment>(p_, e_, stribeck_, mode, state_, remaining, t_, budget_, ceilings,
                                                         left_zone());
    if (integrated->exit || integrated->rest || integrated->duration > 0 || ceilings.empty()) return integrated;
    // A handover at once (rounding at a tiny vs): integrate without it, never an empty segment again.
    return std::make_unique<StribeckSegment>(p_, e_, stribeck_, mode, state_, remaining, t_, budget_,
                                             std::vector<Witness>{}, left_zone());
  }
  double friction_drop(bool motor, double velocity) const override { return stribeck_drop(stribeck_, motor, velocity); }

 private:
  // The static levels with each slipping Stribeck body's Coulomb torque at its kinetic level T + Tk.
  Effects kinetic_level(const Mode& m) const {
    Effects level = e_;
    const bool motor_slips = m.slip_motor != 0, load_slips = m.kind == ModeKind::Contact ? motor_slips : m.slip_load != 0;
    if (motor_slips && stribeck_.stribeck_motor_static > stribeck_.stribeck_motor_kinetic)
      level.coulomb_motor = stribeck_.coulomb_motor + stribeck_.stribeck_motor_kinetic;
    if (load_slips && stribeck_.stribeck_load_static > stribeck_.stribeck_load_kinetic)
      level.coulomb_load = stribeck_.coulomb_load + stribeck_.stribeck_load_kinetic;
    return level;
  }

  const Effects& stribeck_;
  Budget budget_;
};

}  // namespace

SimulationResult simulate_stribeck(const Parameters& p, const Effects& e, const HybridState& start,
                                   const SimulationOptions& options, const EffectsEngineOptions& engine) {
  Effects level = e;  // each body's Coulomb torque at its static level: the engine's static rules read it
  level.coulomb_motor = static_friction(e, true);
  level.coulomb_load = static_friction(e, false);
  return StribeckEngine(p, level, e, options, engine).run(start);
}

}  // namespace backlash::numeric::detail
