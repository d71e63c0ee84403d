#include "backlash/numeric/hybrid_simulation.hpp"

#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/linear_flight.hpp"
#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/segment_dynamics.hpp"
#include "gap_events.hpp"

#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>

namespace backlash::numeric {

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::Separation: return "separation";
    case EventKind::Recombination: return "recombination";
    case EventKind::Recontact: return "recontact";
    case EventKind::Rest: return "rest";
    case EventKind::Stick: return "stick";
    case EventKind::Slip: return "slip";
    case EventKind::Saturation: return "saturation";
    case EventKind::Desaturation: return "desaturation";
  }
  return "?";
}

const char* to_string(Body body) {
  switch (body) {
    case Body::None: return "none";
    case Body::Motor: return "motor";
    case Body::Load: return "load";
    case Body::Both: return "both";
  }
  return "?";
}

const char* to_string(SimulationStatus status) {
  switch (status) {
    case SimulationStatus::Completed: return "completed";
    case SimulationStatus::Rest: return "rest";
    case SimulationStatus::Chattering: return "chattering";
    case SimulationStatus::EventLimit: return "event_limit";
    case SimulationStatus::NonFinite: return "non_finite";
    case SimulationStatus::Unresolved: return "unresolved";
    case SimulationStatus::WorkLimit: return "work_limit";
  }
  return "?";
}

bool stopped_early(SimulationStatus status) {
  return status != SimulationStatus::Completed && status != SimulationStatus::Rest;
}

double measured(const Parameters& p, const HybridState& s) {
  return p.measured_at == model::MeasuredAt::Motor ? s.theta_m : s.theta_L;
}

double measured_velocity(const Parameters& p, const HybridState& s) {
  return p.measured_at == model::MeasuredAt::Motor ? s.dtheta_m : s.dtheta_L;
}

namespace {

HybridState contact_state_on_face(const Parameters& p, int face, double theta_o, double velocity) {
  return state_on_face(p, face, theta_o, velocity, true);
}

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}

// A free flight in the simulation frame: state(τ) and the gap change since its start.
struct Flight {
  std::function<HybridState(double)> at;
  std::function<SmallVector(double)> vector;
  std::function<double(double)> gap_change;
};

Flight flight_from_separation_line(const ValidatedEvaluator& evaluator, const HybridState& start) {
  const Parameters& p = evaluator.parameters();
  const double v = start.dtheta_m;
  const double theta0 = evaluator.evaluator().separation_theta(v);  // thesis frame: θm(0) = θL(0) = θ0
  const double offset_m = start.theta_m - theta0, offset_L = start.theta_L - theta0;
  (void)p;
  Flight f;
  f.at = [&evaluator, v, offset_m, offset_L, face = start.face](double tau) {
    const FreeState s = evaluator.free_state(tau, v);
    HybridState h;
    h.in_contact = false;
    h.face = face;
    h.theta_m = s.theta_m + offset_m;
    h.theta_L = s.theta_L + offset_L;
    h.dtheta_m = s.dtheta_m;
    h.dtheta_L = s.dtheta_L;
    return h;
  };
  f.vector = [at = f.at](double tau) {
    const HybridState h = at(tau);
    SmallVector x(4);
    x << h.theta_m, h.dtheta_m, h.theta_L, h.dtheta_L;
    return x;
  };
  f.gap_change = [&evaluator, v](double tau) { return evaluator.free_state(tau, v).gap; };
  return f;
}

Flight flight_from_state(const Parameters& p, const HybridState& start) {
  SmallVector x0(4);
  x0 << start.theta_m, start.dtheta_m, start.theta_L, start.dtheta_L;
  auto flight = std::make_shared<LinearFlight>(free_mode_segment(p), x0);
  Flight f;
  f.vector = [flight](double tau) { return flight->state(tau); };
  f.at = [flight, face = start.face](double tau) {
    const SmallVector x = flight->state(tau);
    HybridState h;
    h.in_contact = false;
    h.face = face;
    h.theta_m = x(0);
    h.dtheta_m = x(1);
    h.theta_L = x(2);
    h.dtheta_L = x(3);
    return h;
  };
  f.gap_change = [flight](double tau) {
    const SmallVector dx = flight->change(tau);
    return dx(2) - dx(0);
  };
  return f;
}

bool on_separation_line(const ValidatedEvaluator& evaluator, double theta_o, double velocity) {
  const double line = evaluator.evaluator().separation_theta(velocity);
  return std::fabs(theta_o - line) <= 1e-9 * std::max({1.0, std::fabs(theta_o), std::fabs(velocity)});
}

void include_state(const Parameters& p, const HybridState& h, Extremes& x) {
  const double o = measured(p, h);
  x.theta_o_min = std::min(x.theta_o_min, o);
  x.theta_o_max = std::max(x.theta_o_max, o);
  x.theta_m_min = std::min(x.theta_m_min, h.theta_m);
  x.theta_m_max = std::max(x.theta_m_max, h.theta_m);
  x.theta_L_min = std::min(x.theta_L_min, h.theta_L);
  x.theta_L_max = std::max(x.theta_L_max, h.theta_L);
}

// Extremes of a segment on [0, duration]: its end states and the certified zeros of θ̇m and θ̇L
// (in contact both are θ̇o).  `vector(τ)` is the segment's state x, x' = A x + c.
void segment_extremes(const Parameters& p, const LinearSegment& segment, const std::function<SmallVector(double)>& vector,
                      const std::function<HybridState(double)>& at, double duration, bool contact, Extremes& x) {
  include_state(p, at(0), x);
  include_state(p, at(duration), x);
  const Eigen::Index n = segment.A.rows();
  std::vector<Eigen::Index> velocity_rows = contact ? std::vector<Eigen::Index>{1} : std::vector<Eigen::Index>{1, 3};
  for (Eigen::Index row : velocity_rows) {
    LinearWitness w;
    w.A = segment.A;
    w.c = segment.c;
    w.e = SmallRow::Zero(n);
    w.e(row) = 1;
    w.state = vector;
    double from = 0;
    for (int k = 0; k < 10000; ++k) {
      const auto zero = first_crossing(w, from, duration);
      if (!zero) break;
      include_state(p, at(zero->t), x);
      from = zero->t + 1e-12 * std::max(1.0, zero->t);
      if (from >= duration) break;
    }
  }
}


}  // namespace

HybridState state_on_face(const Parameters& p, int face, double theta_o, double velocity, bool in_contact) {
  HybridState s;
  s.in_contact = in_contact;
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

HybridState step_start(const Parameters& p, double step) {
  // θo = θR − A, at rest, on the face that drives toward θR: for A > 0 the motor pushes
  // forward (x = −b/2), for A < 0 backward (x = +b/2).
  return contact_state_on_face(p, step >= 0 ? -1 : +1, p.theta_R - step, 0);
}

HybridState rigid_start(const Parameters& p, const HybridState& start) {
  if (p.backlash > 0) return start;
  const double omega = start.dtheta_m == start.dtheta_L ? start.dtheta_m
                                                        : recombined_velocity(p, start.dtheta_m, start.dtheta_L);
  const int face = start.face == 0 ? -1 : start.face;
  return contact_state_on_face(p, face, measured(p, start), omega);
}

namespace {

SimulationResult simulate_as_given(const ValidatedEvaluator& evaluator, const HybridState& start,
                                   const SimulationOptions& options) {
  const Parameters& p = evaluator.parameters();
  SimulationResult result;
  TrajectoryRecorder recorder(p, options, result);
  const LinearSegment contact_segment = contact_mode_segment(p);
  const LinearSegment free_segment = free_mode_segment(p);
  const TransmittedTorque torque = transmitted_torque(p);
  const bool rigid = p.backlash <= 0;  // a rigid drive: contact for ever, no events
  HybridState state = rigid ? rigid_start(p, start) : start;
  double t = 0;
  std::deque<double> impacts;
  long separations = 0;
  auto finish = [&](SimulationStatus status) {
    result.status = status;
    result.t_final = t;
    result.final_state = state;
    result.theta_o_final = measured(p, state);
    return result;
  };
  auto push_event = [&](EventKind kind, bool bounce, bool grazing) {
    SimulationEvent e;
    e.t = t;
    e.kind = kind;
    e.theta_o = measured(p, state);
    e.dtheta_o = measured_velocity(p, state);
    e.after = state;
    e.bounce = bounce;
    e.grazing = grazing;
    result.events.push_back(e);
  };

  auto stop = [&](SimulationStatus status, std::string reason) {
    result.stop_reason = std::move(reason);
    return finish(status);
  };

  try {
  while (t < options.t_end) {
    if (!finite(state)) return stop(SimulationStatus::NonFinite, "the state is no longer finite");
    if (static_cast<long>(result.events.size()) >= options.max_events)
      return stop(SimulationStatus::EventLimit, "the event cap of " + std::to_string(options.max_events) + " events was reached");
    if (auto problem = resolution_problem(p, motion_scale(p, state.theta_m, state.theta_L), "the motion"))
      return stop(SimulationStatus::Unresolved, *problem);
    const double remaining = options.t_end - t;

    if (state.in_contact) {
      const double theta0 = measured(p, state), omega0 = state.dtheta_m;
      LinearWitness w;
      w.A = contact_segment.A;
      w.c = contact_segment.c;
      w.e = torque.r;
      w.level = 0;  // w = Tc, given directly by `value` below (eᵀx' and its bounds need no level)
      w.state = [&evaluator, theta0, omega0](double tau) {
        const ContactState c = evaluator.contact_state(tau, theta0, omega0);
        SmallVector y(2);
        y << c.theta_o, c.dtheta_o;
        return y;
      };
      // Tc = (JL K/J)(θR − θo) + (FL − JL F/J) θ̇o without the cancellation θR − θo: by
      // linearity θo − θR = (θo0 − θR)·a(τ) + θ̇o0·b(τ) with the unit responses a, b of the
      // validated closed form, so the rounding error scales with the motion, not with θR.
      // Far from a zero of Tc the cancellation is harmless, so the unit responses are only
      // evaluated where |Tc| is within a few thousand ulps of θR's scale.
      const double cancellation_scale = 4096 * std::numeric_limits<double>::epsilon() * std::fabs(torque.r(0)) *
                                        std::max(1.0, std::fabs(p.theta_R));
      w.value = [&evaluator, &p, &torque, theta0, omega0, cancellation_scale](double tau) {
        const ContactState c = evaluator.contact_state(tau, theta0, omega0);
        const double direct = torque.r(0) * (c.theta_o - p.theta_R) + torque.r(1) * c.dtheta_o;
        if (std::fabs(direct) > cancellation_scale) return direct;
        const double a = evaluator.contact_state(tau, p.theta_R + 1, 0).theta_o - p.theta_R;
        const double b = evaluator.contact_state(tau, p.theta_R, 1).theta_o - p.theta_R;
        const double deviation = (theta0 - p.theta_R) * a + omega0 * b;
        return torque.r(0) * deviation + torque.r(1) * c.dtheta_o;
      };
      const int face = state.face;
      auto at = [&evaluator, &p, theta0, omega0, face](double tau) {
        const ContactState c = evaluator.contact_state(tau, theta0, omega0);
        return contact_state_on_face(p, face, c.theta_o, c.dtheta_o);
      };
      // The next time Tc leaves its holding sign (a grazing touch keeps contact).
      std::optional<Crossing> separation;
      double from = 0;
      if (std::fabs(transmitted_torque_at(p, theta0, omega0)) <= 1e-13 * std::max(1.0, std::fabs(omega0))) {
        // Starting on the separation line: certified departure of Tc first.
        if (auto t0 = certified_departure(w, 1e-12)) from = *t0;
      }
      while (!rigid) {
        separation = first_crossing(w, from, remaining);
        if (!separation || !separation->grazing) break;
        from = separation->t + 1e-12 * std::max(1.0, separation->t);
      }
      // Tc = r·y + r0 goes through the cancellation θR − θo: once the contact motion has decayed
      // to rounding level its sign is noise, and a "separation" found there is spurious (e.g. an
      // over-damped contact whose Tc = A e^{λ1 t} + B e^{λ2 t} has no zero for t > 0).  The test is
      // on the state, not on Tc's terms: when Fm/Jm = FL/JL the velocity term of Tc vanishes
      // identically and every genuine separation happens at θo = θR, with θ̇o far from zero.
      if (separation) {
        const ContactState c = evaluator.contact_state(separation->t, theta0, omega0);
        const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(p.theta_R));
        const double rate = std::sqrt(p.K / (p.Jm + p.JL));  // converts a velocity to a displacement scale
        if (std::fabs(c.theta_o - p.theta_R) <= noise && std::fabs(c.dtheta_o) <= noise * rate) separation.reset();
      }
      auto contact_vector = [&evaluator, theta0, omega0](double tau) {
        const ContactState c = evaluator.contact_state(tau, theta0, omega0);
        SmallVector y(2);
        y << c.theta_o, c.dtheta_o;
        return y;
      };
      if (options.track_extremes)
        segment_extremes(p, contact_segment, contact_vector, at, separation ? separation->t : remaining, true, result.extremes);
      if (!separation) {
        recorder.record(t, options.t_end + 1e-12, at);
        state = at(remaining);
        t = options.t_end;
        return finish(SimulationStatus::Completed);
      }
      recorder.record(t, t + separation->t + 1e-12, at);
      const HybridState at_separation = at(separation->t);
      t += separation->t;
      state = at_separation;
      state.in_contact = false;  // face σ is the face just left
      push_event(EventKind::Separation, false, false);
      if (options.stop_after_separations > 0 && ++separations >= options.stop_after_separations)
        return finish(SimulationStatus::Completed);
      continue;
    }

    // Free flight.
    const double theta_o = measured(p, state);
    const bool from_line = std::fabs(state.dtheta_m - state.dtheta_L) <= 1e-12 * std::max(1.0, std::fabs(state.dtheta_m)) &&
                           on_separation_line(evaluator, theta_o, state.dtheta_m);
    const Flight flight = from_line ? flight_from_separation_line(evaluator, state) : flight_from_state(p, state);
    const double scale = std::max({1.0, std::fabs(theta_o), std::fabs(state.dtheta_m)});
    const auto event =
        detail::first_gap_event(free_segment, flight.vector, flight.gap_change, -state.face * p.backlash, remaining, scale);
    if (options.track_extremes)
      segment_extremes(p, free_segment, flight.vector, flight.at, event ? event->crossing.t : remaining, false, result.extremes);
    if (!event) {
      recorder.record(t, options.t_end + 1e-12, flight.at);
      const HybridState end = flight.at(remaining);
      const double speed = std::max(std::fabs(end.dtheta_m), std::fabs(end.dtheta_L));
      if (speed < options.rest_velocity) {
        // Rest: the last time any velocity exceeded the tolerance (bisection on the closed form).
        double lo = 0, hi = remaining;
        for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
          const double mid = 0.5 * (lo + hi);
          bool moving = false;
          for (int k = 0; k <= 32 && !moving; ++k) {  // any motion left in [mid, remaining]?
            const HybridState s = flight.at(mid + (remaining - mid) * k / 32.0);
            moving = std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) >= options.rest_velocity;
          }
          (moving ? lo : hi) = mid;
        }
        const double t_end = t + remaining;
        t += hi;
        state = flight.at(hi);
        push_event(EventKind::Rest, false, false);
        t = t_end;
        state = end;
        return finish(SimulationStatus::Rest);
      }
      state = end;
      t = options.t_end;
      return finish(SimulationStatus::Completed);
    }
    recorder.record(t, t + event->crossing.t + 1e-12, flight.at);
    HybridState before = flight.at(event->crossing.t);
    t += event->crossing.t;
    // Inelastic impact (eq. 24) on the face hit.
    const int face_hit = event->kind == detail::GapEventKind::OppositeFace ? -state.face : state.face;
    const double omega = recombined_velocity(p, before.dtheta_m, before.dtheta_L);
    state = contact_state_on_face(p, face_hit, measured(p, before), omega);
    const double tc = transmitted_torque_at(p, measured(p, state), omega);
    const bool holds = -face_hit * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
    if (!holds) state.in_contact = false;  // a bounce: the bodies part again at once
    push_event(event->kind == detail::GapEventKind::OppositeFace ? EventKind::Recombination : EventKind::Recontact, !holds,
               event->crossing.grazing);
    impacts.push_back(t);
    while (!impacts.empty() && impacts.front() < t - options.zeno_window) impacts.pop_front();
    if (static_cast<int>(impacts.size()) >= options.zeno_impacts)
      return stop(SimulationStatus::Chattering, std::to_string(options.zeno_impacts) + " impacts within " +
                                                    std::to_string(options.zeno_window) + " s (Zeno)");
  }
  } catch (const SearchBudgetExhausted& budget) {
    return stop(SimulationStatus::WorkLimit, budget.what());
  }
  return finish(SimulationStatus::Completed);
}

void shift_state(HybridState& s, double offset) {
  s.theta_m += offset;
  s.theta_L += offset;
}

}  // namespace

// The numerics run in error coordinates (validation.hpp, in_error_coordinates): the angles are
// shifted by −θR on the way in and by +θR on the way out, so the gap θL − θm keeps its digits
// whatever θR is.  A generated case evaluator (θR folded in) runs as given.
SimulationResult simulate(const ValidatedEvaluator& evaluator, const HybridState& start, const SimulationOptions& options) {
  const std::optional<ValidatedEvaluator> centred = in_error_coordinates(evaluator);
  if (!centred) return simulate_as_given(evaluator, start, options);
  const double R = evaluator.parameters().theta_R;
  HybridState from = start;
  shift_state(from, -R);
  SimulationOptions shifted = options;
  auto shift_sample = [R](TrajectorySample& s) {
    s.theta_o += R;
    s.theta_m += R;
    s.theta_L += R;
  };
  if (options.sample_sink)
    shifted.sample_sink = [&options, &shift_sample](const TrajectorySample& sample) {
      TrajectorySample moved = sample;
      shift_sample(moved);
      options.sample_sink(moved);
    };
  SimulationResult r = simulate_as_given(*centred, from, shifted);
  for (SimulationEvent& e : r.events) {
    e.theta_o += R;
    shift_state(e.after, R);
    shift_state(e.before, R);
  }
  shift_state(r.final_state, R);
  r.theta_o_final += R;
  for (TrajectorySample& s : r.samples) shift_sample(s);
  for (double* angle : {&r.extremes.theta_o_min, &r.extremes.theta_o_max, &r.extremes.theta_m_min, &r.extremes.theta_m_max,
                        &r.extremes.theta_L_min, &r.extremes.theta_L_max})
    *angle += R;  // ±infinity (nothing tracked) stays
  return r;
}

SimulationResult simulate_step(const ValidatedEvaluator& evaluator, double step, const SimulationOptions& options) {
  return simulate(evaluator, step_start(evaluator.parameters(), step), options);
}

}  // namespace backlash::numeric
