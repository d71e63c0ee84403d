// backlash/discrepancy/measured_drive.hpp — the discrepancy workflow on a record of a
// real drive whose drive torque is logged (docs/discrepancy.md §"Measured drive").
//
// The model (a case file with `[experiment] kind = "drive"` and backlash 0) is a rigid drive
// (a backlash > 0 makes it two bodies with their gap: two_body_drive.hpp):
//     J·q'' + F·q' + Tc·sgn(q') = u(t − τ) + T0,   u = sat_L(gain · drive)
// with J = Jm + JL, F = Fm + FL, and the effects of the vocabulary that make sense without a
// gap: Coulomb friction Tc (coulomb_motor; on a rigid drive the motor's and the load's are
// one friction), the torque offset T0, saturation L, delay τ.  Units are the record's own (EMPS:
// metres, newtons, kilograms).
//
// The comparison is in the torque domain (inverse dynamics): the torque the model needs along
// the MEASURED motion against the measured drive,
//     r = filter(Ū − φ) + T0 − (J·â + F·v̂)          [torque]
// where v̂, â are derivatives of the measured position through a zero-phase low-pass
// (Butterworth, forward–backward), Ū the logged drive clipped at ±L and held (zero-order hold,
// delayed by τ) as the second difference of the position sees it (quadratic B-spline weights),
// φ the friction — Tc·s̄ moving (s̄ the average of sgn v), at rest the force that holds the
// drive (Ū + T0 within ±Tc) or Tc·sgn(Ū + T0) — all through the same filter
// (docs/discrepancy.md).  The cut-off is the user's, or the highest frequency at which the
// position's spectrum stands 100× (20 dB) above its noise floor
// (measurements/inverse_dynamics_signals.hpp).  The filter's end transients, and the samples
// within the filter's length of a start, a stop or a reversal, are not compared.
// The torque residual is also checked where it matters to a user, in position: the model,
// restarted from the measured state at the start of every window (0.5 s by default), predicts
// the position over the window (measured_drive_simulation.hpp, exact for the zero-order-hold
// drive); the page shows the RMS of those predictions before and after.
//
// The workflow:
//   1. the nominal parameters the model file marks free ([fit] free = ["motor.J", ...]) are
//      fitted first, so that the gap "before" is that of the best nominal model;
//   2. the residual is localised: moving forward, moving backward, at reversals (±20 ms
//      around a change of the sign of v̂), at rest, at high acceleration (|â| above its 90th
//      percentile), each with its RMS and its mean (a mean of opposite signs forward and
//      backward is the signature of Coulomb friction, a mean of one sign everywhere that of an
//      offset); and in time, stretch by stretch between reversals;
//   3. every candidate effect is fitted on seven of ten blocks of the record (the third, sixth
//      and ninth held out), linear parameters by least squares, a delay or a saturation limit
//      by a scan and Brent's minimisation of the least-squares cost over it; it is decisive when
//      ΔBIC < −decisive_bic, with n the number of INDEPENDENT residuals n/τ_int (τ_int the
//      residual's integrated autocorrelation time: filtered 1 kHz residuals are far from
//      independent), its held-out RMS ≤ decisive_holdout × the current one, and no parameter at
//      an end of its range.  The most decisive is named, the whole model refitted on the whole
//      record, the search repeated; when no single candidate is decisive, pairs are tried by
//      the same rule (two parameters' penalty);
//   4. uncertainties are one standard deviation from the least-squares covariance
//      s²(AᵀA)⁻¹ (A the Jacobian of the residual, a delay's or limit's column by central
//      differences) inflated by τ_int;
//   5. with a validation record, the best nominal and the corrected model, as fitted on the
//      estimation record, are scored on it without refitting.
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/discrepancy/measured_drive_simulation.hpp"
#include "backlash/discrepancy/two_body_drive.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace backlash::discrepancy {

/// The effects that can be named on a rigid measured drive, in the order they are tried.
const std::vector<std::string>& drive_vocabulary();

struct DriveOptions {
  double cutoff = NAN;            ///< [Hz]; NaN: from the position's spectrum
  double window = 0.5;            ///< [s] position-prediction windows
  double holdout_fraction = 0.3;  ///< the blocks held out of every fit (every third of ten)
  double decisive_bic = 10;
  double decisive_holdout = 0.8;
  int max_effects = 3;
  std::vector<std::string> candidates = drive_vocabulary();
};

/// A stretch or a class of samples and the torque residual there.
struct TorqueRegion {
  std::string kind;  ///< "forward", "backward", "reversal", "rest", "high acceleration"
  double t_start = NAN, t_end = NAN;  ///< for stretches in time; NaN for classes
  int samples = 0;
  double rms_before = 0, rms_after = 0;    ///< of r [torque]
  double mean_before = 0, mean_after = 0;  ///< of r [torque]
};

/// One record's scores under the best nominal and the corrected model.
struct DriveScores {
  std::string record;
  int samples = 0;
  double torque_rms_nominal = 0, torque_rms_corrected = 0;      ///< [torque]
  double position_rms_nominal = 0, position_rms_corrected = 0;  ///< window predictions [position]
  int windows = 0;
};

struct DriveDiscrepancyResult {
  Status status = Status::NoDiscrepancy;
  // The band.
  double sample_rate = 0;       ///< [Hz]
  double cutoff = 0;            ///< [Hz]
  bool cutoff_from_spectrum = true;
  double spectrum_floor = NAN;  ///< the position's PSD floor [position²/Hz] (cut-off from the spectrum)
  // Noise.
  double position_noise = 0;    ///< σ of the measured position (Δ⁴ rule)
  double drive_noise = 0;       ///< σ of gain·drive (Δ⁴ rule) [torque]
  double noise = 0;             ///< the torque residual's noise level: both propagated through the filter [torque]
  double rest_speed = 0;        ///< below this |v̂| the drive is at rest [position/s]
  double tau_int_before = 0, tau_int_after = 0;  ///< residual correlation times [samples]
  // The models.
  numeric::Parameters given;            ///< as in the model file
  numeric::Parameters nominal;          ///< free nominal parameters refitted (the "before" model)
  std::vector<Parameter> nominal_fit;   ///< "motor.J", ... with uncertainty
  numeric::Parameters parameters;       ///< of the corrected model
  numeric::Effects corrected_effects;
  std::vector<Parameter> corrected_nominal;  ///< the free nominal parameters refitted with the effects
  std::vector<Candidate> effects;            ///< named, in the order found
  std::vector<std::vector<Candidate>> rounds;
  // The gap.
  double rms_given = 0;                 ///< torque RMS of the file's model
  double rms_before = 0, rms_after = 0; ///< torque RMS, best nominal and corrected [torque]
  std::vector<TorqueRegion> classes;    ///< forward, backward, reversal, rest, high acceleration
  std::vector<TorqueRegion> stretches;  ///< the record between reversals
  DriveScores estimation;
  std::optional<DriveScores> validation;
  // Traces for the figures (estimation record; every sample).
  std::vector<double> t, velocity, torque_measured, torque_nominal, torque_corrected;
  std::vector<double> position, position_nominal, position_corrected;  ///< window predictions
  std::vector<double> window_starts;
  std::vector<double> validation_t, validation_position, validation_nominal, validation_corrected, validation_window_starts;
  /// A drive with a gap (backlash > 0 in the model file): the two-body findings
  /// (two_body_drive.hpp); absent for a rigid drive.
  std::optional<TwoBodyFindings> two_body;
  int least_squares = 0;  ///< least-squares solves the fits used
  double seconds = 0;
};

/// The whole workflow on a measured-drive record.  `validation`: a second record of the same
/// drive, scored without refitting.  Throws std::invalid_argument for a model or record it
/// cannot use (a free parameter a rigid drive cannot show, no drive column, no theta_out on a
/// rigid drive, no theta_motor on a drive with a gap, non-uniform sampling, too short a
/// record), naming the problem.  A model with backlash > 0 runs the two-body workflow
/// (two_body_drive.hpp; the result's `two_body` is set; no validation record yet).
DriveDiscrepancyResult find_drive_discrepancy(const model::CaseSpec& model, const measurements::MeasuredRecord& data,
                                              const DriveOptions& options = {},
                                              const measurements::MeasuredRecord* validation = nullptr);

// The result as files: reports/discrepancy_pages.hpp.

}  // namespace backlash::discrepancy
