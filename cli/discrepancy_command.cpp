// `backlash discrepancy --model M.toml --data D.csv [--step A] [--json] [--out DIR]` —
// where the model and the measurement disagree, the missing effect named and
// fitted, the gap before and after (docs/discrepancy.md), through the facade
// (api::discrepancy; its JSON and files: api/discrepancy_pages.hpp).  A measured-drive model ([experiment] kind = "drive") runs the
// torque-domain workflow, with [--validate D2.csv] [--cutoff HZ] [--window S]; a .mat
// record (EMPS) is read as `backlash import` would convert it.
#include "commands.hpp"
#include "flags.hpp"
#include "progress.hpp"

#include "backlash/api/backlash.hpp"
#include "backlash/api/discrepancy_pages.hpp"
#include "backlash/output/staged_directory.hpp"
#include "backlash/output/target.hpp"

#include <filesystem>
#include <memory>
#include <optional>

namespace backlash::cli {

namespace {

struct DiscrepancyOptions {
  std::string model, data, out;
  std::optional<std::string> step, validate, cutoff, window;
  std::string threads = "2";
  bool json = false;
  bool no_progress = false;
};

api::DiscrepancyRequest request_of(const DiscrepancyOptions& o) {
  api::DiscrepancyRequest request;
  if (o.step) request.step = parse_number(*o.step, "--step");
  if (o.cutoff) request.cutoff = parse_number(*o.cutoff, "--cutoff");
  if (o.window) request.window = parse_number(*o.window, "--window");
  request.threads = parse_whole_int(o.threads, "--threads");
  request.progress = progress_bar(o.no_progress);
  return request;
}

std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

void run_discrepancy(const DiscrepancyOptions& o) {
  const api::Case model = api::load(o.model);
  api::DiscrepancyRequest request = request_of(o);
  if (!o.out.empty()) output::check_target(o.out, output::Target::folder);
  const measurements::MeasuredRecord data = api::read_record(o.data);
  if (o.validate) request.validation = api::read_record(*o.validate);
  const api::Discrepancy found = api::discrepancy(model, data, request);
  const std::string validation_name = o.validate ? file_name(*o.validate) : "";
  if (!o.out.empty()) {
    output::StagedDirectory staged(o.out);
    for (const auto& [name, content] : api::discrepancy_files(found, file_name(o.data), validation_name)) staged.write(name, content);
    staged.commit();
  }
  if (o.json) return print(api::discrepancy_json(found));
  print(found.text(o.data, validation_name));
  if (!o.out.empty()) print("  written to " + o.out + "/discrepancy.md\n");
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
  command->add_flag("--no-progress", options->no_progress, "no progress bar (step records: one bar per round of candidates, on a terminal)");
  command->callback([options] { run_discrepancy(*options); });
}

}  // namespace backlash::cli
