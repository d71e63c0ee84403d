// backlash/numeric/validation.hpp — the validation gate.
//
// Every evaluator (generated per case, stable parametric, direct per branch)
// is checked against Boost.Odeint integrating the same segment ODEs
// (reference.hpp: dopri5, dense output, abs = rel = 1e-12):
//   free mode   θm, θ̇m, θL, θ̇L and the gap θL − θm on a grid of θ̇m0 (both
//               signs, down to 1e-7), each over the segment's whole horizon:
//               up to recombination (the gap has changed by b, or returned to
//               0), at most `time_constants` time constants of the slowest pole;
//   contact     θo, θ̇o from several initial states (steps toward θR and points
//               on the separation line), over `time_constants` time constants;
//   cot φ       against (Jm·FL − Fm·JL)/(K·JL).
// Angles are compared in error coordinates θ − θR (the reference integrates with θR = 0), so
// the gate does not depend on the reference angle.  The maximum absolute error of each state,
// and where it occurs, is reported; the gate passes when every error is ≤ tolerance (1e-9)
// times max(1, the trajectory's size in that state): a trajectory of unit size or smaller is
// held to 1e-9 absolute, a larger one (velocities of 1e3 rad/s when K = 1e6) to 1e-9 of its size.
// The horizon is also capped at `max_rate_units` units of the fastest rate (the explicit
// reference needs steps of about 1/rate): a stiff segment is compared over some sixty of its fast
// periods, not integrated for minutes.
//
// The gate is part of the pipeline: a ValidatedEvaluator can only be obtained
// from validate(), and only when validation passed — tracing and simulation
// take a ValidatedEvaluator, so an evaluator that failed (or was never
// checked) cannot be used by mistake.
#pragma once

#include "backlash/numeric/evaluator.hpp"

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace backlash::numeric {

struct ValidationOptions {
  double tolerance = 1e-9;         ///< max abs error allowed per state
  double odeint_tolerance = 1e-12; ///< abs = rel tolerance of the reference
  std::vector<double> dtheta_m0_grid{-2, -1, -0.3, -0.01, -1e-4, -1e-7, 1e-7, 1e-4, 0.01, 0.3, 1, 2};
  /// Contact-mode initial states (θo0, θ̇o0); empty → steps of ±1, ±1e-3 toward θR,
  /// (θR + 0.5, −0.3) and points of the separation line.
  std::vector<std::pair<double, double>> contact_starts;
  int time_points = 400;           ///< uniform samples over the horizon (plus early log-spaced ones)
  double time_constants = 10;      ///< horizon in time constants of the slowest decaying pole
  double max_horizon = 200;        ///< cap on the horizon
  double max_rate_units = 400;     ///< cap on the horizon in units of 1/(the fastest rate of the modes)
  /// Compare the centred copy (θR = 0) of a parametric or direct evaluator — the copy the
  /// simulators run (in_error_coordinates) — instead of the evaluator itself, whose angles carry
  /// |θR|·ε of rounding (θR = 1e7: 1e-9 rad, the whole tolerance).  The facade's models do.
  bool error_coordinates = false;
};

struct StateError {
  std::string state;           ///< theta_m, dtheta_m, theta_L, dtheta_L, gap, theta_o, dtheta_o, cot_phi
  bool contact = false;        ///< contact-mode state (the location is θo0, θ̇o0 instead of θ̇m0)
  double max_abs_error = 0;
  double max_scaled_error = 0; ///< max of |error| / max(1, the trajectory's size in this state): the gate's measure
  double scale = 1;            ///< max(1, size) where max_scaled_error occurs
  double at_t = 0;
  double at_dtheta_m0 = 0;     ///< free mode: θ̇m0 where the maximum occurs
  double at_theta_o0 = 0, at_dtheta_o0 = 0;  ///< contact mode: initial state where it occurs
  long samples = 0;
  bool passed = false;
};

enum class ValidationStatus { Passed, Failed };
const char* to_string(ValidationStatus status);

struct ValidationReport {
  std::string evaluator;       ///< SegmentEvaluator::name()
  std::string kind;            ///< "case", "parametric", "direct"
  BranchSelection branches;
  double tolerance = 0;
  double free_horizon = 0, contact_horizon = 0;  ///< horizons before recombination cut-offs
  int free_trajectories = 0, contact_trajectories = 0;
  std::vector<StateError> states;
  ValidationStatus status = ValidationStatus::Failed;
  bool passed() const { return status == ValidationStatus::Passed; }
  /// One line per state: "theta_m  max |error| 3.1e-13 at t = 4.2, dtheta_m0 = 2  pass".
  std::string summary() const;
  /// The failing states on one line: "theta_m max |error| 3.1e-09 > 1e-09; gap ..." (empty when passed).
  std::string failures() const;
};

/// Thrown when an evaluator that did not pass validation is asked for.
class ValidationFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ValidationResult;
class ValidatedEvaluator;

/// The same validated evaluator in error coordinates (θR = 0), for the numerics: angles of
/// size |θR| would cost the gap θL − θm its digits (θR = 1e4 leaves 2e-12 rad of rounding
/// noise, enough to fake impacts).  The parametric and per-branch layers compute θ − θR and add
/// θR back, and the gate compares in error coordinates, so its verdict carries over.  Nothing
/// when θR = 0 or the evaluator is a generated case (its θR is folded into the closed forms).
std::optional<ValidatedEvaluator> in_error_coordinates(const ValidatedEvaluator& evaluator);

/// Run the gate.  Never throws for a failing evaluator: the result says so.
ValidationResult validate(EvaluatorPtr evaluator, const ValidationOptions& options = {});

/// An evaluator that passed the gate, with its report.  Only validate() makes one.
class ValidatedEvaluator {
 public:
  const SegmentEvaluator& evaluator() const { return *evaluator_; }
  const EvaluatorPtr& shared() const { return evaluator_; }
  const ValidationReport& report() const { return report_; }
  const Parameters& parameters() const { return evaluator_->parameters(); }
  double cot_phi() const { return evaluator_->cot_phi(); }
  FreeState free_state(double t, double dtheta_m0) const { return evaluator_->free_state(t, dtheta_m0); }
  ContactState contact_state(double t, double theta_o0, double dtheta_o0) const {
    return evaluator_->contact_state(t, theta_o0, dtheta_o0);
  }

 private:
  friend ValidationResult validate(EvaluatorPtr evaluator, const ValidationOptions& options);
  friend class ValidatedParametricFamily;  // validated_family.hpp: the parametric layer validated per branch
  friend std::optional<ValidatedEvaluator> in_error_coordinates(const ValidatedEvaluator& evaluator);
  ValidatedEvaluator(EvaluatorPtr evaluator, ValidationReport report)
      : evaluator_(std::move(evaluator)), report_(std::move(report)) {}
  EvaluatorPtr evaluator_;
  ValidationReport report_;
};

class ValidationResult {
 public:
  ValidationStatus status() const { return report_.status; }
  bool passed() const { return report_.passed(); }
  const ValidationReport& report() const { return report_; }
  /// The validated evaluator; throws ValidationFailed (naming the failing
  /// states) when validation did not pass.
  const ValidatedEvaluator& evaluator() const;

 private:
  friend ValidationResult validate(EvaluatorPtr evaluator, const ValidationOptions& options);
  ValidationReport report_;
  std::optional<ValidatedEvaluator> validated_;
};

/// The horizons used by validate() (before recombination cut-offs).
double free_horizon(const Parameters& p, const ValidationOptions& options = {});
double contact_horizon(const Parameters& p, const ValidationOptions& options = {});

}  // namespace backlash::numeric
