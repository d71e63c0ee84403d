// The event loop of the hybrid model with effects (effects_engine.hpp, docs/effects.md).
#include "effects/effects_engine.hpp"
#include "hybrid/gap_events.hpp"
#include "hybrid/rest_search.hpp"


#include <algorithm>
#include <cmath>
#include <limits>

namespace backlash::numeric::detail {

namespace {

int sign_of(double value) { return value > 0 ? 1 : value < 0 ? -1 : 0; }

Functional velocity(int dimension, int index, double sign) {
  Functional f{SmallRow::Zero(dimension), 0, 0, 0};
  f.row(index) = sign;
  return f;
}

Functional mesh_force_functional(const Parameters& p, const Effects& e, const ModeFunctionals& f, int face) {
  const Functional delta = f.gap.scaled(face).shifted(-p.backlash / 2);
  return delta.scaled(e.mesh_stiffness).plus(velocity(4, 3, face * e.mesh_damping)).plus(velocity(4, 1, -face * e.mesh_damping));
}

void add(std::vector<Witness>& out, Guard guard, int face, const Functional& f) { out.push_back({guard, face, f}); }

bool varies(const Functional& f) { return f.row.cwiseAbs().sum() > 0 || f.drive_weight != 0; }

// Tc ≥ 0 / ≤ 0 and the pair's velocity zero (rigid contact); a stuck pair's band (the drive can
// only move with the delay).
void contact_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                       std::vector<Witness>& out) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, Tm = e.coulomb_motor, TL = e.coulomb_load, T = Tm + TL;
  const int s = m.slip_motor;
  if (s == 0) {
    if (!varies(f.drive)) return;
    const double low = m.face < 0 ? -Tm : -T, high = m.face < 0 ? T : Tm;
    const Functional above = f.drive.shifted(-low), below = f.drive.scaled(-1).shifted(high);
    add(out, m.face < 0 ? Guard::PairBreakPush : Guard::PairBreakPull, 0, below);
    add(out, m.face < 0 ? Guard::PairBreakPull : Guard::PairBreakPush, 0, above);
    return;
  }
  // Tc = JL ω̇ + FL ω + TL s,  J ω̇ = D − F ω − T s.
  const Functional tc = f.drive.scaled(p.JL / J)
                            .plus(velocity(2, 1, p.FL - p.JL * F / J))
                            .shifted(TL * s - p.JL * T * s / J);
  // Without backlash the gear is a rigid drive: it transmits a torque of either sign and never
  // separates (docs/physics.md).
  if (p.backlash > 0) add(out, Guard::ContactTorque, m.face, tc.scaled(-m.face));
  if (T > 0) add(out, Guard::PairVelocity, 0, velocity(2, 1, s));
}

// Velocity zeros of slipping bodies; break-away of stuck ones (N leaving [−T, T]).
void body_witnesses(const Effects& e, const Mode& m, const Functional& motor_torque, const Functional& load_torque,
                    std::vector<Witness>& out) {
  if (m.slip_motor != 0 && e.coulomb_motor > 0) add(out, Guard::MotorVelocity, 0, velocity(4, 1, m.slip_motor));
  if (m.slip_load != 0 && e.coulomb_load > 0) add(out, Guard::LoadVelocity, 0, velocity(4, 3, m.slip_load));
  if (m.slip_motor == 0 && varies(motor_torque)) {
    add(out, Guard::MotorBreakHigh, 0, motor_torque.scaled(-1).shifted(e.coulomb_motor));
    add(out, Guard::MotorBreakLow, 0, motor_torque.shifted(e.coulomb_motor));
  }
  if (m.slip_load == 0 && varies(load_torque)) {
    add(out, Guard::LoadBreakHigh, 0, load_torque.scaled(-1).shifted(e.coulomb_load));
    add(out, Guard::LoadBreakLow, 0, load_torque.shifted(e.coulomb_load));
  }
}

void free_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                    std::vector<Witness>& out) {
  if (!e.compliant()) {
    add(out, Guard::GapOpposite, -m.face, f.gap.scaled(m.face).shifted(p.backlash / 2));
    add(out, Guard::GapSame, m.face, f.gap.scaled(-m.face).shifted(p.backlash / 2));
  } else {
    for (int face : {m.face, -m.face}) {
      const Functional delta = f.gap.scaled(face).shifted(-p.backlash / 2);
      // the displacements start at 0: δ(0) = its constant
      if (face == f.left_zone || delta.constant <= 1e-11 * delta.magnitude) {
        add(out, Guard::EngageFace, face, delta.scaled(-1));
      } else {
        add(out, Guard::EngageForce, face, mesh_force_functional(p, e, f, face).scaled(-1));
        add(out, Guard::ZoneExit, face, delta);
      }
    }
  }
  body_witnesses(e, m, f.drive, Functional{SmallRow::Zero(4), 0, 0, 0}, out);
}

void mesh_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                    std::vector<Witness>& out) {
  const Functional force = mesh_force_functional(p, e, f, m.face);
  add(out, Guard::MeshRelease, m.face, force);
  body_witnesses(e, m, f.drive.plus(force.scaled(m.face)), force.scaled(-m.face), out);
}

bool measured_shaft_moves(const Parameters& p, const Mode& m) {
  if (m.kind == ModeKind::Contact) return m.slip_motor != 0;
  return p.measured_at == model::MeasuredAt::Motor ? m.slip_motor != 0 : m.slip_load != 0;
}

// K(θR − θo) reaching ±L (or leaving it): closed-form modes only; with a delay the drive's
// limits are crossings of the history.
void drive_limit_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                           std::vector<Witness>& out) {
  if (!e.saturating() || !measured_shaft_moves(p, m)) return;
  const Functional demand = f.theta_o_error.scaled(-p.K);  // K(θR − θo)
  if (m.regime == 0) {
    add(out, Guard::DriveHigh, 0, demand.scaled(-1).shifted(e.saturation));
    add(out, Guard::DriveLow, 0, demand.shifted(e.saturation));
  } else {
    add(out, Guard::DriveLeave, 0, demand.scaled(m.regime).shifted(-e.saturation));
  }
}

}  // namespace

void mode_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f, bool with_drive_limits,
                    std::vector<Witness>& out) {
  out.clear();
  switch (m.kind) {
    case ModeKind::Contact: contact_witnesses(p, e, m, f, out); break;
    case ModeKind::Free: free_witnesses(p, e, m, f, out); break;
    case ModeKind::Mesh: mesh_witnesses(p, e, m, f, out); break;
  }
  if (with_drive_limits) drive_limit_witnesses(p, e, m, f, out);
}

// The gap rate's annihilating polynomial (docs/effects.md, "A flight whose gap turns at most
// once"): a stuck motor's velocity is 0, a clipped drive's motor solves D(D + Fm/Jm)θ̇m = 0; the
// load solves (D + FL/JL)θ̇L = 0, D(D + FL/JL)θ̇L = 0 with its Coulomb torque, θ̇L = 0 stuck.  A
// linear drive adds the nominal flight's factor (gap_rate_turns_at_most_once) — times the load's
// extra root at 0 when the load slips with a Coulomb torque, which makes the degree 4.
bool free_gap_turns_once(const Parameters& p, const Effects& e, const Mode& m) {
  if (m.kind != ModeKind::Free || e.compliant() || e.delayed() || e.stribeck() || !(p.backlash > 0)) return false;
  if (m.slip_motor == 0 || m.regime != 0) return true;
  if (m.slip_load != 0 && e.coulomb_load > 0) return false;
  return gap_rate_turns_at_most_once(p);
}

std::vector<Witness> mode_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                                    bool with_drive_limits) {
  std::vector<Witness> out;
  mode_witnesses(p, e, m, f, with_drive_limits, out);
  return out;
}

// ------------------------------------------------------------------ Engine

Engine::Engine(const Parameters& p, const Effects& e, const SimulationOptions& options,
               const EffectsEngineOptions& engine)
    : p_(p), e_(e), o_(options), engine_(engine), recorder_(p_, o_, result_) {}

SimulationResult Engine::finish(SimulationStatus status) {
  result_.status = status;
  result_.t_final = t_;
  result_.final_state = state_;
  result_.theta_o_final = measured(p_, state_);
  return std::move(result_);
}

SimulationResult Engine::stop(SimulationStatus status, std::string reason) {
  result_.stop_reason = std::move(reason);
  return finish(status);
}

void Engine::push(EventKind kind, Body body, bool bounce, bool grazing, bool accumulation) {
  SimulationEvent e;
  e.t = t_;
  e.kind = kind;
  e.theta_o = measured(p_, state_);
  e.dtheta_o = measured_velocity(p_, state_);
  e.after = state_;
  e.bounce = bounce;
  e.grazing = grazing;
  e.body = body;
  e.accumulation = accumulation;
  result_.events.push_back(e);
  if (kind == EventKind::Separation) ++separations_;
  if (engine_.stop_at_face != 0 && kind == engine_.stop_at_kind && state_.face == engine_.stop_at_face && t_ > 0)
    stop_reached_ = true;
  if (engine_.stop_when && engine_.stop_when(result_.events)) stop_reached_ = true;
}

double Engine::motor_static_torque(const HybridState& s) const {
  double torque = drive_now();
  if (e_.compliant() && s.in_contact) torque += s.face * numeric::mesh_force(p_, e_, s.face, s);
  return torque;
}

double Engine::load_static_torque(const HybridState& s) const {
  return e_.compliant() && s.in_contact ? -s.face * numeric::mesh_force(p_, e_, s.face, s) : 0.0;
}

double Engine::contact_torque(const Mode& m, const HybridState& s) const {
  const double J = p_.Jm + p_.JL, F = p_.Fm + p_.FL, omega = s.dtheta_m;
  if (m.slip_motor == 0) return 0;
  const double TL = e_.coulomb_load - friction_drop(false, omega);
  const double T = e_.coulomb_motor - friction_drop(true, omega) + TL;
  const double acceleration = (drive_now() - F * omega - T * m.slip_motor) / J;
  return p_.JL * acceleration + p_.FL * omega + TL * m.slip_motor;
}

Mode Engine::mode_of(const HybridState& s) const {
  Mode m;
  m.face = s.face;
  m.regime = s.drive_regime;
  if (s.in_contact && !e_.compliant()) {
    m.kind = ModeKind::Contact;
    // At rest and not stuck the pair can only move the way the motor pushes the load (−σ); a
    // rigid drive (no backlash) moves the way the drive turns it.
    const int slip = s.motor_stuck && s.load_stuck ? 0
                     : s.dtheta_m != 0         ? sign_of(s.dtheta_m)
                     : p_.backlash == 0        ? sign_of(drive_now())
                                               : -s.face;
    m.slip_motor = m.slip_load = slip;
    return m;
  }
  m.kind = s.in_contact ? ModeKind::Mesh : ModeKind::Free;
  auto slip = [](bool stuck, double velocity, double torque) {
    if (stuck) return 0;
    if (velocity != 0) return sign_of(velocity);
    return torque != 0 ? sign_of(torque) : 1;
  };
  m.slip_motor = slip(s.motor_stuck, s.dtheta_m, motor_static_torque(s));
  m.slip_load = slip(s.load_stuck, s.dtheta_L, load_static_torque(s));
  return m;
}

bool Engine::at_rest(const Mode& m) const {
  if (m.kind == ModeKind::Contact) return m.slip_motor == 0;
  return m.slip_motor == 0 && m.slip_load == 0;
}

// The static rules of docs/effects.md for whatever is at rest and not marked stuck.
void Engine::settle() {
  if (state_.in_contact && !e_.compliant()) {
    settle_contact();
    return;
  }
  settle_body(true);
  settle_body(false);
}

void Engine::settle_contact() {
  if (state_.dtheta_m != 0 || (state_.motor_stuck && state_.load_stuck)) return;
  const double Tm = e_.coulomb_motor, TL = e_.coulomb_load;
  if (Tm + TL <= 0) return;
  const double u = drive_now();
  const int face = state_.face;
  const double low = face < 0 ? -Tm : -(Tm + TL), high = face < 0 ? Tm + TL : Tm;
  if ((u >= low && u <= high) || (p_.backlash == 0 && std::fabs(u) <= Tm + TL)) {
    state_.motor_stuck = state_.load_stuck = true;
    state_.dtheta_L = 0;
    push(EventKind::Stick, Body::Both);
  } else if (p_.backlash > 0 && ((face < 0 && u < low) || (face > 0 && u > high))) {
    // beyond the pulling edge: the motor leaves the load, which stays stuck
    state_.in_contact = false;
    state_.motor_stuck = false;
    state_.load_stuck = TL > 0;
    push(EventKind::Separation);
  } else {
    state_.motor_stuck = state_.load_stuck = false;  // beyond the pushing edge: on together (s = −σ)
  }
}

void Engine::settle_body(bool motor) {
  const double v = motor ? state_.dtheta_m : state_.dtheta_L;
  bool& stuck = motor ? state_.motor_stuck : state_.load_stuck;
  const double T = motor ? e_.coulomb_motor : e_.coulomb_load;
  if (v != 0 || stuck || T <= 0) return;
  const double torque = motor ? motor_static_torque(state_) : load_static_torque(state_);
  if (std::fabs(torque) <= T) {
    stuck = true;
    push(EventKind::Stick, motor ? Body::Motor : Body::Load);
  }
}

bool Engine::contact_holds(const HybridState& s) const {
  const Mode m = mode_of(s);
  if (m.slip_motor == 0) return true;
  const double tc = contact_torque(m, s);
  return -s.face * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
}

// After an impact with restitution on face σ: the relative acceleration α pressing the bodies
// back together (free-flight torques); α > 0 makes the bounces that follow a converging series.
double Engine::closing_acceleration(int face) const {
  const Mode m = mode_of(state_);
  const double Tm = e_.coulomb_motor - friction_drop(true, state_.dtheta_m);
  const double TL = e_.coulomb_load - friction_drop(false, state_.dtheta_L);
  const double motor = m.slip_motor == 0 ? 0.0 : (drive_now() - p_.Fm * state_.dtheta_m - Tm * m.slip_motor) / p_.Jm;
  const double load = m.slip_load == 0 ? 0.0 : (-p_.FL * state_.dtheta_L - TL * m.slip_load) / p_.JL;
  return face * (load - motor);
}

// The rest of a converging bounce series is summed when its duration τ∞ = 2w/(α(1 − e)) is below
// accumulation_fraction·T_servo: the inelastic impact at t, then the contact motion over τ∞.
bool Engine::accumulate(int face, double alpha, const HybridState& before) {
  const double w = -face * (state_.dtheta_L - state_.dtheta_m);  // separating relative speed
  if (!(w > 0) || !(alpha > 0)) return false;
  const double tail = 2 * w / (alpha * (1 - e_.restitution));
  if (tail > accumulation_fraction * servo_period(p_)) return false;
  const ImpactVelocities v = impact_velocities(p_, 0, before.dtheta_m, before.dtheta_L);
  HybridState contact = state_on_face(p_, face, measured(p_, before), v.dtheta_m, true);
  contact.drive_regime = state_.drive_regime;
  if (!contact_holds(contact)) return false;
  const HybridState saved = state_;
  state_ = contact;
  const std::unique_ptr<Segment> motion = next_segment(mode_of(contact), tail);
  if (motion->exit && motion->exit->tau < tail) {  // something happens within the tail: keep bouncing
    state_ = saved;
    return false;
  }
  state_ = motion->state(tail);
  t_ += tail;
  return true;
}

void Engine::impact(const Exit& exit) {
  const HybridState before = state_;
  const int face_hit = exit.witness.face;
  const EventKind kind = exit.witness.guard == Guard::GapOpposite ? EventKind::Recombination : EventKind::Recontact;
  // Restitution applies above the slowest bounce; a slower impact is inelastic (effects.md).
  const bool bounces = e_.restitution > 0 && std::fabs(before.dtheta_L - before.dtheta_m) >= slowest_bounce(p_);
  const ImpactVelocities v = impact_velocities(p_, bounces ? e_.restitution : 0.0, before.dtheta_m, before.dtheta_L);
  HybridState after = state_on_face(p_, face_hit, measured(p_, before), v.dtheta_m, true);
  after.dtheta_L = v.dtheta_L;
  after.drive_regime = before.drive_regime;
  state_ = after;
  bool converging = false;
  if (!bounces) {
    const bool holds = contact_holds(state_);
    if (!holds) state_.in_contact = false;
    push(kind, Body::None, !holds, exit.grazing);
    result_.events.back().before = before;
  } else {
    // A bounce series continues when the event before this impact was a bounce on this face:
    // only then is the impact exempt from the chattering guard (a stick-bounce cascade is not).
    const auto& events = result_.events;
    const bool continues_series = !events.empty() && events.back().bounce &&
                                  (events.back().kind == EventKind::Recombination ||
                                   events.back().kind == EventKind::Recontact) &&
                                  events.back().after.face == face_hit;
    state_.in_contact = false;
    push(kind, Body::None, true, exit.grazing);
    result_.events.back().before = before;
    const double alpha = closing_acceleration(face_hit);
    converging = alpha > 0 && continues_series;
    if (accumulate(face_hit, alpha, before)) push(EventKind::Recontact, Body::None, false, false, true);
  }
  if (!converging) count_impact();
  settle();
}

void Engine::count_impact() {
  impacts_.push_back(t_);
  while (!impacts_.empty() && impacts_.front() < t_ - zeno_window(p_, o_)) impacts_.pop_front();
}

void Engine::transition(const Exit& exit, const Mode& m) {
  switch (exit.witness.guard) {
    case Guard::ContactTorque:
    case Guard::MeshRelease:
      state_.in_contact = false;
      push(EventKind::Separation);
      break;
    case Guard::PairVelocity:
      state_.dtheta_m = state_.dtheta_L = 0;
      settle_contact();
      break;
    case Guard::PairBreakPush:
      state_.motor_stuck = state_.load_stuck = false;
      push(EventKind::Slip, Body::Both);
      break;
    case Guard::PairBreakPull:
      state_.in_contact = false;
      state_.motor_stuck = false;
      push(EventKind::Slip, Body::Motor);
      push(EventKind::Separation);
      break;
    case Guard::DriveHigh:
    case Guard::DriveLow:
      state_.drive_regime = exit.witness.guard == Guard::DriveHigh ? 1 : -1;
      push(EventKind::Saturation);
      break;
    case Guard::DriveLeave:
      state_.drive_regime = 0;
      push(EventKind::Desaturation);
      break;
    case Guard::GapOpposite:
    case Guard::GapSame:
      impact(exit);
      break;
    case Guard::MotorVelocity:
      state_.dtheta_m = 0;
      settle_body(true);
      break;
    case Guard::LoadVelocity:
      state_.dtheta_L = 0;
      settle_body(false);
      break;
    case Guard::MotorBreakHigh:
    case Guard::MotorBreakLow:
      state_.motor_stuck = false;
      push(EventKind::Slip, Body::Motor);
      break;
    case Guard::LoadBreakHigh:
    case Guard::LoadBreakLow:
      state_.load_stuck = false;
      push(EventKind::Slip, Body::Load);
      break;
    case Guard::EngageFace:
    case Guard::EngageForce:
      state_.in_contact = true;
      state_.face = exit.witness.face;
      push(exit.witness.face == m.face ? EventKind::Recontact : EventKind::Recombination);
      count_impact();  // engagements count towards the chattering guard like impacts
      break;
    case Guard::ZoneExit:  // the teeth no longer overlap: the engagement guard changes, nothing happens
      zone_left_face_ = exit.witness.face;
      zone_left_at_ = t_;
      break;
    case Guard::Handover:
      break;  // never an exit of a segment (effects_stribeck.cpp)
  }
}

// The nominal rest rule: free flight without a further event whose velocities have all decayed
// below rest_velocity at t_end; the rest event is the last time one was above it.
bool Engine::rests_in_free_flight(const Mode& m, const Segment& segment, double remaining) {
  if (m.kind != ModeKind::Free) return false;
  const HybridState end = segment.state(remaining);
  if (std::max(std::fabs(end.dtheta_m), std::fabs(end.dtheta_L)) >= o_.rest_velocity) return false;
  const double hi = detail::rest_time([&](double t) { return segment.state(t); }, remaining, o_.rest_velocity);
  const double t_end = t_ + remaining;
  t_ += hi;
  state_ = segment.state(hi);
  push(EventKind::Rest);
  t_ = t_end;
  state_ = end;
  return true;
}

namespace {
// Mode changes at one instant without an event (a guard handing over to another) before the
// engine stops: each changes the mode, so a handful suffice; more is a loop.
constexpr long max_instant_steps = 64;

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}
}  // namespace

SimulationResult Engine::run(const HybridState& start) {
  state_ = start;
  try {
    settle();
    return advance();
  } catch (const SearchBudgetExhausted& budget) {  // a certified search, or the delayed model's steps
    return stop(SimulationStatus::WorkLimit, budget.what());
  }
}

SimulationResult Engine::advance() {
  while (t_ < o_.t_end) {
    if (!finite(state_)) return stop(SimulationStatus::NonFinite, "the state is no longer finite");
    if (static_cast<long>(result_.events.size()) >= o_.max_events)
      return stop(SimulationStatus::EventLimit, event_limit_reason(o_));
    if (static_cast<int>(impacts_.size()) >= o_.zeno_impacts)
      return stop(SimulationStatus::Chattering, zeno_reason(o_, zeno_window(p_, o_)));
    if (o_.stop_after_separations > 0 && separations_ >= o_.stop_after_separations)
      return finish(SimulationStatus::Completed);
    if (stop_reached_) return finish(SimulationStatus::Completed);
    const Mode mode = mode_of(state_);
    const double remaining = o_.t_end - t_;
    const std::unique_ptr<Segment> segment = next_segment(mode, remaining);
    const auto record = [this, &segment](double from, double upto) {  // the samples over [from, upto]
      if (o_.sample_theta_o_only)
        recorder_.record(from, upto, [this, &segment](double tau) { return segment->measured_at(p_, tau); });
      else
        recorder_.record(from, upto, [&segment](double tau) { return segment->state(tau); });
    };
    if (segment->rest) {  // everything stuck, the drive constant (or coasting to rest): nothing can change any more
      if (segment->rest_after > 0) {
        record(t_, t_ + segment->rest_after);
        state_ = segment->state(segment->rest_after);
        t_ += segment->rest_after;
      }
      push(EventKind::Rest);
      const HybridState resting = state_;
      if (o_.sample_theta_o_only)
        recorder_.record(t_, o_.t_end + 1e-12, [theta_o = measured(p_, resting)](double) { return theta_o; });
      else
        recorder_.record(t_, o_.t_end + 1e-12, [&resting](double) { return resting; });
      t_ = o_.t_end;
      return finish(SimulationStatus::Rest);
    }
    if (o_.track_extremes && t_ >= engine_.extremes_after) segment->extremes(segment->duration, result_.extremes);
    const double t0 = t_;
    if (!segment->exit) {
      if (segment->duration < remaining) {  // a breakpoint of the delayed model: the mode goes on
        record(t0, t0 + segment->duration);
        state_ = segment->state(segment->duration);
        t_ = t0 + segment->duration;
        continue;
      }
      record(t0, o_.t_end + 1e-12);
      if (rests_in_free_flight(mode, *segment, remaining)) return finish(SimulationStatus::Rest);
      state_ = segment->state(remaining);
      t_ = o_.t_end;
      return finish(SimulationStatus::Completed);
    }
    record(t0, t0 + segment->exit->tau + 1e-12);
    state_ = segment->state(segment->exit->tau);
    t_ = t0 + segment->exit->tau;
    const std::size_t events = result_.events.size();
    transition(*segment->exit, mode);
    instant_steps_ = t_ == t0 && result_.events.size() == events ? instant_steps_ + 1 : 0;
    if (instant_steps_ > max_instant_steps)
      return stop(SimulationStatus::WorkLimit, "the mode changed " + std::to_string(max_instant_steps) +
                                                   " times at one instant without an event (docs/effects.md)");
  }
  return finish(SimulationStatus::Completed);
}

}  // namespace backlash::numeric::detail
