// `backlash discrepancy --model M.toml --data D.csv [--step A] [--json] [--out DIR]` —
// where the model and the measurement disagree, the missing effect named and
// fitted, the gap before and after (discrepancy/discrepancy.hpp, docs/discrepancy.md).
#include "commands.hpp"

#include "backlash/discrepancy/discrepancy.hpp"
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
  std::optional<std::string> step;
  std::string threads = "2";
  bool json = false;
};

void run_discrepancy(const DiscrepancyOptions& o) {
  const model::CaseSpec spec = model::load_case(o.model);
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
  measurements::MeasuredRecord data;
  try {
    data = measurements::read_measured_csv(o.data);
  } catch (const measurements::MeasuredDataError& error) {
    throw UsageError(error.what());
  }
  discrepancy::DiscrepancyOptions options;
  options.threads = static_cast<int>(threads);
  const discrepancy::DiscrepancyResult r = discrepancy::find_discrepancy(spec, data, step, options);
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
  command->add_option("--data", options->data, "the measured record: CSV with t, theta_out [, theta_motor, theta_load]")->required();
  command->add_option("--step", options->step, "the step A (default: the model's [experiment] step)");
  command->add_option("--out", options->out, "write the page, figures, JSON and corrected model to this folder");
  command->add_option("--threads", options->threads, "candidates fitted in parallel (default 2)");
  command->add_flag("--json", options->json, "print one JSON document");
  command->callback([options] { run_discrepancy(*options); });
}

}  // namespace backlash::cli
