// The closed-form hybrid simulator with effects (effects_simulation.hpp,
// docs/effects.md).  One segment per mode: its closed-form flow (effect_modes.cpp),
// its witnesses, the first certified exit among them, the transition.
#include "backlash/numeric/effects_simulation.hpp"

#include "backlash/numeric/first_crossing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <sstream>

namespace backlash::numeric {

namespace {

int sign_of(double value) { return value > 0 ? 1 : value < 0 ? -1 : 0; }
bool at_motor(const Parameters& p) { return p.measured_at == model::MeasuredAt::Motor; }

// ------------------------------------------------------------------ witnesses

enum class Guard {
  ContactTorque,   // rigid contact: −σ·Tc ≥ 0
  PairVelocity,    // rigid contact: s·ω ≥ 0
  DriveHigh,       // linear drive: L − K(θR − θo) ≥ 0
  DriveLow,        // linear drive: L + K(θR − θo) ≥ 0
  DriveLeave,      // clipped drive: r·K(θR − θo) − L ≥ 0
  GapOpposite,     // free, rigid: σ·x + b/2 ≥ 0
  GapSame,         // free, rigid: b/2 − σ·x ≥ 0
  MotorVelocity,   // s_m·θ̇m ≥ 0
  LoadVelocity,    // s_L·θ̇L ≥ 0
  MotorBreakHigh,  // stuck motor: Tm − N ≥ 0
  MotorBreakLow,   // stuck motor: Tm + N ≥ 0
  LoadBreakHigh,   // stuck load (mesh): TL − N ≥ 0
  LoadBreakLow,    // stuck load (mesh): TL + N ≥ 0
  MeshRelease,     // mesh on face σ: P ≥ 0
  EngageFace,      // free, compliant: −δ_φ ≥ 0 (teeth apart)
  EngageForce,     // free, compliant, teeth overlapping: −P_φ ≥ 0
  ZoneExit,        // free, compliant, teeth overlapping: δ_φ ≥ 0
};

struct Witness {
  Guard guard;
  int face = 0;  ///< the face a gap/engagement guard concerns
  SmallRow row;  ///< w = row·z + constant, valid while w ≥ 0
  double constant = 0;
  double magnitude = 0;  ///< the size of the terms the constant was formed from (its rounding scale)
};

// row·z + constant; `magnitude` follows the size of the terms through the arithmetic.
struct Functional {
  SmallRow row;
  double constant = 0;
  double magnitude = 0;
  Functional scaled(double k) const { return {row * k, constant * k, magnitude * std::fabs(k)}; }
  Functional plus(const Functional& o) const { return {row + o.row, constant + o.constant, magnitude + o.magnitude}; }
  Functional shifted(double c) const { return {row, constant + c, magnitude + std::fabs(c)}; }
};

Functional of(const ModeFlow::Functional& f) { return {f.row, f.constant, f.magnitude}; }
Witness witness(Guard guard, int face, const Functional& f) { return {guard, face, f.row, f.constant, f.magnitude}; }

// The drive torque D as a functional of z (its regime fixed by the mode).
Functional drive_functional(const Parameters& p, const Effects& e, const ModeFlow& flow) {
  const Mode& m = flow.mode();
  const Functional error = of(flow.theta_o_error());
  if (m.regime == 0) return error.scaled(-p.K).shifted(e.torque_offset);
  return {SmallRow::Zero(error.row.size()), m.regime * e.saturation + e.torque_offset,
          e.saturation + std::fabs(e.torque_offset)};
}

// P_φ = kc·δ_φ + cc·δ̇_φ on face φ, δ_φ = φ·x − b/2.
Functional penetration_functional(const Parameters& p, const ModeFlow& flow, int face) {
  return of(flow.gap_functional()).scaled(face).shifted(-p.backlash / 2);
}
Functional mesh_force_functional(const Parameters& p, const Effects& e, const ModeFlow& flow, int face) {
  Functional rate{SmallRow::Zero(4), 0, 0};
  rate.row(1) = -face * e.mesh_damping;
  rate.row(3) = face * e.mesh_damping;
  return penetration_functional(p, flow, face).scaled(e.mesh_stiffness).plus(rate);
}

bool measured_shaft_moves(const Parameters& p, const Mode& m) {
  if (m.kind == ModeKind::Contact) return m.slip_motor != 0;
  return at_motor(p) ? m.slip_motor != 0 : m.slip_load != 0;
}

void add_drive_witnesses(const Parameters& p, const Effects& e, const ModeFlow& flow, std::vector<Witness>& out) {
  const Mode& m = flow.mode();
  if (!e.saturating() || !measured_shaft_moves(p, m)) return;
  const Functional demand = of(flow.theta_o_error()).scaled(-p.K);  // K(θR − θo)
  if (m.regime == 0) {
    const Functional high = demand.scaled(-1).shifted(e.saturation), low = demand.shifted(e.saturation);
    out.push_back(witness(Guard::DriveHigh, 0, high));
    out.push_back(witness(Guard::DriveLow, 0, low));
  } else {
    const Functional leave = demand.scaled(m.regime).shifted(-e.saturation);
    out.push_back(witness(Guard::DriveLeave, 0, leave));
  }
}

void add_contact_witnesses(const Parameters& p, const Effects& e, const ModeFlow& flow, std::vector<Witness>& out) {
  const Mode& m = flow.mode();
  if (m.slip_motor == 0) return;  // a stuck pair: nothing moves (rest)
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, T = e.coulomb_motor + e.coulomb_load;
  const int s = m.slip_motor;
  // Tc = JL ω̇ + FL ω + TL s with J ω̇ = −K d − F ω (drive linear, d the deviation from y*)
  // or J ω̇ = rL + T0 − T s − F ω (clipped).
  Functional tc{SmallRow::Zero(2), e.coulomb_load * s, e.coulomb_load};
  tc.row(1) = p.FL - p.JL * F / J;
  if (m.regime == 0) {
    tc.row(0) = -p.JL * p.K / J;
  } else {
    tc.constant += p.JL * (m.regime * e.saturation + e.torque_offset - T * s) / J;
    tc.magnitude += p.JL * (e.saturation + std::fabs(e.torque_offset) + T) / J;
  }
  const Functional hold = tc.scaled(-m.face);
  out.push_back(witness(Guard::ContactTorque, m.face, hold));
  if (T > 0) {
    SmallRow row = SmallRow::Zero(2);
    row(1) = s;
    out.push_back({Guard::PairVelocity, 0, row, 0});
  }
  add_drive_witnesses(p, e, flow, out);
}

void add_body_witnesses(const Effects& e, const Mode& m, const Functional& motor_torque, const Functional& load_torque,
                        bool load_can_break, std::vector<Witness>& out) {
  if (m.slip_motor != 0 && e.coulomb_motor > 0) {
    SmallRow row = SmallRow::Zero(4);
    row(1) = m.slip_motor;
    out.push_back({Guard::MotorVelocity, 0, row, 0});
  }
  if (m.slip_load != 0 && e.coulomb_load > 0) {
    SmallRow row = SmallRow::Zero(4);
    row(3) = m.slip_load;
    out.push_back({Guard::LoadVelocity, 0, row, 0});
  }
  if (m.slip_motor == 0) {
    const Functional high = motor_torque.scaled(-1).shifted(e.coulomb_motor), low = motor_torque.shifted(e.coulomb_motor);
    if (high.row.cwiseAbs().sum() > 0) {  // a constant torque cannot change: no break-away
      out.push_back(witness(Guard::MotorBreakHigh, 0, high));
      out.push_back(witness(Guard::MotorBreakLow, 0, low));
    }
  }
  if (m.slip_load == 0 && load_can_break) {
    const Functional high = load_torque.scaled(-1).shifted(e.coulomb_load), low = load_torque.shifted(e.coulomb_load);
    out.push_back(witness(Guard::LoadBreakHigh, 0, high));
    out.push_back(witness(Guard::LoadBreakLow, 0, low));
  }
}

void add_free_witnesses(const Parameters& p, const Effects& e, const ModeFlow& flow, std::vector<Witness>& out) {
  const Mode& m = flow.mode();
  const Functional gap = of(flow.gap_functional());
  if (!e.compliant()) {
    const Functional opposite = gap.scaled(m.face).shifted(p.backlash / 2);
    const Functional same = gap.scaled(-m.face).shifted(p.backlash / 2);
    out.push_back(witness(Guard::GapOpposite, -m.face, opposite));
    out.push_back(witness(Guard::GapSame, m.face, same));
  } else {
    for (int face : {m.face, -m.face}) {
      const Functional delta = penetration_functional(p, flow, face);
      const double delta0 = delta.constant;  // z starts at 0 displacement: δ(0) = its constant
      if (delta0 <= 1e-11 * delta.magnitude) {
        const Functional apart = delta.scaled(-1);
        out.push_back(witness(Guard::EngageFace, face, apart));
      } else {
        const Functional force = mesh_force_functional(p, e, flow, face).scaled(-1);
        out.push_back(witness(Guard::EngageForce, face, force));
        out.push_back(witness(Guard::ZoneExit, face, delta));
      }
    }
  }
  add_body_witnesses(e, m, drive_functional(p, e, flow), {SmallRow::Zero(4), 0, 0}, false, out);
  add_drive_witnesses(p, e, flow, out);
}

void add_mesh_witnesses(const Parameters& p, const Effects& e, const ModeFlow& flow, std::vector<Witness>& out) {
  const Mode& m = flow.mode();
  const Functional force = mesh_force_functional(p, e, flow, m.face);
  out.push_back(witness(Guard::MeshRelease, m.face, force));
  const Functional motor = drive_functional(p, e, flow).plus(force.scaled(m.face));
  const Functional load = force.scaled(-m.face);
  add_body_witnesses(e, m, motor, load, true, out);
  add_drive_witnesses(p, e, flow, out);
}

std::vector<Witness> witnesses_of(const Parameters& p, const Effects& e, const ModeFlow& flow) {
  std::vector<Witness> out;
  switch (flow.mode().kind) {
    case ModeKind::Contact: add_contact_witnesses(p, e, flow, out); break;
    case ModeKind::Free: add_free_witnesses(p, e, flow, out); break;
    case ModeKind::Mesh: add_mesh_witnesses(p, e, flow, out); break;
  }
  return out;
}

// ------------------------------------------------------------------ the first exit of a witness

struct Exit {
  double tau = 0;
  Witness witness;
  bool grazing = false;
};

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// A witness on its boundary at τ = 0 leaves it toward w > 0 (its first derivative that is not
// rounding noise is positive): the largest τ0 = horizon/2^i where the Taylor lower bound
//   w(τ) ≥ w_K τ^K/K! − Σ_{j<K} |w_j| τ^j/j! − sup|w^{(K+1)}| τ^{K+1}/(K+1)!
// is positive, sup|w^{(K+1)}| ≤ ‖e A^K‖₁ e^{‖A‖τ} ‖ż(0)‖∞.  0 when none is found.
double departure_time(const LinearWitness& lw, const SmallVector& zdot0, const std::array<double, 4>& w, int K,
                      double horizon) {
  SmallRow eAK = lw.e;
  for (int k = 0; k < K; ++k) eAK = eAK * lw.A;
  const double norm_A = lw.A.cwiseAbs().rowwise().sum().maxCoeff(), norm_z = zdot0.cwiseAbs().maxCoeff();
  const double norm_eAK = eAK.cwiseAbs().sum();
  double tau = horizon;
  for (int i = 0; i < 400 && tau > 0; ++i, tau *= 0.5) {
    double lower = w[K] * std::pow(tau, K) / factorial(K) -
                   norm_eAK * std::exp(norm_A * tau) * norm_z * std::pow(tau, K + 1) / factorial(K + 1);
    for (int j = 0; j < K; ++j) lower -= std::fabs(w[j]) * std::pow(tau, j) / factorial(j);
    if (lower > 0) return tau;
  }
  return 0;
}

enum class StartKind { Inside, ExitNow, Never };
struct Start {
  StartKind kind = StartKind::Inside;
  double from = 0;
};

// Where the search for the exit of a witness starts (see the header).  Rounding scales come
// from the size of the terms that formed each quantity (a deviation or a forcing can cancel):
// w(0) is on the boundary within 1e-11 of its terms' size; a derivative is noise below 1e-9.
Start classify_start(const ModeFlow& flow, const LinearWitness& lw, double magnitude, double horizon) {
  const SmallVector& z0 = flow.local_start();
  const SmallVector& z0_noise = flow.local_start_noise();
  const SmallVector zdot = lw.A * z0 + lw.c;
  const SmallVector zdot_scale = lw.A.cwiseAbs() * (z0.cwiseAbs() + z0_noise) + flow.forcing_magnitude();
  std::array<double, 4> w{};
  std::array<double, 4> scale{};
  w[0] = lw.e.dot(z0) - lw.level;
  const double tolerance = 1e-11 * (lw.e.cwiseAbs().dot(z0.cwiseAbs().transpose()) + magnitude) +
                           32 * lw.e.cwiseAbs().dot(z0_noise.transpose());
  SmallRow e = lw.e;
  for (int k = 1; k <= 3; ++k) {
    w[k] = e.dot(zdot);
    scale[k] = e.cwiseAbs().dot(zdot_scale.transpose());
    e = e * lw.A;
  }
  if (w[0] > tolerance) return {StartKind::Inside, 0};
  if (w[0] < -tolerance) return {StartKind::ExitNow, 0};
  for (int K = 1; K <= 3; ++K) {
    if (std::fabs(w[K]) <= 1e-9 * scale[K]) continue;
    if (w[K] < 0) return {StartKind::ExitNow, 0};
    const double from = departure_time(lw, zdot, w, K, horizon);
    return {StartKind::Inside, from > 0 ? from : std::min(horizon, 1e-12 * std::max(1.0, horizon))};
  }
  return {StartKind::Never, 0};
}

bool grazing_is_event(Guard g) { return g == Guard::GapOpposite || g == Guard::GapSame; }

std::optional<Exit> first_exit(const ModeFlow& flow, const Witness& witness, double horizon) {
  LinearWitness lw;
  lw.A = flow.segment().A;
  lw.c = flow.segment().c;
  lw.e = witness.row;
  lw.level = -witness.constant;
  lw.state = [&flow](double tau) { return flow.local(tau); };
  const Start start = classify_start(flow, lw, witness.magnitude, horizon);
  if (start.kind == StartKind::Never) return std::nullopt;
  if (start.kind == StartKind::ExitNow) return Exit{0, witness, false};
  double from = start.from;
  while (from < horizon) {
    const std::optional<Crossing> crossing = first_crossing(lw, from, horizon);
    if (!crossing) return std::nullopt;
    if (!crossing->grazing || grazing_is_event(witness.guard)) return Exit{crossing->t, witness, crossing->grazing};
    from = crossing->t + 1e-12 * std::max(1.0, crossing->t);
  }
  return std::nullopt;
}

// ------------------------------------------------------------------ the engine

class Engine {
 public:
  Engine(const ValidatedEffectModel& model, const SimulationOptions& options)
      : p_(model.parameters()), e_(model.effects()), o_(options), recorder_(p_, o_, result_) {}

  SimulationResult run(const HybridState& start);

 private:
  SimulationResult finish(SimulationStatus status);
  void push(EventKind kind, Body body = Body::None, bool bounce = false, bool grazing = false, bool accumulation = false);
  Mode mode_of(const HybridState& s) const;
  bool at_rest(const Mode& m) const;
  void settle();
  void settle_contact();
  void settle_body(bool motor);
  void transition(const Exit& exit, const ModeFlow& flow);
  void impact(const Exit& exit);
  double closing_acceleration(int face) const;
  bool accumulate(int face, double alpha, const HybridState& before);
  bool contact_holds(const HybridState& s) const;
  void track_extremes(const ModeFlow& flow, double duration);
  void include(const HybridState& h);
  bool rests_in_free_flight(const ModeFlow& flow, double remaining);

  const Parameters& p_;
  const Effects& e_;
  const SimulationOptions& o_;
  SimulationResult result_;
  TrajectoryRecorder recorder_;
  HybridState state_;
  double t_ = 0;
  long separations_ = 0;
  std::deque<double> impacts_;
};

SimulationResult Engine::finish(SimulationStatus status) {
  result_.status = status;
  result_.t_final = t_;
  result_.final_state = state_;
  result_.theta_o_final = measured(p_, state_);
  return std::move(result_);
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
}

Mode Engine::mode_of(const HybridState& s) const {
  Mode m;
  m.face = s.face;
  m.regime = s.drive_regime;
  if (s.in_contact && !e_.compliant()) {
    m.kind = ModeKind::Contact;
    const int slip = s.motor_stuck && s.load_stuck ? 0 : s.dtheta_m != 0 ? sign_of(s.dtheta_m) : -s.face;
    m.slip_motor = m.slip_load = slip;
    return m;
  }
  m.kind = s.in_contact ? ModeKind::Mesh : ModeKind::Free;
  auto slip = [](bool stuck, double velocity, double torque) {
    if (stuck) return 0;
    if (velocity != 0) return sign_of(velocity);
    return torque != 0 ? sign_of(torque) : 1;
  };
  m.slip_motor = slip(s.motor_stuck, s.dtheta_m, motor_static_torque(p_, e_, s));
  m.slip_load = slip(s.load_stuck, s.dtheta_L, load_static_torque(p_, e_, s));
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
  const double u = drive_torque_in_regime(p_, e_, measured(p_, state_), state_.drive_regime);
  const int face = state_.face;
  const double low = face < 0 ? -Tm : -(Tm + TL), high = face < 0 ? Tm + TL : Tm;
  if (u >= low && u <= high) {
    state_.motor_stuck = state_.load_stuck = true;
    state_.dtheta_L = 0;
    push(EventKind::Stick, Body::Both);
  } else if ((face < 0 && u < low) || (face > 0 && u > high)) {
    // beyond the pulling edge: the motor leaves the load, which stays stuck
    state_.in_contact = false;
    state_.motor_stuck = false;
    state_.load_stuck = TL > 0;
    push(EventKind::Separation);
  }
  // beyond the pushing edge: the pair moves on together (mode_of: s = −σ)
}

void Engine::settle_body(bool motor) {
  const double velocity = motor ? state_.dtheta_m : state_.dtheta_L;
  bool& stuck = motor ? state_.motor_stuck : state_.load_stuck;
  const double T = motor ? e_.coulomb_motor : e_.coulomb_load;
  if (velocity != 0 || stuck || T <= 0) return;
  const double torque = motor ? motor_static_torque(p_, e_, state_) : load_static_torque(p_, e_, state_);
  if (std::fabs(torque) <= T) {
    stuck = true;
    push(EventKind::Stick, motor ? Body::Motor : Body::Load);
  }
}

bool Engine::contact_holds(const HybridState& s) const {
  Mode m = mode_of(s);
  if (m.slip_motor == 0) return true;
  const double tc = contact_torque(p_, e_, m, s);
  return -s.face * tc >= -1e-14 * std::max(1.0, std::fabs(tc));
}

// After an impact with restitution on face σ (docs/effects.md): the relative acceleration α
// pressing the bodies back together; α > 0 makes the bounces that follow a converging series.
double Engine::closing_acceleration(int face) const {
  const Mode m = mode_of(state_);
  auto acceleration = [&](bool motor) {
    const int slip = motor ? m.slip_motor : m.slip_load;
    if (slip == 0) return 0.0;
    if (motor)
      return (drive_torque_in_regime(p_, e_, measured(p_, state_), state_.drive_regime) - p_.Fm * state_.dtheta_m -
              e_.coulomb_motor * slip) / p_.Jm;
    return (-p_.FL * state_.dtheta_L - e_.coulomb_load * slip) / p_.JL;
  };
  return face * (acceleration(false) - acceleration(true));
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
  const ModeFlow flow(p_, e_, mode_of(contact), contact);
  state_ = flow.state(tail);
  t_ += tail;
  return true;
}

void Engine::impact(const Exit& exit) {
  const HybridState before = state_;
  const int face_hit = exit.witness.face;
  const EventKind kind = exit.witness.guard == Guard::GapOpposite ? EventKind::Recombination : EventKind::Recontact;
  const ImpactVelocities v = impact_velocities(p_, e_.restitution, before.dtheta_m, before.dtheta_L);
  HybridState after = state_on_face(p_, face_hit, measured(p_, before), v.dtheta_m, true);
  after.dtheta_L = v.dtheta_L;
  after.drive_regime = before.drive_regime;
  state_ = after;
  bool converging = false;
  if (e_.restitution == 0) {
    const bool holds = contact_holds(state_);
    if (!holds) state_.in_contact = false;
    push(kind, Body::None, !holds, exit.grazing);
  } else {
    state_.in_contact = false;
    push(kind, Body::None, true, exit.grazing);
    const double alpha = closing_acceleration(face_hit);
    converging = alpha > 0;  // impacts of a converging series are not chattering
    if (accumulate(face_hit, alpha, before)) push(EventKind::Recontact, Body::None, false, false, true);
  }
  if (!converging) {
    impacts_.push_back(t_);
    while (!impacts_.empty() && impacts_.front() < t_ - o_.zeno_window) impacts_.pop_front();
  }
  settle();
}

void Engine::transition(const Exit& exit, const ModeFlow& flow) {
  const Mode& m = flow.mode();
  switch (exit.witness.guard) {
    case Guard::ContactTorque:
      state_.in_contact = false;
      push(EventKind::Separation);
      break;
    case Guard::PairVelocity:
      state_.dtheta_m = state_.dtheta_L = 0;
      settle_contact();
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
    case Guard::MeshRelease:
      state_.in_contact = false;
      push(EventKind::Separation);
      break;
    case Guard::EngageFace:
    case Guard::EngageForce:
      state_.in_contact = true;
      state_.face = exit.witness.face;
      push(exit.witness.face == m.face ? EventKind::Recontact : EventKind::Recombination);
      break;
    case Guard::ZoneExit:
      break;  // the teeth no longer overlap: the engagement guard changes, nothing happens
  }
}

void Engine::include(const HybridState& h) {
  Extremes& x = result_.extremes;
  const double o = measured(p_, h);
  x.theta_o_min = std::min(x.theta_o_min, o);
  x.theta_o_max = std::max(x.theta_o_max, o);
  x.theta_m_min = std::min(x.theta_m_min, h.theta_m);
  x.theta_m_max = std::max(x.theta_m_max, h.theta_m);
  x.theta_L_min = std::min(x.theta_L_min, h.theta_L);
  x.theta_L_max = std::max(x.theta_L_max, h.theta_L);
}

// The exact extremes of a segment: its ends and the certified zeros of each moving velocity.
void Engine::track_extremes(const ModeFlow& flow, double duration) {
  if (!o_.track_extremes) return;
  include(flow.state(0));
  include(flow.state(duration));
  std::vector<ModeFlow::Functional> velocities;
  if (flow.mode().kind == ModeKind::Contact) {
    if (flow.mode().slip_motor != 0) velocities.push_back(flow.motor_velocity());
  } else {
    if (flow.mode().slip_motor != 0) velocities.push_back(flow.motor_velocity());
    if (flow.mode().slip_load != 0) velocities.push_back(flow.load_velocity());
  }
  for (const ModeFlow::Functional& v : velocities) {
    LinearWitness w;
    w.A = flow.segment().A;
    w.c = flow.segment().c;
    w.e = v.row;
    w.level = -v.constant;
    w.state = [&flow](double tau) { return flow.local(tau); };
    double from = 0;
    for (int k = 0; k < 10000 && from < duration; ++k) {
      const auto zero = first_crossing(w, from, duration);
      if (!zero) break;
      include(flow.state(zero->t));
      from = zero->t + 1e-12 * std::max(1.0, zero->t);
    }
  }
}

// The nominal rest rule: free flight without a further event whose velocities have all decayed
// below rest_velocity at t_end; the rest event is the last time one was above it.
bool Engine::rests_in_free_flight(const ModeFlow& flow, double remaining) {
  if (flow.mode().kind != ModeKind::Free) return false;
  const HybridState end = flow.state(remaining);
  if (std::max(std::fabs(end.dtheta_m), std::fabs(end.dtheta_L)) >= o_.rest_velocity) return false;
  double lo = 0, hi = remaining;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = 0.5 * (lo + hi);
    bool moving = false;
    for (int k = 0; k <= 32 && !moving; ++k) {
      const HybridState s = flow.state(mid + (remaining - mid) * k / 32.0);
      moving = std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)) >= o_.rest_velocity;
    }
    (moving ? lo : hi) = mid;
  }
  const double t_end = t_ + remaining;
  t_ += hi;
  state_ = flow.state(hi);
  push(EventKind::Rest);
  t_ = t_end;
  state_ = end;
  return true;
}

bool finite(const HybridState& s) {
  return std::isfinite(s.theta_m) && std::isfinite(s.theta_L) && std::isfinite(s.dtheta_m) && std::isfinite(s.dtheta_L);
}

// The rounding-level rule of the nominal simulators: a zero of Tc where the contact motion has
// decayed to rounding level about its equilibrium is not a separation.
bool spurious_separation(const Parameters& p, const ModeFlow& flow, double tau) {
  const Mode& m = flow.mode();
  if (m.kind != ModeKind::Contact || m.regime != 0) return false;
  const SmallVector z = flow.local(tau);
  const double noise = 1024 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(p.theta_R));
  return std::fabs(z(0)) <= noise && std::fabs(z(1)) <= noise * std::sqrt(p.K / (p.Jm + p.JL));
}

SimulationResult Engine::run(const HybridState& start) {
  state_ = start;
  settle();
  while (t_ < o_.t_end) {
    if (!finite(state_)) return finish(SimulationStatus::NonFinite);
    if (static_cast<long>(result_.events.size()) >= o_.max_events) return finish(SimulationStatus::EventLimit);
    if (static_cast<int>(impacts_.size()) >= o_.zeno_impacts) return finish(SimulationStatus::Chattering);
    if (o_.stop_after_separations > 0 && separations_ >= o_.stop_after_separations)
      return finish(SimulationStatus::Completed);
    const Mode mode = mode_of(state_);
    if (at_rest(mode)) {  // everything stuck, the drive constant: nothing can change any more
      push(EventKind::Rest);
      const HybridState resting = state_;
      recorder_.record(t_, o_.t_end + 1e-12, [&resting](double) { return resting; });
      t_ = o_.t_end;
      return finish(SimulationStatus::Rest);
    }
    const double remaining = o_.t_end - t_;
    const ModeFlow flow(p_, e_, mode, state_);
    std::optional<Exit> next;
    double horizon = remaining;
    for (const Witness& w : witnesses_of(p_, e_, flow)) {
      std::optional<Exit> exit = first_exit(flow, w, horizon);
      while (exit && exit->witness.guard == Guard::ContactTorque && spurious_separation(p_, flow, exit->tau)) exit.reset();
      if (exit && (!next || exit->tau < next->tau)) {
        next = exit;
        horizon = exit->tau;
      }
    }
    const double duration = next ? next->tau : remaining;
    track_extremes(flow, duration);
    const double t0 = t_;
    if (!next) {
      recorder_.record(t0, o_.t_end + 1e-12, [&flow](double tau) { return flow.state(tau); });
      if (rests_in_free_flight(flow, remaining)) return finish(SimulationStatus::Rest);
      state_ = flow.state(remaining);
      t_ = o_.t_end;
      return finish(SimulationStatus::Completed);
    }
    recorder_.record(t0, t0 + next->tau + 1e-12, [&flow](double tau) { return flow.state(tau); });
    state_ = flow.state(next->tau);
    t_ = t0 + next->tau;
    transition(*next, flow);
  }
  return finish(SimulationStatus::Completed);
}

}  // namespace

SimulationResult simulate_effects(const ValidatedEffectModel& model, const HybridState& start,
                                  const SimulationOptions& options) {
  const Effects& e = model.effects();
  if (!e.any() && !options.general_engine) return simulate(model.nominal(), start, options);
  if (e.delayed()) return detail::simulate_delayed(model.parameters(), e, start, options);
  return Engine(model, options).run(start);
}

SimulationResult simulate_effects_step(const ValidatedEffectModel& model, double step, const SimulationOptions& options) {
  return simulate_effects(model, effects_step_start(model.parameters(), model.effects(), step), options);
}

}  // namespace backlash::numeric
