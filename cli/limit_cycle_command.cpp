// `backlash limit-cycle CASE [--json]` — the limit cycle (fixed point of the
// half-cycle return map on the separation line) or its absence.
#include "commands.hpp"
#include "numeric_case.hpp"

#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/limit_cycle.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

namespace backlash::cli {

namespace {

struct LimitCycleOptions {
  std::string case_name;
  bool json = false;
};

void run_limit_cycle(const LimitCycleOptions& options) {
  const ValidatedCase c = validated_case(options.case_name);
  numeric::EffectLimitCycleOptions lc;
  if (c.spec.experiment && c.spec.experiment->kind == model::ExperimentKind::Step)
    lc.step = model::to_double(c.spec.experiment->step);
  const numeric::LimitCycle cycle = numeric::find_limit_cycle(c.model(), lc);
  const bool found = cycle.status == numeric::CycleStatus::LimitCycle;
  const bool with_effects = c.model().effects().any();
  if (options.json) {
    auto value = [&](double v) { return found && std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    nlohmann::json out{{"case", c.spec.id},
                       {"status", numeric::to_string(cycle.status)},
                       {"amplitude", value(cycle.amplitude)},
                       {"peak_to_peak", value(cycle.peak_to_peak)},
                       {"period", value(cycle.period)},
                       {"separation_velocity", value(cycle.separation_velocity)},
                       {"multiplier", value(cycle.multiplier)},
                       {"half_map_derivative", value(cycle.half_map_derivative)},
                       {"stable", found && cycle.stable},
                       {"peak_to_peak_motor", value(cycle.peak_to_peak_motor)},
                       {"peak_to_peak_load", value(cycle.peak_to_peak_load)},
                       {"bounce", found && cycle.bounced},
                       {"other_fixed_points", cycle.other_fixed_points},
                       {"effects", effects_json(c.model().effects())},
                       {"method", cycle.method}};
    if (with_effects) {
      out["iterations"] = cycle.iterations;
      out["residual"] = value(cycle.residual);
    } else {
      out["stability_constant"] = {{"C_separation", value(cycle.C_separation)},
                                   {"C_recombination", value(cycle.C_recombination)},
                                   {"contact_arc_crossings_of_theta_R", cycle.contact_arc_crossings_of_theta_R},
                                   {"jump_factor_across_theta_R", numeric::stability_constant_jump(c.evaluator().parameters())}};
    }
    if (!found) out["reason"] = cycle.reason;
    if (!found && cycle.rest_error != 0) out["rest_error"] = cycle.rest_error;
    std::cout << out.dump(2) << "\n";
    return;
  }
  if (!found) {
    std::printf("%s: no limit cycle: %s\n", c.spec.id.c_str(), cycle.reason.c_str());
    return;
  }
  std::printf("%s: %s limit cycle (%s; effects: %s)\n", c.spec.id.c_str(), cycle.stable ? "stable" : "unstable",
              cycle.method.c_str(), c.model().effects().describe().c_str());
  std::printf("  separation velocity  %.12f\n  multiplier (P')      %.9f\n  period               %.9f\n", cycle.separation_velocity,
              cycle.multiplier, cycle.period);
  std::printf("  amplitude |θo−θR|    %.9f\n  peak-to-peak θo      %.9f\n  peak-to-peak θm, θL  %.9f, %.9f\n", cycle.amplitude,
              cycle.peak_to_peak, cycle.peak_to_peak_motor, cycle.peak_to_peak_load);
  if (!with_effects)
    std::printf("  eq. 38: C at separation %.9f, after recombination %.9f (contact arc crosses θR %d×)\n", cycle.C_separation,
                cycle.C_recombination, cycle.contact_arc_crossings_of_theta_R);
}

}  // namespace

void register_limit_cycle_command(CLI::App& app) {
  auto options = std::make_shared<LimitCycleOptions>();
  CLI::App* command = app.add_subcommand("limit-cycle", "Limit cycle from the return map on the separation line, or its absence");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path")->required();
  command->add_flag("--json", options->json, "print one JSON document");
  command->callback([options] { run_limit_cycle(*options); });
}

}  // namespace backlash::cli
