// discrepancy.cpp — a model against a measured record: the step workflow or the
// measured-drive one (chosen by the model's experiment), and records from files or arrays.
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include "backlash/measurements/emps.hpp"
#include "backlash/numeric/scales.hpp"

#include <cmath>

namespace backlash::api {

using detail::appendf;

namespace {

using detail::number_text;

/// The named effects, one line each: "  NAME  p = v ± u ...  (ΔBIC d)".
void append_effects(std::string& out, const std::vector<discrepancy::Candidate>& effects) {
  for (const discrepancy::Candidate& c : effects) {
    appendf(out, "  %-14s", c.effect.c_str());
    for (const discrepancy::Parameter& p : c.parameters)
      appendf(out, "  %s = %.6g ± %.2g", p.name.c_str(), p.value, p.uncertainty);
    appendf(out, "  (ΔBIC %.1f)\n", c.delta_bic);
  }
}

/// A drive with a gap: the parameter corrections (the backlash first) and the lost motion.
void append_two_body(std::string& out, const discrepancy::TwoBodyFindings& two) {
  appendf(out, "  drive with a gap, %s; %d reversals of the motor\n", two.method.c_str(), two.reversals_count);
  for (const discrepancy::ParameterCorrection& c : two.parameter_corrections)
    appendf(out, "  %-14s  %.6g -> %.6g ± %.2g  (x%.4g)\n", c.key.c_str(), c.nominal, c.fitted, c.uncertainty, c.ratio);
  if (two.rigid) appendf(out, "  a rigid drive: the backlash is not distinguishable from 0 (within 3 sigma)\n");
}

}  // namespace

measurements::MeasuredRecord read_record(const std::filesystem::path& file) {
  if (file.extension() == ".mat") return measurements::to_measured_record(measurements::read_emps(file));
  return measurements::read_measured_csv(file);
}

measurements::MeasuredRecord make_record(std::vector<double> t, std::vector<double> theta_out,
                                         std::optional<std::vector<double>> theta_motor,
                                         std::optional<std::vector<double>> theta_load,
                                         std::optional<std::vector<double>> drive, const std::string& name) {
  measurements::MeasuredRecord record;
  record.t = std::move(t);
  record.theta_out = std::move(theta_out);
  record.theta_motor = std::move(theta_motor);
  record.theta_load = std::move(theta_load);
  record.drive = std::move(drive);
  record.source = name;
  // The CSV contract, checked by its own reader: the shortest round-trip form makes the
  // text give back every value bit for bit.
  std::string text;
  try {
    text = measurements::format_measured_csv(record);
  } catch (const measurements::MeasuredDataError& error) {
    // The writer's check says "cannot write: ..."; for arrays nothing is written.
    std::string problem = error.problem();
    if (const std::string prefix = "cannot write: "; problem.rfind(prefix, 0) == 0) problem.erase(0, prefix.size());
    throw measurements::MeasuredDataError(name, 0, error.column(), problem);
  }
  return measurements::parse_measured_csv(text, name);
}

discrepancy::Status Discrepancy::status() const { return step_ ? step_->status : drive_->status; }

Discrepancy discrepancy(const Case& model, const measurements::MeasuredRecord& data, const DiscrepancyRequest& request) {
  const model::CaseSpec& spec = model.spec();
  measurements::require_computable(data);  // a sample beyond 1e100 is bad input, named by its line
  if (request.validation) measurements::require_computable(*request.validation);
  Discrepancy out;
  out.model_ = spec;
  if (spec.experiment && spec.experiment->kind == model::ExperimentKind::Drive) {
    if (request.step) throw BadInput("step", "the model's experiment is a measured drive, which has no step");
    discrepancy::DriveOptions options;
    if (request.cutoff) {
      if (!(*request.cutoff > 0) || !std::isfinite(*request.cutoff))
        throw BadInput("cutoff", "expected a frequency > 0 [Hz], got '" + number_text(*request.cutoff) + "'");
      options.cutoff = *request.cutoff;
    }
    if (request.window) {
      if (!(*request.window > 0) || !std::isfinite(*request.window))
        throw BadInput("window", "expected a duration > 0 [s], got '" + number_text(*request.window) + "'");
      options.window = *request.window;
    }
    out.window_ = options.window;
    try {
      out.drive_ = discrepancy::find_drive_discrepancy(spec, data, options,
                                                       request.validation ? &*request.validation : nullptr);
    } catch (const std::invalid_argument& error) {
      throw BadInput("", error.what());
    }
    return out;
  }
  if (request.validation) throw BadInput("validation", "only for a measured-drive model ([experiment] kind = \"drive\")");
  if (request.cutoff) throw BadInput("cutoff", "only for a measured-drive model ([experiment] kind = \"drive\")");
  if (request.window) throw BadInput("window", "only for a measured-drive model ([experiment] kind = \"drive\")");
  double step = 0;
  if (request.step) {
    step = *request.step;
    if (!std::isfinite(step)) throw BadInput("step", "not finite, got " + number_text(step));
    if (step == 0) throw BadInput("step", "must not be 0");
  } else if (spec.experiment && spec.experiment->kind == model::ExperimentKind::Step) {
    step = model::to_double(spec.experiment->step);
  } else {
    throw model::CaseFileError(spec.source, 1, "experiment.step",
                               "the model has no [experiment] step and no step was given: there is nothing to compare");
  }
  // A step whose motion double precision cannot resolve against the backlash is refused before
  // any work, as simulate refuses it (numeric/scales.hpp).
  const std::string what = request.step ? "the step " + number_text(step) : "the step of the case file";
  if (const auto problem = numeric::resolution_problem(numeric::parameters_of(spec), std::fabs(step), what))
    throw BadInput("step", *problem);
  if (request.threads < 1 || request.threads > 256)
    throw BadInput("threads", "expected an integer from 1 to 256, got " + std::to_string(request.threads));
  if (data.theta_out.size() != data.size())  // a logged drive's record may leave it out (measured_record.hpp)
    throw measurements::MeasuredDataError(data.source, 1, "theta_out", "missing required column (the step workflow compares the measured shaft)");
  discrepancy::DiscrepancyOptions options;
  options.threads = request.threads;
  options.progress = request.progress;
  out.step_value_ = step;
  try {
    out.step_ = discrepancy::find_discrepancy(spec, data, step, options);
  } catch (const std::invalid_argument& error) {  // a record the model cannot be compared with
    throw BadInput(data.source.empty() ? "data" : data.source.string(), error.what());
  }
  return out;
}

std::string Discrepancy::text(const std::string& data, const std::string& validation) const {
  std::string out;
  if (drive_) {
    const discrepancy::DriveDiscrepancyResult& r = *drive_;
    if (r.two_body)  // the two-body fits count no solves (docs/discrepancy.md): the cut-off alone
      appendf(out, "%s against %s (measured drive): %s (cut-off %.4g Hz)\n", model_.id.c_str(), data.c_str(),
              discrepancy::to_string(r.status), r.cutoff);
    else
      appendf(out, "%s against %s (measured drive): %s (cut-off %.4g Hz, %d least-squares solves, %.2f s)\n",
              model_.id.c_str(), data.c_str(), discrepancy::to_string(r.status), r.cutoff, r.least_squares, r.seconds);
    for (const discrepancy::Parameter& p : r.corrected_nominal.empty() ? r.nominal_fit : r.corrected_nominal)
      appendf(out, "  %-14s  %.6g ± %.2g\n", p.name.c_str(), p.value, p.uncertainty);
    append_effects(out, r.effects);
    if (r.status == discrepancy::Status::Unexplained && !r.rounds.empty() && !r.rounds.front().empty())
      appendf(out, "  best candidate (not decisive): %s, torque RMS %.4g\n", r.rounds.front().front().effect.c_str(),
              r.rounds.front().front().rms);
    appendf(out, "  torque RMS: %.4g before (best nominal), %.4g after (noise level %.3g)\n", r.rms_before, r.rms_after,
            r.noise);
    if (r.two_body) {
      append_two_body(out, *r.two_body);
      return out;
    }
    appendf(out, "  position RMS over %d windows of %.3g s: %.4g before, %.4g after\n", r.estimation.windows, window_,
            r.estimation.position_rms_nominal, r.estimation.position_rms_corrected);
    if (r.validation)
      appendf(out, "  validation %s: torque RMS %.4g before, %.4g after; position RMS %.4g before, %.4g after\n",
              validation.c_str(), r.validation->torque_rms_nominal, r.validation->torque_rms_corrected,
              r.validation->position_rms_nominal, r.validation->position_rms_corrected);
    return out;
  }
  const discrepancy::DiscrepancyResult& r = *step_;
  appendf(out, "%s against %s: %s (noise %.3g, %d simulations, %.2f s)\n", model_.id.c_str(), data.c_str(),
          discrepancy::to_string(r.status), r.noise, r.simulations, r.seconds);
  append_effects(out, r.effects);
  for (const discrepancy::ParameterCorrection& c : r.parameter_corrections)
    appendf(out, "  %-14s  %.6g -> %.6g ± %.2g  (x%.4g)%s\n", c.key.c_str(), c.nominal, c.fitted, c.uncertainty, c.ratio,
            c.given_free ? "  [fit] free" : "");
  if (!r.alternatives.empty())
    appendf(out, "  ambiguous: %s or %s; to tell them apart: %s\n", r.alternatives[0].effect.c_str(),
            r.alternatives[1].effect.c_str(), r.distinguishing_experiment.c_str());
  if (r.noise_estimate.correlation > 0 || !r.outliers.empty())
    appendf(out, "  noise: correlated over tau_int %.3g samples (n_eff %.4g); %zu outliers given no weight\n",
            r.noise_estimate.tau_int, r.noise_estimate.n_eff, r.outliers.size());
  if (!r.reason.empty()) appendf(out, "  %s\n", r.reason.c_str());
  if (r.status == discrepancy::Status::Unexplained && !r.rounds.empty() && !r.rounds.front().empty())
    appendf(out, "  best candidate (not decisive): %s, RMS %.3g\n", r.rounds.front().front().effect.c_str(),
            r.rounds.front().front().rms);
  appendf(out, "  RMS of theta_out: %.4g before, %.4g after (%.2f and %.2f noise sigmas)\n", r.rms_before, r.rms_after,
          r.rms_before / r.noise, r.rms_after / r.noise);
  return out;
}

}  // namespace backlash::api
