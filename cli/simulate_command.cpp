// `backlash simulate CASE [--step A] [--t-end T] [--dt S] [--csv|--json]` — the exact
// event-driven step response (docs/physics.md: start at rest in contact, θo = θR − A),
// through the facade (api::Model::simulate; the CSV streamed row by row as it is computed).
// A run that stops before T (chattering, event cap, ...) prints what it computed, says why
// on stderr and exits 3 (docs/design.md, "Exit 3").
#include "commands.hpp"
#include "flags.hpp"

#include "backlash/api/backlash.hpp"

#include <memory>
#include <optional>

namespace backlash::cli {

namespace {

struct SimulateOptions {
  std::string case_name;
  std::optional<std::string> step, t_end;
  std::string dt = "0.01";
  bool csv = false, json = false;
};

void run_simulate(const SimulateOptions& options) {
  api::SimulationRequest request;
  if (options.step) request.step = parse_number(*options.step, "--step");
  if (options.t_end) request.t_end = parse_number(*options.t_end, "--t-end");
  const double dt = parse_number(options.dt, "--dt");
  api::check_sample_interval(dt);  // also without --csv (BadInput "sample_interval": --dt, main.cpp)
  const api::Model model(api::load(options.case_name));
  api::Simulation run;
  if (options.csv) {
    request.sample_interval = dt;
    run = model.simulate_csv(request, print);
  } else {
    run = model.simulate(request);
    print(options.json ? run.json() : run.text());
  }
  flush_stdout();
  if (run.stopped_early()) throw StoppedEarly(run.stop_message());
}

}  // namespace

void register_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* command = app.add_subcommand("simulate", "Exact event-driven step response (closed forms, certified event times)");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path")->required();
  command->add_option("--step", options->step, "step size A: start at rest with theta_o = theta_R - A (default: the case's [experiment])");
  command->add_option("--t-end", options->t_end, "end time, > 0 (default: the case's t_end or 60)");
  command->add_option("--dt", options->dt, "CSV sample interval (default 0.01)");
  auto* csv = command->add_flag("--csv", options->csv, "print the trajectory as CSV");
  auto* json = command->add_flag("--json", options->json, "print one JSON document");
  csv->excludes(json);
  command->callback([options] { run_simulate(*options); });
}

}  // namespace backlash::cli
