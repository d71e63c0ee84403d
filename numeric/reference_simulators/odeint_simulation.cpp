// The independent hybrid simulator on Boost.Odeint (see odeint_simulation.hpp).
// The only translation unit of the simulator that includes odeint (slow to compile).
#include "backlash/numeric/odeint_simulation.hpp"

#include "backlash/numeric/scales.hpp"

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <exception>
#include <limits>
#include <optional>
#include <utility>

namespace backlash::numeric {

namespace odeint = boost::numeric::odeint;

namespace {

using FreeVector = std::array<double, 4>;     // p = θm − θm0, θ̇m, S·Δ, S·Δ̇ (Δ = gap change since the start)
using ContactVector = std::array<double, 2>;  // e = θo − θR, θ̇o

// The mode ODEs, written out here from docs/physics.md (independently of segment_dynamics).
//
// Free mode in start-relative coordinates: the motor's displacement p = θm − θm0 and the gap
// change Δ = (θL − θm) − (θL0 − θm0), scaled by S.  The gap is then integrated directly (no
// cancellation θL − θm) and its error is controlled at tolerance/S absolute: a gap that
// leaves a face by 1e-13 and comes back (a bounce whose torque barely fails to hold) is
// resolved, where integrating θm and θL separately at 1e-12 could not tell it from noise.
//   θ̈m = (K(θR − θo) − Fm θ̇m)/Jm   (eq. 16, θo = θm; eq. 39, θo = θL)
//   θ̈L = −FL θ̇L / JL                (eq. 17)
struct FreeSystem {
  Parameters p;
  double e0;     ///< θo0 − θR at the start
  double scale;  ///< S
  bool at_motor;
  double motor_acceleration(const FreeVector& y) const {
    const double e = at_motor ? e0 + y[0] : e0 + y[0] + y[2] / scale;  // θo − θR
    return (-p.K * e - p.Fm * y[1]) / p.Jm;
  }
  void operator()(const FreeVector& y, FreeVector& dy, double /*t*/) const {
    const double am = motor_acceleration(y);
    const double aL = -p.FL * (y[1] + y[3] / scale) / p.JL;
    dy[0] = y[1];
    dy[1] = am;
    dy[2] = y[3];
    dy[3] = scale * (aL - am);
  }
  /// The gap's second and third derivatives at a state: how it leaves the face.
  std::pair<double, double> gap_departure(const FreeVector& y) const {
    const double am = motor_acceleration(y), vL = y[1] + y[3] / scale, aL = -p.FL * vL / p.JL;
    const double eo_rate = at_motor ? y[1] : vL;
    const double jm = (-p.K * eo_rate - p.Fm * am) / p.Jm;
    const double jL = -p.FL * aL / p.JL;
    return {aL - am, jL - jm};
  }
};

// Contact mode in the deviation e = θo − θR: then Tc is free of the cancellation θR − θo
// and keeps its relative accuracy as the motion decays (its sign near equilibrium is not
// rounding noise).
struct ContactSystem {
  Parameters p;
  void operator()(const ContactVector& y, ContactVector& dy, double /*t*/) const {
    dy[0] = y[1];
    dy[1] = (-p.K * y[0] - (p.Fm + p.FL) * y[1]) / (p.Jm + p.JL);  // eq. 25
  }
};

// Tc = JL·θ̈o + FL·θ̇o in contact, from the deviation e = θo − θR.
double contact_torque_deviation(const Parameters& p, double e, double omega) {
  const double acceleration = (-p.K * e - (p.Fm + p.FL) * omega) / (p.Jm + p.JL);
  return p.JL * acceleration + p.FL * omega;
}
// Tc from θo (the impact's holding test, as the closed-form simulator writes it).
double contact_torque(const Parameters& p, double theta_o, double omega) {
  const double acceleration = (p.K * (p.theta_R - theta_o) - (p.Fm + p.FL) * omega) / (p.Jm + p.JL);
  return p.JL * acceleration + p.FL * omega;
}
// dTc/dt in contact.
double contact_torque_rate(const Parameters& p, double e, double omega) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const double acceleration = (-p.K * e - F * omega) / J;
  const double jerk = (-p.K * omega - F * acceleration) / J;
  return p.JL * jerk + p.FL * acceleration;
}

// The rule both simulators share (hybrid_simulation.cpp): a zero of Tc where the contact
// motion has decayed to rounding level, |θo − θR| ≤ ν and |θ̇o| ≤ ν·√(K/J) with
// ν = 1024 ε·max(1, |θR|), is not a separation (the closed form cannot resolve the sign of
// Tc there: θR − θo cancels).  Contact then holds to t_end.
bool at_rounding_level(const Parameters& p, const std::array<double, 2>& deviation) {
  const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(p.theta_R));
  const double rate = std::sqrt(p.K / (p.Jm + p.JL));
  return std::fabs(deviation[0]) <= noise && std::fabs(deviation[1]) <= noise * rate;
}

HybridState contact_on_face(const Parameters& p, int face, double theta_o, double velocity) {
  HybridState s;
  s.in_contact = true;
  s.face = face;
  s.dtheta_m = s.dtheta_L = velocity;
  const double x = face * p.backlash / 2;  // θL − θm
  if (p.measured_at == model::MeasuredAt::Motor) {
    s.theta_m = theta_o;
    s.theta_L = theta_o + x;
  } else {
    s.theta_L = theta_o;
    s.theta_m = theta_o - x;
  }
  return s;
}

// The free state from the start-relative coordinates.
struct FreeFrame {
  double theta_m0, theta_L0, scale;
  int face;
  HybridState at(const FreeVector& y) const {
    HybridState h;
    h.in_contact = false;
    h.face = face;
    h.theta_m = theta_m0 + y[0];
    h.dtheta_m = y[1];
    h.theta_L = theta_L0 + y[0] + y[2] / scale;
    h.dtheta_L = y[1] + y[3] / scale;
    return h;
  }
};

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}

template <class V>
bool finite(const V& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

struct NonFiniteState {};

// Root of f on [a, b] (f(a), f(b) of opposite signs or one zero) with toms748.
template <class F>
double refine_root(F f, double a, double b, double fa, double fb) {
  if (fa == 0) return a;
  if (fb == 0) return b;
  std::uintmax_t iterations = 200;
  const auto bracket =
      boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(52), iterations);
  return 0.5 * (bracket.first + bracket.second);
}

// One segment integrated with dopri5 + dense output from τ = 0 over [0, horizon].
// `visit(t_old, t_new, stepper)` is called for each accepted step (t_new clamped to
// the horizon) and returns true to stop.
template <class Vector, class System, class Visit>
void march(const System& system, const Vector& x0, double horizon, double dt_max, double tolerance, Visit visit,
           double first_step = 0) {
  auto stepper = odeint::make_dense_output(tolerance, tolerance, dt_max, odeint::runge_kutta_dopri5<Vector>());
  double dt0 = std::min(dt_max, horizon) * 0.05;
  if (first_step > 0) dt0 = std::min(dt0, first_step);
  stepper.initialize(x0, 0.0, dt0);
  double t_old = 0;
  while (t_old < horizon) {
    const auto step = stepper.do_step(system);
    if (!finite(stepper.current_state()) || !std::isfinite(step.second)) throw NonFiniteState{};
    const double t_new = std::min(step.second, horizon);
    if (visit(t_old, t_new, stepper)) return;
    t_old = t_new;
  }
}

// Interior sample times of a step: t_old + (t_new − t_old)·k/n, k = 1..n (the last is t_new).
inline double sample_time(double t_old, double t_new, int k, int n) {
  return k == n ? t_new : t_old + (t_new - t_old) * k / n;
}


// The contact segment's witness on face σ in the deviation y = (θo − θR, θ̇o): h = −σ·Tc (> 0
// while contact holds), and the state.
struct ContactWitness {
  const Parameters& p;
  int face;
  double hold(const ContactVector& y) const { return -face * contact_torque_deviation(p, y[0], y[1]); }
  HybridState at(const ContactVector& y) const { return contact_on_face(p, face, p.theta_R + y[0], y[1]); }
};

// What a contact segment's witness samples have seen: the last h and θ̇o, whether the witness
// is armed, whether the motion has converged to rounding level, and the separation found.
struct ContactScan {
  double h_prev, v_prev;
  bool armed, converged;
  std::optional<double> separation;
};

// The free flight's witnesses in the start-relative coordinates: the opposite face reached
// (recombination, ≥ 0 inside), the face left reached again (recontact, ≤ 0 inside), and the
// speed above rest_velocity.
struct FreeWitnesses {
  int face;
  double S, offset, backlash, rest_velocity;
  double recombination(const FreeVector& y) const { return face * y[2] / S + offset + backlash; }
  double recontact(const FreeVector& y) const { return face * y[2] / S + offset; }
  double speed(const FreeVector& y) const {
    return std::max(std::fabs(y[1]), std::fabs(y[1] + y[3] / S)) - rest_velocity;
  }
};

// What a free flight's witness samples have seen: the last sample's witnesses and velocities,
// whether recontact is armed, the event found and the rest time.
struct FreeScan {
  double r_prev, c_prev, v_prev, vm_prev, vL_prev;
  bool armed = false;
  std::optional<double> event_tau;
  bool opposite = false;
  double rest_tau = 0;
};

}  // namespace

double fastest_rate(const Parameters& p) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  // |roots of s² + a s + k| ≤ a + √k; the load's pole is FL/JL.
  double rate = std::max({F / J + std::sqrt(p.K / J), p.Fm / p.Jm + std::sqrt(p.K / p.Jm), p.FL / p.JL});
  return rate > 0 ? rate : 1.0;
}

namespace {

// One run of the odeint hybrid simulator from a start state: contact segments integrated in
// (θo − θR, θ̇o) up to the first zero of −σ·Tc, free flights in (θm − θm0, θ̇m, S·Δ, S·Δ̇) up to
// the first face reached, joined by the impact law (eq. 24).  Witnesses are sampled at most
// `spacing` apart on the dense output and their zeros refined with toms748.
class OdeintRun {
 public:
  OdeintRun(const Parameters& p, const HybridState& start, const SimulationOptions& options,
            const OdeintSimulationOptions& oo)
      : p_(p),
        o_(options),
        oo_(oo),
        recorder_(p, options, result_),
        contact_system_{p},
        dt_max_(oo.max_step_fraction / fastest_rate(p)),
        // Witness samples: at most dt_max / (interior_checks + 1) apart on every step (a step of
        // dt_max gets interior_checks interior samples plus its end; shorter steps fewer).
        spacing_(dt_max_ / std::max(1, oo.interior_checks + 1)),
        at_motor_(p.measured_at == model::MeasuredAt::Motor),
        rigid_(p.backlash <= 0),  // b = 0: a rigid drive, contact for ever (docs/physics.md)
        state_(rigid_ ? rigid_start(p, start) : start) {}

  SimulationResult run() {
    try {
      while (t_ < o_.t_end) {
        if (!finite(state_)) return stop(SimulationStatus::NonFinite, "the state is no longer finite");
        if (static_cast<long>(result_.events.size()) >= o_.max_events)
          return stop(SimulationStatus::EventLimit, event_limit_reason(o_));
        if (auto problem = resolution_problem(p_, motion_scale(p_, state_.theta_m, state_.theta_L), "the motion"))
          return stop(SimulationStatus::Unresolved, *problem);
        const std::optional<SimulationStatus> end = state_.in_contact ? contact() : flight();
        if (end) return finish(*end);
      }
    } catch (const NonFiniteState&) {
      return stop(SimulationStatus::NonFinite, "the integration produced a non-finite state");
    } catch (const odeint::step_adjustment_error&) {
      return stop(SimulationStatus::NonFinite, "odeint could not adjust its step");
    } catch (const odeint::no_progress_error&) {
      return stop(SimulationStatus::NonFinite, "odeint made no progress");
    }
    return finish(SimulationStatus::Completed);
  }

 private:
  SimulationResult finish(SimulationStatus status) {
    result_.status = status;
    result_.t_final = t_;
    result_.final_state = state_;
    result_.theta_o_final = measured(p_, state_);
    return result_;
  }
  SimulationResult stop(SimulationStatus status, std::string reason) {
    result_.stop_reason = std::move(reason);
    return finish(status);
  }
  void push_event(EventKind kind, bool bounce) {
    SimulationEvent e;
    e.t = t_;
    e.kind = kind;
    e.theta_o = measured(p_, state_);
    e.dtheta_o = at_motor_ ? state_.dtheta_m : state_.dtheta_L;
    e.after = state_;
    e.bounce = bounce;
    result_.events.push_back(e);
  }
  void include(const HybridState& h) {
    if (!o_.track_extremes) return;
    include_extremes(p_, h, result_.extremes);
  }
  // Extremes inside a step: the zeros of a velocity between two samples, located on the interpolant.
  template <class VelocityAt>
  std::optional<double> velocity_zero(double a, double b, double va, double vb, VelocityAt velocity_at) const {
    if (!o_.track_extremes || !((va < 0 && vb >= 0) || (va > 0 && vb <= 0))) return std::nullopt;
    return refine_root(velocity_at, a, b, va, vb);
  }
  int samples_in(double ta, double tb) const {
    return std::max(1, static_cast<int>(std::ceil((tb - ta) / spacing_ * (1 - 1e-12))));
  }

  std::optional<SimulationStatus> contact();
  std::optional<SimulationStatus> flight();
  std::optional<SimulationStatus> impact(const HybridState& before, int face_hit, bool opposite);
  SimulationStatus flight_to_end(const FreeFrame& frame, const FreeWitnesses& w, double rest_tau, const FreeVector& y_rest,
                                 const FreeVector& y_end, double remaining);
  template <class AtTau>
  bool contact_sample(const ContactWitness& w, ContactScan& scan, double s_prev, double s, AtTau at_tau,
                      ContactVector& y_end);
  template <class AtTau>
  bool free_sample(const FreeWitnesses& w, const FreeFrame& frame, FreeScan& scan, double s_prev, double s, AtTau at_tau,
                   FreeVector& y_event, FreeVector& y_rest);

  const Parameters& p_;
  const SimulationOptions& o_;
  const OdeintSimulationOptions& oo_;
  SimulationResult result_;
  TrajectoryRecorder recorder_;
  const ContactSystem contact_system_;
  const double dt_max_, spacing_;
  const bool at_motor_, rigid_;
  HybridState state_;
  double t_ = 0;
  long separations_ = 0;
  std::deque<double> impacts_;
};

// ---- contact on face σ: integrate (θo − θR, θ̇o); separation at the first zero of h = −σ·Tc.
std::optional<SimulationStatus> OdeintRun::contact() {
  const Parameters& p = p_;
  const double remaining = o_.t_end - t_;
  const double t0 = t_;
  const int face = state_.face;
  const ContactVector y0{measured(p, state_) - p.theta_R, state_.dtheta_m};
  const ContactWitness w{p, face};
  include(w.at(y0));
  ContactScan scan{w.hold(y0), y0[1], !rigid_, rigid_, std::nullopt};
  // Starting on the separation line (Tc ≈ 0): Tc leaving toward its non-holding sign
  // separates at once; otherwise the witness is armed once it has the holding sign.
  if (!rigid_ && std::fabs(scan.h_prev) <= 1e-13 * std::max(1.0, std::fabs(y0[1]))) {
    if (-face * contact_torque_rate(p, y0[0], y0[1]) < 0) scan.separation = 0.0;
    scan.armed = false;
  }
  ContactVector y_end = y0;
  if (!scan.separation) {
    march(contact_system_, y0, remaining, dt_max_, oo_.tolerance, [&](double ta, double tb, auto& stepper) {
      auto at_tau = [&](double tau) {
        ContactVector z;
        stepper.calc_state(tau, z);
        return z;
      };
      auto samples_upto = [&](double upto) {
        recorder_.record(t0, upto, [&](double tau) { return w.at(at_tau(tau)); });
      };
      double s_prev = ta;
      const int n = samples_in(ta, tb);
      for (int k = 1; k <= n; ++k) {
        const double s = sample_time(ta, tb, k, n);
        if (contact_sample(w, scan, s_prev, s, at_tau, y_end)) {
          samples_upto(t0 + *scan.separation + 1e-12);
          return true;
        }
        s_prev = s;
      }
      const bool last = tb >= remaining;
      samples_upto(t0 + tb + (last ? 1e-12 : 0.0));
      if (last) y_end = at_tau(remaining);
      return false;
    });
  }
  const std::optional<double> separation = scan.separation;
  auto at_vec = [&w](const ContactVector& y) { return w.at(y); };
  include(at_vec(y_end));
  if (!separation) {
    state_ = at_vec(y_end);
    t_ = o_.t_end;
    return SimulationStatus::Completed;
  }
  if (*separation == 0) recorder_.record(t0, t0 + 1e-12, [&](double) { return at_vec(y0); });
  t_ += *separation;
  state_ = at_vec(y_end);
  state_.in_contact = false;  // face σ is now the face just left
  push_event(EventKind::Separation, false);
  if (o_.stop_after_separations > 0 && ++separations_ >= o_.stop_after_separations) return SimulationStatus::Completed;
  return std::nullopt;
}

// One witness sample of a contact segment at s (after s_prev): the separation, the first zero
// of −σ·Tc (true, scan.separation and y_end set) unless the motion there is at rounding level
// (then contact holds to t_end), else the extremes bookkept and the witness armed.
template <class AtTau>
bool OdeintRun::contact_sample(const ContactWitness& w, ContactScan& scan, double s_prev, double s, AtTau at_tau,
                               ContactVector& y_end) {
  const ContactVector y = at_tau(s);
  const double h = w.hold(y);
  std::optional<double> sep;
  if (scan.armed && scan.h_prev > 0 && h <= 0) {
    sep = refine_root([&](double tau) { return w.hold(at_tau(tau)); }, s_prev, s, scan.h_prev, h);
    if (at_rounding_level(p_, at_tau(*sep))) {  // not a separation: contact holds to t_end
      sep.reset();
      scan.armed = false;
      scan.converged = true;
    }
  }
  const double until = sep ? *sep : s;
  const ContactVector y_until = sep ? at_tau(*sep) : y;
  if (auto z = velocity_zero(s_prev, until, scan.v_prev, y_until[1], [&](double tau) { return at_tau(tau)[1]; }))
    include(w.at(at_tau(*z)));
  if (sep) {
    scan.separation = sep;
    y_end = y_until;
    return true;
  }
  if (!scan.armed && !scan.converged && h > 0) scan.armed = true;
  scan.h_prev = h;
  scan.v_prev = y[1];
  return false;
}

// ---- free flight from the face σ left: integrate (θm − θm0, θ̇m, S·Δ, S·Δ̇).
std::optional<SimulationStatus> OdeintRun::flight() {
  const Parameters& p = p_;
  const double remaining = o_.t_end - t_;
  const double t0 = t_;
  const int face = state_.face;
  const double half = p.backlash / 2, S = oo_.gap_scale;
  const FreeSystem free_system{p, measured(p, state_) - p.theta_R, S, at_motor_};
  const FreeFrame frame{state_.theta_m, state_.theta_L, S, face};
  const FreeVector y0{0, state_.dtheta_m, 0, S * (state_.dtheta_L - state_.dtheta_m)};
  // Where the gap starts relative to the face σ b/2 (0 when on it, up to rounding).
  const double x0 = state_.theta_L - state_.theta_m;
  const double offset = std::fabs(face * x0 - half) <= 1e-12 * std::max(1.0, p.backlash) ? 0.0 : face * x0 - half;
  const FreeWitnesses w{face, S, offset, p.backlash, o_.rest_velocity};
  include(frame.at(y0));
  FreeScan scan{w.recombination(y0), w.recontact(y0), w.speed(y0), y0[1], frame.at(y0).dtheta_L, false, std::nullopt, false, 0};
  // Recontact is armed once the gap is strictly inside.  A gap that leaves the face with
  // Δ'' inward and Δ''' outward turns back after about 3|Δ''/Δ'''|: the first step is
  // kept below that so its samples see the excursion.
  scan.armed = scan.c_prev < 0;
  double first_step = 0;
  if (y0[3] == 0 && offset == 0) {
    const auto [second, third] = free_system.gap_departure(y0);
    if (face * second < 0 && face * third > 0) first_step = 0.5 * std::fabs(second / third);
  }
  FreeVector y_event = y0, y_end = y0, y_rest = y0;
  march(free_system, y0, remaining, dt_max_, oo_.tolerance, [&](double ta, double tb, auto& stepper) {
    auto at_tau = [&](double tau) {
      FreeVector z;
      stepper.calc_state(tau, z);
      return z;
    };
    auto samples_upto = [&](double upto) {
      recorder_.record(t0, upto, [&](double tau) { return frame.at(at_tau(tau)); });
    };
    double s_prev = ta;
    const int n = samples_in(ta, tb);
    for (int k = 1; k <= n; ++k) {
      const double s = sample_time(ta, tb, k, n);
      if (free_sample(w, frame, scan, s_prev, s, at_tau, y_event, y_rest)) {
        samples_upto(t0 + *scan.event_tau + 1e-12);
        return true;
      }
      s_prev = s;
    }
    const bool last = tb >= remaining;
    samples_upto(t0 + tb + (last ? 1e-12 : 0.0));
    if (last) y_end = at_tau(remaining);
    return false;
  }, first_step);
  include(frame.at(scan.event_tau ? y_event : y_end));
  if (!scan.event_tau) return flight_to_end(frame, w, scan.rest_tau, y_rest, y_end, remaining);
  t_ += *scan.event_tau;
  return impact(frame.at(y_event), scan.opposite ? -face : face, scan.opposite);
}

// A free flight without a gap event to t_end: at rest (the event at the last time a velocity fell
// below rest_velocity) when every velocity is below it at the end, else still moving.
SimulationStatus OdeintRun::flight_to_end(const FreeFrame& frame, const FreeWitnesses& w, double rest_tau,
                                          const FreeVector& y_rest, const FreeVector& y_end, double remaining) {
  const HybridState end = frame.at(y_end);
  if (w.speed(y_end) < 0) {
    const double t_end = t_ + remaining;
    t_ += rest_tau;
    state_ = frame.at(y_rest);
    push_event(EventKind::Rest, false);
    t_ = t_end;
    state_ = end;
    return SimulationStatus::Rest;
  }
  state_ = end;
  t_ = o_.t_end;
  return SimulationStatus::Completed;
}

// One witness sample of a free flight at s (after s_prev): the first face reached between them
// (true, scan.event_tau and y_event set), else the extremes and rest bookkeeping moved on.
template <class AtTau>
bool OdeintRun::free_sample(const FreeWitnesses& w, const FreeFrame& frame, FreeScan& scan, double s_prev, double s,
                            AtTau at_tau, FreeVector& y_event, FreeVector& y_rest) {
  const FreeVector y = at_tau(s);
  const double r = w.recombination(y), c = w.recontact(y), v = w.speed(y);
  std::optional<double> t_opposite, t_back;
  if (scan.r_prev > 0 && r <= 0)
    t_opposite = refine_root([&](double tau) { return w.recombination(at_tau(tau)); }, s_prev, s, scan.r_prev, r);
  // Recontact: the gap back on the face.  Unarmed and already outside means a return
  // the samples missed (or a gap leaving outward): the bodies meet again there.
  if (c >= 0 && (scan.armed ? scan.c_prev < 0 : c > 0))
    t_back = refine_root([&](double tau) { return w.recontact(at_tau(tau)); }, s_prev, s, std::min(scan.c_prev, 0.0), c);
  if (t_opposite || t_back) {
    scan.opposite = t_opposite && (!t_back || *t_opposite <= *t_back);
    scan.event_tau = scan.opposite ? *t_opposite : *t_back;
    y_event = at_tau(*scan.event_tau);
  }
  const double until = scan.event_tau ? *scan.event_tau : s;
  const HybridState h_until = frame.at(scan.event_tau ? y_event : y);
  if (auto z = velocity_zero(s_prev, until, scan.vm_prev, h_until.dtheta_m, [&](double tau) { return at_tau(tau)[1]; }))
    include(frame.at(at_tau(*z)));
  if (auto z = velocity_zero(s_prev, until, scan.vL_prev, h_until.dtheta_L,
                             [&](double tau) { return frame.at(at_tau(tau)).dtheta_L; }))
    include(frame.at(at_tau(*z)));
  if (scan.event_tau) return true;
  if (!scan.armed && c < 0) scan.armed = true;
  // Rest bookkeeping: the last time a velocity fell below rest_velocity.
  if (scan.v_prev >= 0 && v < 0) {
    scan.rest_tau = refine_root([&](double tau) { return w.speed(at_tau(tau)); }, s_prev, s, scan.v_prev, v);
    y_rest = at_tau(scan.rest_tau);
  }
  scan.r_prev = r;
  scan.c_prev = c;
  scan.v_prev = v;
  scan.vm_prev = h_until.dtheta_m;
  scan.vL_prev = h_until.dtheta_L;
  return false;
}

// Inelastic impact (eq. 24) on the face hit; a bounce when the torque does not hold there.
std::optional<SimulationStatus> OdeintRun::impact(const HybridState& before, int face_hit, bool opposite) {
  const double omega = (p_.Jm * before.dtheta_m + p_.JL * before.dtheta_L) / (p_.Jm + p_.JL);
  const double theta_o = measured(p_, before);
  state_ = contact_on_face(p_, face_hit, theta_o, omega);
  const double tc = contact_torque(p_, theta_o, omega);
  const bool holds = -face_hit * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
  if (!holds) state_.in_contact = false;  // a bounce: the bodies part again at once
  push_event(opposite ? EventKind::Recombination : EventKind::Recontact, !holds);
  impacts_.push_back(t_);
  const double window = zeno_window(p_, o_);
  while (!impacts_.empty() && impacts_.front() < t_ - window) impacts_.pop_front();
  if (static_cast<int>(impacts_.size()) >= o_.zeno_impacts) {
    result_.stop_reason = zeno_reason(o_, window);
    return SimulationStatus::Chattering;
  }
  return std::nullopt;
}

}  // namespace

SimulationResult simulate_with_odeint(const Parameters& p, const HybridState& start, const SimulationOptions& options,
                                      const OdeintSimulationOptions& oo) {
  return OdeintRun(p, start, options, oo).run();
}

SimulationResult simulate_step_with_odeint(const Parameters& p, double step, const SimulationOptions& options,
                                           const OdeintSimulationOptions& odeint_options) {
  return simulate_with_odeint(p, step_start(p, step), options, odeint_options);
}

}  // namespace backlash::numeric
