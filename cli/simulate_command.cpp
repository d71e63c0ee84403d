// `backlash simulate CASE [--step A | --from LIST [--flight] [--gap X] [--other-velocity V]]
// [--t-end T] [--dt S] [--csv|--json]` — the exact event-driven step response (docs/physics.md:
// start at rest in contact, θo = θR − A), or the run from any admissible state (--from:
// θm,θ̇m,θL,θ̇L or θo,θ̇o; api::start_state, Model::simulate_from_state), through the facade
// (the CSV streamed row by row as it is computed).
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
  std::optional<std::string> step, t_end, from, gap, other_velocity;
  std::string dt = "0.01";
  bool csv = false, json = false, flight = false;
};

/// The run: the step response, or (--from) the run from the given state.
api::Simulation run(const api::Model& model, const SimulateOptions& options, const api::SimulationRequest& request) {
  if (!options.from) {
    if (options.flight || options.gap || options.other_velocity)
      throw UsageError("--flight, --gap and --other-velocity need --from");
    return options.csv ? model.simulate_csv(request, print) : model.simulate(request);
  }
  std::optional<double> gap, other_velocity;
  if (options.gap) gap = parse_number(*options.gap, "--gap");
  if (options.other_velocity) other_velocity = parse_number(*options.other_velocity, "--other-velocity");
  const api::StartState start = api::start_state(model.evaluator().parameters(), parse_number_list(*options.from, "--from"),
                                                 !options.flight, gap, other_velocity);
  return options.csv ? model.simulate_from_state_csv(start, request, print) : model.simulate_from_state(start, request);
}

void run_simulate(const SimulateOptions& options) {
  api::SimulationRequest request;
  if (options.step) request.step = parse_number(*options.step, "--step");
  if (options.t_end) request.t_end = parse_number(*options.t_end, "--t-end");
  const double dt = parse_number(options.dt, "--dt");
  api::check_sample_interval(dt);  // also without --csv (BadInput "sample_interval": --dt, main.cpp)
  const api::Model model(api::load(options.case_name));
  if (options.csv) request.sample_interval = dt;
  const api::Simulation result = run(model, options, request);
  if (!options.csv) print(options.json ? result.json() : result.text());
  flush_stdout();
  if (result.stopped_early()) throw StoppedEarly(result.stop_message());
}

}  // namespace

void register_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* command = app.add_subcommand("simulate", "Exact event-driven step response (closed forms, certified event times)");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path")->required();
  command->add_option("--step", options->step, "step size A: start at rest with theta_o = theta_R - A (default: the case's [experiment])");
  auto* from = command->add_option("--from", options->from,
                                   "start state instead of a step: theta_m,dtheta_m,theta_L,dtheta_L or theta_o,dtheta_o "
                                   "(contact on the face driving toward theta_R unless --gap/--flight)");
  command->add_flag("--flight", options->flight, "with --from: start in free flight (default: in contact)");
  command->add_option("--gap", options->gap, "with --from theta_o,dtheta_o: the gap theta_L - theta_m (default: the driving face)");
  command->add_option("--other-velocity", options->other_velocity,
                      "with --from theta_o,dtheta_o: the other shaft's velocity (default dtheta_o)");
  command->get_option("--step")->excludes(from);
  command->add_option("--t-end", options->t_end, "end time, > 0 (default: the case's t_end or 60)");
  command->add_option("--dt", options->dt, "CSV sample interval (default 0.01)");
  auto* csv = command->add_flag("--csv", options->csv, "print the trajectory as CSV");
  auto* json = command->add_flag("--json", options->json, "print one JSON document");
  csv->excludes(json);
  command->callback([options] { run_simulate(*options); });
}

}  // namespace backlash::cli
