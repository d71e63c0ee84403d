// backlash/discrepancy/two_body_drive.hpp — the measured-drive workflow on a drive WITH a gap:
// the motor and the load as two bodies (docs/discrepancy.md, "Measured drive with a gap").
//
// The model: a case file with `[experiment] kind = "drive"` and backlash b > 0.  The logged drive
// acts on the motor (the loop is open in the model); the gap x = θL − θm is centred, its faces at
// x0 ± b/2 (x0 the two encoders' zero offset, a nuisance parameter):
//     Jm·θm'' + Fm·θm' + Tm·sgn θm' = u + T0 − R,     u = gain·drive
//     JL·θL'' + FL·θL' + TL·sgn θL' = R
// with R the mesh torque on the load: 0 in flight, on face σ (σ = −1: the motor pushes the load
// forward, +1 backward) R = −σ·P, P ≥ 0 — a rigid mesh holds x on the face, a compliant one
// (stiffness kc) lets it in by P/kc:  x = x0 + σ·b/2 − R/kc.  Units are the record's own (rad,
// N·m, kg·m², N·m·s/rad).
//
// The method (torque domain, the filter and the noise rules of the rigid workflow,
// measured_drive.hpp):
//  * both encoders logged: the sum of the two equations, R cancelled,
//        u + T0 = Jm·âm + JL·âL + Fm·v̂m + FL·v̂L + Tm·s̄m + TL·s̄L      (filtered alike)
//    is linear in the load's parameters and the frictions (least squares, every sample away from
//    the filter's ends, a stop or a reversal of either body); the gap is then read where contact
//    is certain: on each face x = x0 + σ·b/2 − R/kc with R = JL·âL + FL·v̂L + TL·s̄L the load's
//    own inverse dynamics — b, x0 and 1/kc by least squares over the samples in contact (the
//    faces' plateaus, found by iterating the classification from the gap's two clusters);
//  * the motor encoder alone: the load is reconstructed from the measured motor motion by a LOAD
//    OBSERVER (load_observer below: in contact it follows the motor on its face, it leaves the
//    face when holding it would need a pull, in flight it coasts under its own friction until
//    the gap reaches a face) for a trial b, and the sum equation is compared with the observed
//    load in place of the measured one: at each reversal the motor crosses the gap alone (the
//    inverse dynamics sees Jm) and then takes the load (Jm + JL).  b by a scan and Brent's
//    minimisation of the profiled least-squares cost (the load's parameters and the frictions
//    by least squares at each b), needing at least five reversals.
// Uncertainties: Ceres's covariance of the final fit (numeric derivatives through the observer),
// scaled by the residual variance and the residual's integrated autocorrelation time.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/measurements/measured_record.hpp"

#include <cmath>
#include <span>
#include <string>
#include <vector>

namespace backlash::discrepancy {

/// One reversal of the motor: the lost motion (the motor's travel while the gap is crossed).
struct LostMotion {
  double t = 0;            ///< [s] the motor's reversal
  int direction = 0;       ///< +1: the motor turns forward, −1 backward
  double measured = NAN;   ///< |Δ(θL − θm)| face to face (both encoders); NaN with the motor encoder alone
  double model = NAN;      ///< the fitted model's: b plus the change of the mesh's deflection
};

/// The torque residual's noise level and where it comes from (docs/discrepancy.md, "Noise level
/// on a drive with a gap"): each source's σ and its share of the level [torque], the shares
/// added in quadrature.  An encoder's σ is its step/√12 (step 0: not quantised, the Δ⁴ rule on
/// its position); the drive's is read on its band above the cut-off, less the controller's
/// reaction to the encoders' counts.
struct TwoBodyNoise {
  double level = NAN;                            ///< [torque] the residual's expected RMS
  double drive = NAN, motor = NAN, load = 0;     ///< each source's share [torque] (load: both encoders)
  double sigma_drive = NAN;                      ///< σ of gain·drive [torque]
  double sigma_motor = NAN, sigma_load = NAN;    ///< σ of each encoder [position]
  double step_motor = 0, step_load = 0;          ///< each encoder's step (0: not quantised)
};

/// What the workflow finds on a drive with a gap (in DriveDiscrepancyResult::two_body).
struct TwoBodyFindings {
  bool load_encoder = false;  ///< theta_load logged: the gap observed directly
  std::string method;         ///< "gap observed (both encoders)" or "load observer (motor encoder alone)"
  std::vector<ParameterCorrection> parameter_corrections;  ///< backlash, load.J, load.F (motor.J, motor.F if free)
  double gap_offset = 0;      ///< x0, the encoders' relative zero [position] (both encoders)
  double contact_fraction = 0;  ///< of the compared samples found in contact
  int reversals_count = 0;    ///< of the motor
  bool rigid = false;         ///< the backlash is not distinguishable from 0 (within 3σ)
  double torque_rms_rigid = NAN;  ///< torque RMS of the same fit with b = 0 (motor encoder alone)
  std::vector<LostMotion> reversals;
  TwoBodyNoise noise;         ///< the noise level the status compares the residual with
  /// The motor encoder alone: σ of the backlash = √(moves² + timing²) — the jackknife over the
  /// moves, and the events' timing on whole samples, shared by every move (a bias).
  double backlash_sigma_moves = NAN, backlash_sigma_timing = NAN;
  /// The hysteresis loop (both encoders): θL against θm, measured and the model's (the fitted
  /// load observer on the measured motor motion), every sample.
  std::vector<double> loop_motor, loop_load, loop_model;
};

/// The load observer: the load's motion reconstructed from the motor's (filtered position qm,
/// velocity vm, acceleration am at the samples of rate fs) for a gap b centred on x0, the load's
/// inertia JL > 0, viscous friction FL ≥ 0 and Coulomb friction TL ≥ 0.  Returns the gap
/// x = θL − θm at every sample.  Starts in contact on the face the first motion presses (the
/// back face at rest).  Contact on face σ holds while −σ·(JL·am + FL·vm + TL·sgn vm) ≥ 0 (the
/// motor pushes; a pull would be needed otherwise); in flight the load coasts (exact closed form
/// over each sample, sticking at v = 0 under Coulomb friction) until x reaches a face, where the
/// inelastic impact puts it in contact again.  `compliance` = 1/kc ≥ 0 (0: a rigid mesh): in
/// contact the mesh is deflected quasi-statically, x = x0 + σ·b/2 − R/kc with R the torque the
/// load needs (its resonance is taken to lie above the band compared).
std::vector<double> load_observer(std::span<const double> qm, std::span<const double> vm, std::span<const double> am,
                                  double fs, double b, double x0, double JL, double FL, double TL, double compliance = 0);

}  // namespace backlash::discrepancy
