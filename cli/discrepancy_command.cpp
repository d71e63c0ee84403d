// `backlash discrepancy --model M.toml --data D.csv [--step A] [--json] [--out DIR]` —
// where the model and the measurement disagree, the missing effect named and
// fitted, the gap before and after (discrepancy/discrepancy.hpp, docs/discrepancy.md).
// A measured-drive model ([experiment] kind = "drive") runs the torque-domain workflow
// (discrepancy/measured_drive.hpp), with [--validate D2.csv] [--cutoff HZ] [--window S];
// a .mat record (EMPS) is read as `backlash import` would convert it.
#include "commands.hpp"

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/reports/output_directory.hpp"
#include "numeric_case.hpp"

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

namespace backlash::cli {

namespace {

struct DiscrepancyOptions {
  std::string model, data, out;
  std::optional<std::string> step, validate, cutoff, window;
  std::string threads = "2";
  bool json = false;
};

// A record: the project's CSV, or an EMPS .mat converted as `backlash import` does.
measurements::MeasuredRecord read_record(const std::string& file) {
  const std::filesystem::path path(file);
  if (path.extension() == ".mat") return measurements::to_measured_record(measurements::read_emps(path));
  return measurements::read_measured_csv(path);
}

void run_drive_discrepancy(const DiscrepancyOptions& o, const model::CaseSpec& spec) {
  if (o.step) throw UsageError("--step: the model's experiment is a measured drive, which has no step");
  discrepancy::DriveOptions options;
  if (o.cutoff) {
    options.cutoff = parse_number(*o.cutoff, "--cutoff");
    if (!(options.cutoff > 0)) throw UsageError("--cutoff: expected a frequency > 0 [Hz], got '" + *o.cutoff + "'");
  }
  if (o.window) {
    options.window = parse_number(*o.window, "--window");
    if (!(options.window > 0)) throw UsageError("--window: expected a duration > 0 [s], got '" + *o.window + "'");
  }
  if (!o.out.empty()) reports::check_output_target(o.out);
  const measurements::MeasuredRecord data = read_record(o.data);
  std::optional<measurements::MeasuredRecord> validation;
  if (o.validate) validation = read_record(*o.validate);
  discrepancy::DriveDiscrepancyResult r;
  try {
    r = discrepancy::find_drive_discrepancy(spec, data, options, validation ? &*validation : nullptr);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());
  }
  const std::string data_name = std::filesystem::path(o.data).filename().string();
  const std::string validation_name = o.validate ? std::filesystem::path(*o.validate).filename().string() : "";
  if (!o.out.empty()) {
    reports::StagedDirectory staged(o.out);
    for (const auto& [name, content] : discrepancy::drive_report_files(spec, data_name, validation_name, r))
      staged.write(name, content);
    staged.commit();
  }
  if (o.json) {
    std::cout << discrepancy::drive_to_json(spec, r);
    return;
  }
  std::printf("%s against %s (measured drive): %s (cut-off %.4g Hz, %d least-squares solves, %.2f s)\n", spec.id.c_str(),
              o.data.c_str(), discrepancy::to_string(r.status), r.cutoff, r.least_squares, r.seconds);
  for (const discrepancy::Parameter& p : r.corrected_nominal.empty() ? r.nominal_fit : r.corrected_nominal)
    std::printf("  %-14s  %.6g ± %.2g\n", p.name.c_str(), p.value, p.uncertainty);
  for (const discrepancy::Candidate& c : r.effects) {
    std::printf("  %-14s", c.effect.c_str());
    for (const discrepancy::Parameter& p : c.parameters) std::printf("  %s = %.6g ± %.2g", p.name.c_str(), p.value, p.uncertainty);
    std::printf("  (ΔBIC %.1f)\n", c.delta_bic);
  }
  if (r.status == discrepancy::Status::Unexplained && !r.rounds.empty() && !r.rounds.front().empty())
    std::printf("  best candidate (not decisive): %s, torque RMS %.4g\n", r.rounds.front().front().effect.c_str(),
                r.rounds.front().front().rms);
  std::printf("  torque RMS: %.4g before (best nominal), %.4g after (noise level %.3g)\n", r.rms_before, r.rms_after, r.noise);
  std::printf("  position RMS over %d windows of %.3g s: %.4g before, %.4g after\n", r.estimation.windows, options.window,
              r.estimation.position_rms_nominal, r.estimation.position_rms_corrected);
  if (r.validation)
    std::printf("  validation %s: torque RMS %.4g before, %.4g after; position RMS %.4g before, %.4g after\n",
                validation_name.c_str(), r.validation->torque_rms_nominal, r.validation->torque_rms_corrected,
                r.validation->position_rms_nominal, r.validation->position_rms_corrected);
  if (!o.out.empty()) std::printf("  written to %s/discrepancy.md\n", o.out.c_str());
}

void run_discrepancy(const DiscrepancyOptions& o) {
  const model::CaseSpec spec = model::load_case(o.model);
  if (spec.experiment && spec.experiment->kind == model::ExperimentKind::Drive) return run_drive_discrepancy(o, spec);
  for (const auto& [given, name] : {std::pair{&o.validate, "--validate"}, {&o.cutoff, "--cutoff"}, {&o.window, "--window"}})
    if (*given) throw UsageError(std::string(name) + ": only for a measured-drive model ([experiment] kind = \"drive\")");
  double step = 0;
  if (o.step) {
    step = parse_number(*o.step, "--step");
    if (step == 0) throw UsageError("--step: must not be 0");
  } else if (spec.experiment && spec.experiment->kind == model::ExperimentKind::Step) {
    step = model::to_double(spec.experiment->step);
  } else {
    throw model::CaseFileError(spec.source, 1, "experiment.step",
                               "the model has no [experiment] step and --step was not given: there is nothing to compare");
  }
  const double threads = parse_number(o.threads, "--threads");
  if (threads != static_cast<int>(threads) || threads < 1 || threads > 256)
    throw UsageError("--threads: expected an integer from 1 to 256, got '" + o.threads + "'");
  if (!o.out.empty()) reports::check_output_target(o.out);
  const measurements::MeasuredRecord data = read_record(o.data);
  discrepancy::DiscrepancyOptions options;
  options.threads = static_cast<int>(threads);
  discrepancy::DiscrepancyResult r;
  try {
    r = discrepancy::find_discrepancy(spec, data, step, options);
  } catch (const std::invalid_argument& error) {  // a record the model cannot be compared with
    throw UsageError(o.data + ": " + error.what());
  }
  if (!o.out.empty()) {
    reports::StagedDirectory staged(o.out);
    for (const auto& [name, content] :
         discrepancy::report_files(spec, std::filesystem::path(o.data).filename().string(), r, step))
      staged.write(name, content);
    staged.commit();
  }
  if (o.json) {
    std::cout << discrepancy::to_json(spec, r, step);
    return;
  }
  std::printf("%s against %s: %s (noise %.3g, %d simulations, %.2f s)\n", spec.id.c_str(), o.data.c_str(),
              discrepancy::to_string(r.status), r.noise, r.simulations, r.seconds);
  for (const discrepancy::Candidate& c : r.effects) {
    std::printf("  %-14s", c.effect.c_str());
    for (const discrepancy::Parameter& p : c.parameters) std::printf("  %s = %.6g ± %.2g", p.name.c_str(), p.value, p.uncertainty);
    std::printf("  (ΔBIC %.1f)\n", c.delta_bic);
  }
  if (r.status == discrepancy::Status::Unexplained && !r.rounds.empty() && !r.rounds.front().empty())
    std::printf("  best candidate (not decisive): %s, RMS %.3g\n", r.rounds.front().front().effect.c_str(),
                r.rounds.front().front().rms);
  std::printf("  RMS of theta_out: %.4g before, %.4g after (%.2f and %.2f noise sigmas)\n", r.rms_before, r.rms_after,
              r.rms_before / r.noise, r.rms_after / r.noise);
  if (!o.out.empty()) std::printf("  written to %s/discrepancy.md\n", o.out.c_str());
}

}  // namespace

void register_discrepancy_command(CLI::App& app) {
  auto options = std::make_shared<DiscrepancyOptions>();
  CLI::App* command =
      app.add_subcommand("discrepancy", "Where a model and a measured step response disagree: the missing effect, named and fitted");
  command->add_option("--model", options->model, "the nominal model: a case file (or I..VIII)")->required();
  command->add_option("--data", options->data, "the measured record: CSV with t, theta_out [, theta_motor, theta_load, drive], or an EMPS .mat")->required();
  command->add_option("--step", options->step, "the step A (default: the model's [experiment] step)");
  command->add_option("--out", options->out, "write the page, figures, JSON and corrected model to this folder");
  command->add_option("--threads", options->threads, "candidates fitted in parallel (default 2)");
  command->add_option("--validate", options->validate,
                      "measured drive: a second record of the same drive, scored with the fitted models (not refitted)");
  command->add_option("--cutoff", options->cutoff, "measured drive: the low-pass cut-off [Hz] (default: from the position's spectrum)");
  command->add_option("--window", options->window, "measured drive: position-prediction windows [s] (default 0.5)");
  command->add_flag("--json", options->json, "print one JSON document");
  command->callback([options] { run_discrepancy(*options); });
}

}  // namespace backlash::cli
