// backlash/numeric/effects.hpp — the effects the thesis left out, as doubles
// (semantics: docs/effects.md).
//
//   Coulomb friction   Tm, TL ≥ 0 [torque]: −T·sgn(ω) on a moving body; a body at rest
//                      stays stuck while the torque on it is within ±T
//   restitution        e ∈ [0, 1): v_rel⁺ = −e·v_rel⁻ at gap closure, momentum conserved
//   saturation         L > 0 [torque]: the drive K(θR − θo) clipped at ±L
//   compliance         kc > 0 [torque/rad], cc ≥ 0 [torque·s/rad]: the mesh pushes with
//                      kc·δ + cc·δ̇ beyond ±b/2, never pulls
//   delay              τ ≥ 0 [s]: the fed-back angle is θo(t − τ)
//   torque offset      T0 [torque]: a constant torque on the motor shaft
//   Stribeck friction  Ts ≥ Tk ≥ 0 [torque], vs > 0 [rad/s] on either body: a moving body's
//                      friction −s·(Tk + (Ts − Tk)·exp(−(v/vs)²)), added to its Coulomb torque;
//                      a body at rest stays stuck while the torque on it is within ±(T + Ts)
// Every effect at its neutral value (0, no limit, a rigid mesh) is the nominal model.
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/model/effect_table.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/parametric.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace backlash::numeric {

/// The effects as doubles: one member per row of the table of effects
/// (backlash/model/effect_table.hpp), named by its FIELD and holding its NEUTRAL value unless
/// set — coulomb_motor Tm, coulomb_load TL, restitution e, saturation L (∞: unlimited),
/// mesh_stiffness kc (∞: a rigid mesh), mesh_damping cc, delay τ, the torque offset T0.
struct Effects {
#define BACKLASH_EFFECT_PARAMETER_DOUBLE(FIELD, EFFECT, KEY, NAME, SYMBOL, DESCRIPTION, UNIT, NEUTRAL, ...) \
  double FIELD = NEUTRAL;
  BACKLASH_EFFECT_PARAMETERS(BACKLASH_EFFECT_PARAMETER_DOUBLE)
#undef BACKLASH_EFFECT_PARAMETER_DOUBLE

  bool saturating() const { return std::isfinite(saturation); }
  bool compliant() const { return std::isfinite(mesh_stiffness); }
  bool coulomb() const { return coulomb_motor > 0 || coulomb_load > 0; }
  bool delayed() const { return delay > 0; }
  bool stribeck() const { return stribeck_motor_static > 0 || stribeck_load_static > 0; }
  /// True when the effect is present: its first parameter not neutral.
  bool has(const model::EffectInfo& effect) const;
  /// True when some effect differs from its neutral value.
  bool any() const;
  /// "coulomb_load=0.03, restitution=0.4" (only the effects present, every parameter of each by
  /// its table NAME; "none" when nominal).
  std::string describe() const;
};

/// Stribeck friction (docs/effects.md, "Stribeck friction") on the motor (`motor`) or the load:
/// the static level, the body's Coulomb torque plus its Stribeck Ts (a body at rest sticks while
/// the torque on it is within ±static_friction) ...
double static_friction(const Effects& e, bool motor);
/// ... and the drop of a moving body's friction below it at velocity v,
/// (Ts − Tk)·(1 − exp(−(v/vs)²)) ≥ 0 (0 at rest, Ts − Tk as |v| ≫ vs), with its derivative d/dv.
double stribeck_drop(const Effects& e, bool motor, double v);
double stribeck_drop_rate(const Effects& e, bool motor, double v);

/// The constant part of the drive torque in a saturation regime (0 linear, ±1 clipped at ±L):
/// regime·L + T0 (the linear part, K·(θR − θo), is added by the mode).
double drive_constant(const Effects& e, int regime);

/// A bound on the constant part of the drive over every regime: L + |T0| (|T0| when unsaturated).
double drive_constant_bound(const Effects& e);

/// The case file's [effects] table as doubles.
Effects effects_of(const model::CaseSpec& spec);

/// The drive torque D = sat(K·(θR − θo_fed_back)) + T0 and the saturation regime it is in
/// (0 linear, ±1 clipped at ±L).
double drive_torque(const Parameters& p, const Effects& e, double theta_o_fed_back);
int drive_regime(const Parameters& p, const Effects& e, double theta_o_fed_back);
/// D in a given regime (the regime is part of the mode: at a boundary both sides agree).
double drive_torque_in_regime(const Parameters& p, const Effects& e, double theta_o_fed_back, int regime);

/// The servo period 2π·sqrt(J/K), the time scale of the accumulation rule.
double servo_period(const Parameters& p);

/// The slowest impact that bounces (docs/effects.md): 1e-9·sqrt(K/J)·max(1, b) [rad/s] of
/// relative velocity.  A slower impact is inelastic — its bounce would be w²/α high, below
/// the resolution of the positions — which ends a stick–bounce cascade as it accumulates.
double slowest_bounce(const Parameters& p);

/// The step start with effects: at rest, θo = θR − step, in contact (rigid, or the mesh
/// engaged at zero penetration) on the face that drives toward θR; the drive's regime from
/// the initial error.  Sticking is not decided here: each simulator applies the static
/// rules of docs/effects.md to a body at rest that is not marked stuck.
HybridState effects_step_start(const Parameters& p, const Effects& e, double step);

/// Momentum-conserving impact with restitution e: the velocities just after,
/// v_rel⁺ = −e·v_rel⁻ (e = 0: the thesis's eq. 24, both at the common velocity).
struct ImpactVelocities {
  double dtheta_m, dtheta_L;
};
ImpactVelocities impact_velocities(const Parameters& p, double restitution, double dtheta_m, double dtheta_L);

}  // namespace backlash::numeric
