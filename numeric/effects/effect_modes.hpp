// numeric/effects/effect_modes.hpp (internal) — the linear modes of the hybrid model with
// effects (docs/effects.md), each solved in closed form from any state.
//
// A mode fixes what is linear: rigid contact on a face or free flight or the
// mesh engaged (compliance), each body slipping in a direction s = ±1 or stuck,
// the drive linear or clipped at ±L.  In a mode every force is linear in the
// state plus a constant (Coulomb torques −T·s, the offset T0, a clipped drive
// ±L), so the motion is x' = A x + c and has a closed form.  Each mode is
// written in local coordinates z where that closed form is exact and free of
// cancellation:
//
//   contact, drive linear     z = (d, ω): d = θo − θR − y*, y* = (T0 − (Tm+TL)·s)/K, the
//                             equilibrium the Coulomb torque and the offset shift;
//                             J d'' + F d' + K d = 0  →  d = d0·c + (ω0 + α d0)·s_,
//                             ω = ω0·c − (α ω0 + w² d0)·s_  with (c, s_) = damped_pair(α, w², τ),
//                             α = F/2J, w² = K/J  (under-, critically and over-damped alike)
//   contact, drive clipped    z = (Δ, ω), Δ = θo − θo0: J Δ'' + F Δ' = g, g = ±L + T0 − (Tm+TL)·s:
//                             Δ = ω0 τ φ1(−βτ) + (g/J) τ² φ2(−βτ), ω = ω0 e^{−βτ} + (g/J) τ φ1(−βτ), β = F/J
//   contact, stuck            z = (Δ, ω) = 0
//   free flight               z = (Δm, θ̇m, ΔL, θ̇L), displacements since the mode began:
//     load   JL θ̈L + FL θ̇L = −TL sL:  ΔL = vL0 τ φ1(y) + gL τ² φ2(y), θ̇L = vL0 e^{y} + gL τ φ1(y),
//            y = −(FL/JL) τ, gL = −TL sL/JL  (stuck: 0)
//     motor  drive constant (clipped, or the output at the load with the load stuck):
//            Jm θ̈m + Fm θ̇m = D − Tm sm, the same φ form with x = −(Fm/Jm) τ
//            output at the motor, drive linear: damped pair about θR + (T0 − Tm sm)/K
//            output at the load, drive linear: driven by the moving load,
//            Δm = vm0 τ φ1(x) + c0 τ² φ2(x) − k vL0 τ³ A2(x, y) − k gL τ⁴ A3(x, y),
//            θ̇m = vm0 e^{x} + c0 τ φ1(x) − k vL0 τ² A1(x, y) − k gL τ³ A2(x, y),
//            k = K/Jm, c0 = (−K (θL0 − θR) + T0 − Tm sm)/Jm, A_n = exp[0ⁿ, x, y]
//            (the divided differences of phi_functions.hpp: continuous as FL, Fm → 0
//            and as Fm/Jm → FL/JL)
//   mesh engaged (compliance) z as in free flight, the bodies coupled by
//            P = kc δ + cc δ̇ (δ = σ(θL − θm) − b/2): the roots of a quartic, so the flow is
//            the eigen-decomposition of the augmented matrix [[A, c], [0, 0]] when it is
//            well conditioned, else its exponential (Eigen's Padé approximant).
// Every flow is checked against Boost.Odeint integrating its own x' = A x + c by
// the effects gate (effects_simulation.hpp: validate_effects) before use.
#pragma once

#include "backlash/numeric/effects.hpp"
#include "evaluators/phi_functions.hpp"
#include "backlash/numeric/first_crossing.hpp"
#include "backlash/numeric/mode.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace backlash::numeric {

/// Every mode the model can enter (for the gate): kinds × faces × regimes × slips.
std::vector<Mode> reachable_modes(const Parameters& p, const Effects& e);

/// The torque on a body at rest without its Coulomb and viscous terms (docs/effects.md):
/// the motor's drive (plus, with the mesh engaged, its reaction), the load's mesh force.
double motor_static_torque(const Parameters& p, const Effects& e, const HybridState& s);
double load_static_torque(const Parameters& p, const Effects& e, const HybridState& s);

/// Penetration δ beyond face σ and the mesh force P = kc δ + cc δ̇ (compliance).
double penetration(const Parameters& p, int face, const HybridState& s);
double mesh_force(const Parameters& p, const Effects& e, int face, const HybridState& s);

/// Transmitted torque in rigid contact, Tc = JL ω̇ + FL ω + TL s.
double contact_torque(const Parameters& p, const Effects& e, const Mode& m, const HybridState& s);

/// A mode's linear system z' = A z + c (+ drive_column·D(t) when the drive is kept
/// external, as with a delay: then the contact coordinates are (Δ, ω) and no drive term
/// is folded into A or c), its start z0, the rounding z0 carries, and the size of the
/// terms that formed c.
struct ModeSystem {
  LinearSegment segment;
  SmallVector z0, z0_noise, c_magnitude, drive_column;
};
ModeSystem mode_system(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start,
                       bool drive_external);

/// Whether an eigenbasis V (with its inverse) is well conditioned, ‖V‖∞·‖V⁻¹‖∞ ≤ limit, the row sums
/// of the moduli |v_ij| as Eigen's cwiseAbs forms them — decided without the moduli where bounds
/// on them decide it (the mesh modes' flow uses its eigen-decomposition only then).
bool well_conditioned_basis(const Eigen::MatrixXcd& vectors, const Eigen::MatrixXcd& inverse, double limit);

/// Re(a·b) with the bits of (a * b).real() and without the imaginary part (the mesh flow's
/// sums Re Σ_j V_ij w_j: only real parts are read).  Inline: it is called m·n times per sample.
/// The product's real part is ac − bd unless that is NaN, when the product recovers infinities
/// (C99 Annex G, libgcc's __muldc3): then the product itself.
inline double real_of_product(std::complex<double> a, std::complex<double> b) {
  const double re = a.real() * b.real() - a.imag() * b.imag();
  return std::isnan(re) ? (a * b).real() : re;
}

/// A mode's closed-form motion from a state.
class ModeFlow {
 public:
  ModeFlow(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start);
  const Mode& mode() const { return mode_; }
  /// z' = A z + c in the local coordinates.
  const LinearSegment& segment() const { return system_.segment; }
  /// z(τ) from the closed form.
  SmallVector local(double tau) const;
  /// The local coordinates of the start state, and the rounding error they carry (a
  /// deviation formed from absolute positions keeps their rounding, not its own size).
  const SmallVector& local_start() const { return system_.z0; }
  const SmallVector& local_start_noise() const { return system_.z0_noise; }
  /// The size of the terms that formed the forcing c (its rounding scale: c may cancel).
  const SmallVector& forcing_magnitude() const { return system_.c_magnitude; }
  /// The full state at τ (flags of the mode: in_contact, face, stuck, regime).
  HybridState state(double tau) const;
  /// The measured shaft's angle θo at τ, rad: measured(p, state(τ)) bit for bit, with only the
  /// terms θo reads formed (a free flight's other shaft's kernels are not computed).
  double measured_at(double tau) const;
  /// The full state for local coordinates z.
  HybridState state_of(const SmallVector& z) const;
  /// θo for local coordinates z, rad: measured(p, state_of(z)) bit for bit, without the state.
  double measured_of(const SmallVector& z) const;
  /// The gap x = θL − θm for local coordinates z, and the measured shaft.
  double gap(const SmallVector& z) const;
  double theta_o(const SmallVector& z) const;
  /// A linear functional row·z + constant of the local coordinates (θo − θR, the gap, θ̇m,
  /// θ̇L); `magnitude` is the size of the terms the constant was formed from.
  struct Functional {
    SmallRow row;
    double constant = 0;
    double magnitude = 0;
  };
  Functional theta_o_error() const;
  Functional gap_functional() const;
  Functional motor_velocity() const;
  Functional load_velocity() const;
  /// The generic (mesh) flow could not use its eigen-decomposition and evaluates e^{Mτ}.
  bool uses_matrix_exponential() const;
  /// For a flow known as a sum of exponentials (the mesh modes' eigen-decomposition):
  /// sup over [a, b] of |d^k/dτ^k row·z(τ)| ≤ Σ_j |row·V_j q_j| |λ_j|^k max(e^{Re λ_j a}, e^{Re λ_j b}).
  /// For a flow by the matrix exponential: the bound from z'(a) in the plain and the balanced
  /// norm, the smaller.  Empty otherwise (the closed forms are not stiff: the generic bound serves).
  std::function<double(double, double)> derivative_bound(const SmallRow& row, int order) const;

 private:
  struct Generic;
  std::function<double(double, double)> matrix_exponential_bound(const SmallRow& row, int order) const;
  CoupledKernels free_kernels(double x, double y) const;
  CoupledKernels node_kernels(double x, double y, bool motor, bool load) const;
  // A free flight's local coordinates from its kernels: the motor's (z0, z1), the load's (z2, z3).
  void motor_part(double tau, const CoupledKernels& k, double& z0, double& z1) const;
  void load_part(double tau, const CoupledKernels& k, double& z2, double& z3) const;
  Parameters p_;
  Effects e_;
  Mode mode_;
  HybridState start_;
  ModeSystem system_;  // A, c, z0, its rounding, c's terms: mode_system's, kept as formed (not copied)
  // closed-form constants
  DampedRates contact_rates_;                      // contact: α = F/2J, w² = K/J (damped_rates)
  double beta_ = 0, g_ = 0;                        // contact
  double y_star_ = 0;                              // contact / motor: equilibrium shift
  double theta_o_constant_ = 0;  // contact: theta_o_error().constant, formed once (state_of's, per sample)
  double motor_y0_ = 0;          // closed loop at the motor: θo0 − θR − y*, formed once (local's, per sample)
  double a_ = 0, b_ = 0, k_ = 0, c0_ = 0, gL_ = 0, gm_ = 0;  // free
  DampedRates motor_rates_;  // free, closed loop at the motor: α = Fm/2Jm, w² = K/Jm
  int motor_form_ = 0;  // 0 stuck, 1 constant drive, 2 closed loop at the motor, 3 driven by the load
  std::shared_ptr<const Generic> generic_;
};

}  // namespace backlash::numeric
