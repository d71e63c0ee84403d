// `backlash simulate CASE --step A [--t-end T] [--csv|--json]` — the exact
// event-driven step response (docs/physics.md: start at rest in contact, θo = θR − A).
#include "commands.hpp"
#include "numeric_case.hpp"

#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/scales.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
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
  std::optional<double> step, t_end;
  if (options.step) step = parse_number(*options.step, "--step");
  if (options.t_end) {
    t_end = parse_number(*options.t_end, "--t-end");
    if (*t_end <= 0) throw UsageError("--t-end: must be > 0, got " + *options.t_end);
  }
  const double dt = parse_number(options.dt, "--dt");
  if (dt <= 0) throw UsageError("--dt: must be > 0, got " + options.dt);
  const ValidatedCase c = validated_case(options.case_name);
  if (!step) {
    if (!c.spec.experiment) throw UsageError("--step is required (the case file has no [experiment] step)");
    if (c.spec.experiment->kind != model::ExperimentKind::Step)
      throw UsageError("--step is required (the case file's experiment is a measured drive, which needs its record: "
                       "use `backlash discrepancy`)");
    step = model::to_double(c.spec.experiment->step);
  }
  if (!t_end) t_end = c.spec.experiment && c.spec.experiment->t_end ? model::to_double(*c.spec.experiment->t_end) : 60.0;
  // A step whose motion double precision cannot resolve against the backlash is refused
  // before any work (numeric/scales.hpp): an answer there would be rounding noise.
  const numeric::Parameters& parameters = c.evaluator().parameters();
  const std::string step_text = options.step ? *options.step : "of the case file";
  if (auto problem = numeric::resolution_problem(parameters, std::fabs(*step), "the step " + step_text))
    throw UsageError("--step: " + *problem);
  numeric::SimulationOptions sim;
  sim.t_end = *t_end;
  const numeric::Effects& effects = c.model().effects();
  if (options.csv) {
    // Streamed: each sample is printed as soon as it is computed (memory does not grow with
    // the number of rows); an early stop is said in a last comment line and on stderr.
    sim.sample_interval = dt;
    const char* contact_mode = effects.compliant() ? "mesh" : "contact";
    std::printf("t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode\n");
    sim.event_sink = [](const numeric::SimulationEvent&) {};  // not printed: not kept
    sim.sample_sink = [contact_mode](const numeric::TrajectorySample& s) {
      std::printf("%.10g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s\n", s.t, s.theta_o, s.dtheta_o, s.theta_m, s.dtheta_m,
                  s.theta_L, s.dtheta_L, s.in_contact ? contact_mode : "free");
    };
  }
  const numeric::SimulationResult r = numeric::simulate_effects_step(c.model(), *step, sim);
  const double final_error = r.theta_o_final - parameters.theta_R;
  const bool early = numeric::stopped_early(r.status);
  if (options.csv) {
    if (early)
      std::printf("# stopped early at t = %.10g: %s: %s\n", r.t_final, numeric::to_string(r.status), r.stop_reason.c_str());
    std::fflush(stdout);
    if (early) throw StoppedEarly(r.t_final, numeric::to_string(r.status), r.stop_reason);
    return;
  }
  if (options.json) {
    nlohmann::json events = nlohmann::json::array();
    for (const numeric::SimulationEvent& e : r.events) {
      nlohmann::json event{{"t", e.t},
                           {"kind", numeric::to_string(e.kind)},
                           {"theta_o", e.theta_o},
                           {"dtheta_o", e.dtheta_o},
                           {"theta_m", e.after.theta_m},
                           {"theta_L", e.after.theta_L},
                           {"bounce", e.bounce}};
      if (e.body != numeric::Body::None) event["body"] = numeric::to_string(e.body);
      if (e.accumulation) event["accumulation"] = true;
      events.push_back(event);
    }
    nlohmann::json out{{"case", c.spec.id},
                       {"step", *step},
                       {"t_end", *t_end},
                       {"effects", effects_json(effects)},
                       {"status", numeric::to_string(r.status)},
                       {"events", events},
                       {"final",
                        {{"t", r.t_final},
                         {"theta_o", r.theta_o_final},
                         {"error", final_error},
                         {"theta_m", r.final_state.theta_m},
                         {"theta_L", r.final_state.theta_L},
                         {"dtheta_m", r.final_state.dtheta_m},
                         {"dtheta_L", r.final_state.dtheta_L},
                         {"in_contact", r.final_state.in_contact},
                         {"motor_stuck", r.final_state.motor_stuck},
                         {"load_stuck", r.final_state.load_stuck}}}};
    if (early) out["stop_reason"] = r.stop_reason;
    std::cout << out.dump(2) << "\n" << std::flush;
    if (early) throw StoppedEarly(r.t_final, numeric::to_string(r.status), r.stop_reason);
    return;
  }
  std::printf("%s, step %g over %g s: %s, %zu events (effects: %s)\n", c.spec.id.c_str(), *step, *t_end,
              numeric::to_string(r.status), r.events.size(), effects.describe().c_str());
  for (const numeric::SimulationEvent& e : r.events)
    std::printf("  t = %14.10f  %-13s theta_o = %12.8f  dtheta_o = %12.8f%s%s%s\n", e.t, numeric::to_string(e.kind), e.theta_o,
                e.dtheta_o, e.bounce ? "  (bounce)" : "", e.accumulation ? "  (end of a bounce series)" : "",
                e.body != numeric::Body::None ? (std::string("  ") + numeric::to_string(e.body)).c_str() : "");
  std::printf("final: t = %g  theta_o = %.10f  theta_m = %.10f  theta_L = %.10f  error theta_o - theta_R = %.10f\n",
              r.t_final, r.theta_o_final, r.final_state.theta_m, r.final_state.theta_L, final_error);
  if (early) {
    std::printf("stopped early at t = %.10g (%s): %s\n", r.t_final, numeric::to_string(r.status), r.stop_reason.c_str());
    std::fflush(stdout);
    throw StoppedEarly(r.t_final, numeric::to_string(r.status), r.stop_reason);
  }
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
