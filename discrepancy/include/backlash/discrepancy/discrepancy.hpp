// backlash/discrepancy/discrepancy.hpp — where a simulation and a measurement
// disagree, which effect the model is missing, how big it is, and the model
// corrected (docs/discrepancy.md).
//
// Given a nominal model (a case file, possibly with effects already in it) and a
// measured step response (the project's CSV: t, theta_out [, theta_motor,
// theta_load]), the workflow
//   1. simulates the model on the record's own time grid and estimates the noise of
//      theta_out from the record alone: σ = MAD(Δ⁴y)/(0.6745·√70) — the fourth
//      difference removes any smooth motion, and a few kinks (impacts) do not move
//      a median;
//   2. localises the disagreement: the residual per region between the simulated
//      events (contact, free flight, mesh, rest), the first time it leaves the
//      noise band (|r| > 3σ over 5 consecutive samples), and features of the
//      record against the model (overshoot, final error, decay rate, cycle
//      amplitude and period);
//   3. names the missing effect: every effect of the vocabulary (the effects of the
//      table of effects, model/effect_table.hpp, in their STEP_RANK order, and
//      backlash_size) is added to the model in turn and fitted on
//      seven of ten blocks of the record (the third, sixth and ninth are held out,
//      so that they see the transient and the end alike) — a bracketing scan over
//      the parameter's range, then, event timing making the cost non-smooth,
//      Brent's minimisation in the best bracket for one parameter or Ceres
//      (Levenberg–Marquardt, central differences) from the best points for two —
//      and scored by its BIC on the fitted samples and its RMS on the held-out ones.
//      An effect is named when it is decisive on both: ΔBIC < −decisive_bic against
//      the current model, and a held-out RMS below decisive_holdout × the current
//      one (or, where the model already meets the held-out samples at the noise
//      level, not above them) — and none of its parameters pinned at an end of its range
//      (a mesh at the stiffest end is a rigid gear, not a compliance).  The winner is refitted
//      on the whole record (uncertainty from Ceres's covariance, scaled by the
//      residual variance), added, and the search repeats for a second effect, until
//      the residual is at the noise level or nothing is decisive;
//   4. reports the named effects with their parameters and uncertainties, the RMS
//      before and after (total and per region), the candidates' scores, and the
//      corrected model.
//   Nominal parameters are candidates too (motor.J, motor.F, load.J, load.F, K, reference, and the
//   backlash — still tried under its old name backlash_size): judged by the same rule and
//   reported apart as parameter corrections; [fit] free lists those fitted first, [fit] fixed
//   those never corrected.  The noise is estimated with its correlation (an AR(1) fitted to
//   the lagged fourth differences of the nominal model's residual) and the BIC counts
//   n_eff = n/τ_int residuals; isolated spikes are listed as outliers and given no weight.
// Statuses (docs/discrepancy.md): effect_found (effects named, the corrected model meets the record
// at the noise level), parameters_corrected (corrections of nominal parameters alone do),
// partly_explained (something named, a gap above the noise remains), ambiguous (two explanations
// fit alike: both listed, with the experiment that would tell them apart), no_discrepancy (the
// model already fits to the noise level), unexplained (a gap no candidate closes decisively).
#pragma once

#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace backlash::discrepancy {

enum class Status { EffectFound, NoDiscrepancy, Unexplained, ParametersCorrected, PartlyExplained, Ambiguous };
const char* to_string(Status status);

/// The effects the workflow can name (effects.md), in the order they are tried.
const std::vector<std::string>& vocabulary();

/// The nominal parameters a step record may correct, as [fit] free / fixed name them
/// (model::fittable_parameters() but "backlash", which is tried as the candidate backlash_size).
const std::vector<std::string>& parameter_candidates();

/// True for a candidate that corrects a nominal parameter (a key of parameter_candidates(), or
/// backlash_size — the backlash correction's deprecated name as an effect, kept for one release).
bool is_parameter_correction(const std::string& candidate);

struct Parameter {
  std::string name;  ///< "torque", "e", "limit", "stiffness", "damping", "tau", "backlash"
  double value = 0;
  double uncertainty = NAN;  ///< one standard deviation (from the fit's covariance)
};

/// One candidate effect fitted to the record.
struct Candidate {
  std::string effect;
  std::vector<Parameter> parameters;
  double rms = 0;          ///< on the whole record
  double rms_fit = 0;      ///< weighted (σ = 1), on the fitted samples
  double rms_holdout = 0;  ///< weighted (σ = 1), on the held-out samples
  double bic = 0;          ///< on the fitted samples: n·ln(SSE/n) + k·ln n
  double delta_bic = 0;    ///< against the model it was added to
  bool decisive = false;
  bool at_range_edge = false;  ///< a parameter pinned at an end of its range (then never decisive)
  int simulations = 0;     ///< simulations its fit used
  double seconds = 0;      ///< time its fit took
  std::string failure;     ///< why its fit failed or stopped early, if it did
  std::string no_sigma;    ///< a named effect: why a parameter's σ is not reported (empty when every σ is)
};

/// A stretch of the record between events of the simulated model.
struct Region {
  double t_start = 0, t_end = 0;
  std::string kind;  ///< "contact", "free", "mesh", "rest"
  int samples = 0;
  double rms_before = 0, rms_after = 0;
};

/// Features of one trace (measured or simulated).
struct Features {
  double overshoot = NAN;        ///< max (θo − θR)·sign(step) [rad]
  double final_error = NAN;      ///< mean θo − θR over the last tenth of the record
  double decay_rate = NAN;       ///< ln of successive |θo − θR| peak ratios per second (< 0: decaying)
  double cycle_amplitude = NAN;  ///< half the peak-to-peak over the record's last third
  double cycle_period = NAN;     ///< from the crossings of the last third's mean
};

/// A nominal parameter corrected by the record.
struct ParameterCorrection {
  std::string key;           ///< "motor.J", "motor.F", "load.J", "load.F", "K", "backlash", "reference"
  double nominal = 0;        ///< the case file's value
  double fitted = 0;
  double uncertainty = NAN;  ///< one standard deviation
  double ratio = 1;          ///< fitted / nominal (NaN for a nominal 0)
  bool given_free = false;   ///< listed in [fit] free (fitted first)
};

/// A sample the fit gives no weight: an isolated spike (docs/discrepancy.md, "Noise").
struct Outlier {
  std::size_t index = 0;  ///< the sample's row in the record, from 0
  double t = 0;
  std::string column;  ///< "theta_out", "theta_motor", "theta_load"
  double size = 0;     ///< its distance from its neighbours' median, in units of σ
};

/// The noise of theta_out as estimated from the nominal model's residual.
struct NoiseEstimate {
  double sigma = 0;        ///< its level [rad]
  double white_sigma = 0;  ///< the white-noise rule alone (MAD(Δ⁴y)/(0.6745·√70)) [rad]
  double correlation = 0;  ///< the AR(1) coefficient a per sample (0: white)
  double tau_int = 1;      ///< (1 + a)/(1 − a) [samples]
  double n_eff = 0;        ///< n/τ_int of the fitted samples, the n of the BIC
  double at_noise = 1.15;  ///< the RMS (in σ) at or below which a model meets the record
};

struct DiscrepancyOptions {
  double holdout_fraction = 0.3;  ///< the blocks held out of every fit (every third of ten)
  double decisive_bic = 10;       ///< a "very strong" BIC difference (Kass & Raftery)
  double decisive_holdout = 0.8;  ///< the held-out RMS must shrink at least to this fraction
  double noise_level = 1.15;      ///< "at the noise level": RMS ≤ this × σ
  int max_effects = 3;
  std::vector<std::string> candidates = vocabulary();  ///< which effects to try
  int threads = 2;                ///< candidates fitted in parallel (numeric work: threads)
  /// A candidate's fit stops with its best point when its work — 1000 per simulation plus the
  /// events it simulated — reaches this (a stiff mesh can be slow).  A count, not a clock, so that
  /// the result is the same on any machine; 3e6 is about 3 s of a stiff mesh's fit here.
  long candidate_work = 3'000'000;
  /// The whole search stops (status reason "the work budget ... was reached") when the work of
  /// all its fits reaches this: sized so that a step record of a few thousand samples answers in
  /// at most 20 s on one core (bench/discrepancy_real_records.sh prints the CPU seconds).
  /// A simulation's work is calibrated against the clock (docs/discrepancy.md, "Work budget"): a
  /// delayed model, integrated numerically, counts 400 more per radian of the servo's oscillation
  /// over the record (about 12000 for a delayed case V over 30 s) and 1300 per radian of a
  /// compliant mesh's.
  long total_work = 80'000'000;
  /// The nominal parameters tried as corrections (default: all; [fit] fixed removes some).
  std::vector<std::string> parameters = parameter_candidates();
  double ambiguity_bic = 2;       ///< two explanations whose BIC differ by less are alike
  /// Set: called as each candidate of a round is fitted, `done` of the round's `total`
  /// candidates (from the worker threads, serialised); a new round starts again from 0.
  std::function<void(long done, long total)> progress{};
};

struct DiscrepancyResult {
  Status status = Status::NoDiscrepancy;
  double noise = 0;                  ///< σ of theta_out estimated from the record
  double rms_before = 0, rms_after = 0;  ///< of theta_out [rad]
  double gap_before = 0, gap_after = 0;  ///< RMS over every measured column, in units of each column's σ
  double first_departure = NAN;      ///< first time the residual leaves the noise band (NaN: never)
  std::vector<Candidate> effects;    ///< named, in the order found (backlash_size included: deprecated)
  std::vector<ParameterCorrection> parameter_corrections;  ///< nominal parameters corrected
  NoiseEstimate noise_estimate;
  std::vector<Outlier> outliers;
  /// Ambiguous: the explanations that fit alike (the one adopted first), and the experiment that
  /// would tell them apart.
  std::vector<Candidate> alternatives;
  std::string distinguishing_experiment;
  /// Why the search stopped short when it did (the work budget reached), else empty.
  std::string reason;
  /// Partly explained: where the corrected model still leaves the noise band (NaN: nowhere).
  double remaining_departure = NAN;
  std::vector<std::vector<Candidate>> rounds;  ///< every candidate of every round, best first
  std::vector<Region> regions;
  Features measured, nominal, corrected;
  std::vector<numeric::SimulationEvent> nominal_events, corrected_events;
  numeric::Parameters parameters;    ///< of the corrected model
  numeric::Effects corrected_effects;
  std::vector<double> t, theta_measured, theta_nominal, theta_corrected;
  int simulations = 0;
  long work = 0;  ///< the simulations' work as the budget counts it (DiscrepancyOptions::total_work)
  double seconds = 0;
};

/// The whole workflow.  Throws std::invalid_argument for a record the model cannot be
/// compared with (too few samples before t_end, a step of 0).
DiscrepancyResult find_discrepancy(const model::CaseSpec& model, const measurements::MeasuredRecord& data, double step,
                                   const DiscrepancyOptions& options = {});

/// σ of a uniformly or irregularly sampled smooth signal plus noise, from the record alone.
double estimate_noise(const std::vector<double>& y);

/// The features of a trace.
Features features_of(const std::vector<double>& t, const std::vector<double>& theta, double theta_R, double step);

// The result as files — the page, its figures, the JSON, the corrected case file — is
// written apart from the computation: reports/discrepancy_pages.hpp.

}  // namespace backlash::discrepancy
