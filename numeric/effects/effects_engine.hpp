// numeric/effects/effects_engine.hpp (internal) — the event loop of the hybrid model
// with effects, shared by its two ways of moving through a mode:
//   closed forms (effects_simulation.cpp: every mode without delay) and
//   the delayed model integrated by the method of steps (effects_delay.cpp).
// The engine owns what is the same for both (docs/effects.md): the modes a state is
// in, the static rules (sticking, break-away, the pair's band), impacts with
// restitution and the summed bounce series, the transitions and their events, the
// rest rules, the statuses.  A subclass supplies the drive torque now and each
// segment: the motion in the current mode up to its first exit.
#pragma once

#include "effects/effect_modes.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/effects_engine_options.hpp"
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"

#include <deque>
#include <memory>
#include <optional>
#include <vector>

namespace backlash::numeric::detail {

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
  PairBreakPush,   // stuck pair (delay): the drive beyond the band's pushing edge
  PairBreakPull,   // stuck pair (delay): the drive beyond the band's pulling edge
  MeshRelease,     // mesh on face σ: P ≥ 0
  EngageFace,      // free, compliant: −δ_φ ≥ 0 (teeth apart)
  EngageForce,     // free, compliant, teeth overlapping: −P_φ ≥ 0
  ZoneExit,        // free, compliant, teeth overlapping: δ_φ ≥ 0
  Handover,        // Stribeck: a slipping body's speed crossing the level where its drop saturates
                   // (effects_stribeck.cpp); it ends a segment, never an event of the engine
};

/// row·z + constant + drive_weight·D(t) in a mode's local coordinates; `magnitude` is the size
/// of the terms the constant was formed from (its rounding scale).  Closed-form modes fold
/// the drive into row and constant (drive_weight = 0); the delayed model keeps it apart.
struct Functional {
  SmallRow row;
  double constant = 0;
  double magnitude = 0;
  double drive_weight = 0;
  Functional scaled(double k) const { return {row * k, constant * k, magnitude * std::fabs(k), drive_weight * k}; }
  Functional plus(const Functional& o) const {
    return {row + o.row, constant + o.constant, magnitude + o.magnitude, drive_weight + o.drive_weight};
  }
  Functional shifted(double c) const { return {row, constant + c, magnitude + std::fabs(c), drive_weight}; }
};

/// A guard: valid while its functional is ≥ 0; the event is its first exit.
struct Witness {
  Guard guard;
  int face = 0;  ///< the face a gap/engagement guard concerns
  Functional f;
};

struct Exit {
  double tau = 0;
  Witness witness;
  bool grazing = false;
};

/// The guards of a mode that do not involve the drive's regime (gap, velocity zeros,
/// break-away, mesh), given the functionals of the mode's coordinates.
struct ModeFunctionals {
  Functional theta_o_error, gap, drive;  ///< θo − θR, θL − θm, the drive torque D
  int dimension = 4;
  /// The face whose overlap zone the motion has just left at this instant (a ZoneExit, 0 if
  /// none): its teeth count as apart, whatever rounding δ(0) keeps, so that the next guard is
  /// the engagement and not the same ZoneExit again (docs/effects.md).
  int left_zone = 0;
};
std::vector<Witness> mode_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f,
                                    bool with_drive_limits);
/// The same into `out` (cleared first; its storage kept: no allocation per segment once it has grown).
void mode_witnesses(const Parameters& p, const Effects& e, const Mode& m, const ModeFunctionals& f, bool with_drive_limits,
                    std::vector<Witness>& out);

/// The motion in one mode from the engine's current state.
class Segment {
 public:
  virtual ~Segment() = default;
  virtual HybridState state(double tau) const = 0;
  /// θo at τ, measured(p, state(τ)) bit for bit (a segment may form fewer terms for it).
  virtual double measured_at(const Parameters& p, double tau) const { return measured(p, state(tau)); }
  /// Adds the extremes of θo, θm, θL over [0, duration] (ends and velocity zeros).
  virtual void extremes(double duration, Extremes& x) const = 0;
  std::optional<Exit> exit;  ///< the first exit before the horizon
  double duration = 0;       ///< exit->tau, the horizon, or a breakpoint of the delayed model
  bool rest = false;         ///< everything stuck (or coasting to rest) and nothing can happen any more
  double rest_after = 0;     ///< the rest begins this long after the segment's start
};

class Engine {
 public:
  Engine(const Parameters& p, const Effects& e, const SimulationOptions& options, const EffectsEngineOptions& engine);
  virtual ~Engine() = default;
  SimulationResult run(const HybridState& start);

 protected:
  /// The drive torque D at the current time (a state, or the delayed history).
  virtual double drive_now() const = 0;
  /// The segment of `mode` from state_ at t_, over at most `remaining`.
  virtual std::unique_ptr<Segment> next_segment(const Mode& mode, double remaining) = 0;
  /// Called after every event and segment (the delayed model records its history).
  virtual void advanced(double /*t_from*/, const Segment* /*segment*/) {}
  /// How far a slipping body's friction at velocity v lies below the level e_ gives it (Stribeck
  /// friction, effects_stribeck.cpp, where e_ carries the static level); 0 for Coulomb friction.
  virtual double friction_drop(bool /*motor*/, double /*velocity*/) const { return 0; }

  Mode mode_of(const HybridState& s) const;
  double motor_static_torque(const HybridState& s) const;
  double load_static_torque(const HybridState& s) const;
  double contact_torque(const Mode& m, const HybridState& s) const;
  /// ModeFunctionals::left_zone for a segment starting now.
  int left_zone() const { return t_ == zone_left_at_ ? zone_left_face_ : 0; }

  const Parameters& p_;
  const Effects& e_;
  const SimulationOptions& o_;
  const EffectsEngineOptions engine_;
  SimulationResult result_;
  TrajectoryRecorder recorder_;
  HybridState state_;
  double t_ = 0;

 private:
  SimulationResult finish(SimulationStatus status);
  SimulationResult stop(SimulationStatus status, std::string reason);
  SimulationResult advance();
  void push(EventKind kind, Body body = Body::None, bool bounce = false, bool grazing = false, bool accumulation = false);
  bool at_rest(const Mode& m) const;
  void settle();
  void settle_contact();
  void settle_body(bool motor);
  void transition(const Exit& exit, const Mode& m);
  void impact(const Exit& exit);
  void count_impact();
  double closing_acceleration(int face) const;
  bool accumulate(int face, double alpha, const HybridState& before);
  bool contact_holds(const HybridState& s) const;
  bool rests_in_free_flight(const Mode& m, const Segment& segment, double remaining);

  long separations_ = 0;
  int zone_left_face_ = 0;  ///< the face of the last ZoneExit, at zone_left_at_
  double zone_left_at_ = -1;
  long instant_steps_ = 0;  ///< consecutive segments that ended at once without an event
  bool stop_reached_ = false;  ///< the event of engine_.stop_at_kind / stop_at_face happened
  std::deque<double> impacts_;
};

/// The constants of a witness's certified bounds, WitnessMode(A, c, e) bit for bit, kept per
/// thread for the last few (A, e) (effects_simulation.cpp): only the forcing's terms are formed
/// again when a mode is entered with the same matrix and guard.
WitnessMode witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e);
/// The same without the copy: the kept entry itself, its forcing set to c — valid until the next
/// call on this thread (copy it to keep it).
const WitnessMode& kept_witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e);
/// The same for the witnesses of one matrix A: `group` = kept_mode_group(A) (A's value among
/// the kept entries, so A is compared once for all of a segment's witnesses, not once each).
std::uint64_t kept_mode_group(const SmallMatrix& A);
const WitnessMode& kept_witness_mode(std::uint64_t group, const SmallMatrix& A, const SmallVector& c, const SmallRow& e);

/// Whether the gap rate θ̇L − θ̇m of a free flight in mode `m` of the closed-form engine (rigid
/// gear: no compliance, delay or Stribeck friction) has at most two real zeros, counted with
/// multiplicity (docs/effects.md, "A flight whose gap turns at most once"): each body's velocity
/// solves a linear ODE whose added torques are constant over the mode (the offset T0, a clipped
/// drive ±L, the Coulomb torques −T·s), and the gap rate is annihilated by a polynomial in D of
/// degree ≤ 3 with real roots when
///   - the motor is stuck, or its drive is clipped (D(D + Fm/Jm) for the motor), or
///   - the load has no Coulomb torque (or is stuck) and the nominal flight has the property
///     (gap_rate_turns_at_most_once: the output at the load, or an over-damped motor);
/// not with a slipping load's Coulomb torque and a linear drive (degree 4: D²(D + FL/JL)(D + Fm/Jm)
/// at the load, D(D + FL/JL)(D² + (Fm/Jm)D + K/Jm) at the motor).
bool free_gap_turns_once(const Parameters& p, const Effects& e, const Mode& m);

/// Whether a closed-form segment leaves out the search for the return to the face a flight left
/// where it is proved to find nothing — the window of the opposite face's crossing, a window at
/// whose end the gap still moves away from the face left (docs/effects.md, "A flight whose gap
/// turns at most once"):
/// `Proved` where free_gap_turns_once holds and the flight starts with one velocity for both
/// bodies, `Off` never; `Forced` wherever the two gap guards are searched (tests only: where the
/// proof does not hold it misses returns).
enum class OneTurn { Proved, Off, Forced };

/// The closed-form segment of mode `m` from `start` (effects_simulation.cpp) with `extra` guards
/// besides the mode's own (Handover guards: their exit ends the segment without an exit);
/// `left_zone` as ModeFunctionals::left_zone.
std::unique_ptr<Segment> closed_form_segment(const Parameters& p, const Effects& e, const Mode& m,
                                             const HybridState& start, double horizon, double t_global,
                                             int left_zone, const std::vector<Witness>& extra,
                                             OneTurn one_turn = OneTurn::Proved);

/// Stribeck friction (dopri5 with exact event semantics): effects_stribeck.cpp.
SimulationResult simulate_stribeck(const Parameters& p, const Effects& e, const HybridState& start,
                                   const SimulationOptions& options, const EffectsEngineOptions& engine);

/// The delayed model (Boost.Odeint, method of steps): effects_delay.cpp.
SimulationResult simulate_delayed(const Parameters& p, const Effects& e, const HybridState& start,
                                  const SimulationOptions& options, const EffectsEngineOptions& engine);

}  // namespace backlash::numeric::detail
