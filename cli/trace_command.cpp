// `backlash trace CASE [--v0 LIST] [--json]` — the dividing lines: for each
// θ̇m0 on the separation line, the recombination time and the states of motor
// and load just before the impact and of the recombined system just after it.
#include "commands.hpp"
#include "numeric_case.hpp"

#include "backlash/numeric/dividing_lines.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

namespace backlash::cli {

namespace {

struct TraceOptions {
  std::string case_name;
  std::optional<std::string> v0_list;
  bool json = false;
};

nlohmann::json maybe(bool present, double value) { return present ? nlohmann::json(value) : nlohmann::json(nullptr); }

void run_trace(const TraceOptions& options) {
  if (options.v0_list && options.v0_list->empty()) throw UsageError("--v0: empty list");
  const std::vector<double> grid =
      options.v0_list ? parse_number_list(*options.v0_list, "--v0") : numeric::default_dividing_line_grid();
  const ValidatedCase c = validated_case(options.case_name);
  const numeric::DividingLines lines = numeric::trace_dividing_lines(c.evaluator(), grid);
  if (options.json) {
    nlohmann::json points = nlohmann::json::array();
    for (const numeric::DividingLinePoint& p : lines.points) {
      const bool ok = p.status != numeric::RecombinationStatus::NoRecombination;
      points.push_back({{"v0", p.dtheta_m0},
                        {"status", numeric::to_string(p.status)},
                        {"grazing", p.grazing},
                        {"t", maybe(ok, p.t)},
                        {"theta_m", maybe(ok, p.theta_m)},
                        {"dtheta_m", maybe(ok, p.dtheta_m)},
                        {"theta_L", maybe(ok, p.theta_L)},
                        {"dtheta_L", maybe(ok, p.dtheta_L)},
                        {"theta_o", maybe(ok, p.theta_o)},
                        {"dtheta_o", maybe(ok, p.dtheta_o)}});
    }
    nlohmann::json out{{"case", c.spec.id},
                       {"cot_phi", lines.cot_phi},
                       {"threshold", lines.threshold ? nlohmann::json(*lines.threshold) : nlohmann::json(nullptr)},
                       {"horizon", lines.horizon},
                       {"evaluator", c.evaluator().evaluator().name()},
                       {"convention", "theta_m(0) = theta_L(0) = theta_R + cot_phi*v0; m, L before the impact, o after it (eq. 24)"},
                       {"points", points}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::printf("%s: separation line theta_o = theta_R %+.10g*dtheta_o", c.spec.id.c_str(), lines.cot_phi);
  if (lines.threshold) std::printf("; no recombination for |dtheta_m0| < %.10g", *lines.threshold);
  std::printf("\n%10s %-13s %14s %12s %12s %12s %12s %12s %12s\n", "dtheta_m0", "status", "t", "theta_m", "dtheta_m", "theta_L",
              "dtheta_L", "theta_o", "dtheta_o+");
  for (const numeric::DividingLinePoint& p : lines.points) {
    if (p.status == numeric::RecombinationStatus::NoRecombination) {
      std::printf("%10.6g %-13s\n", p.dtheta_m0, "none");
      continue;
    }
    std::printf("%10.6g %-13s %14.10f %12.8f %12.8f %12.8f %12.8f %12.8f %12.8f\n", p.dtheta_m0, numeric::to_string(p.status),
                p.t, p.theta_m, p.dtheta_m, p.theta_L, p.dtheta_L, p.theta_o, p.dtheta_o);
  }
}

}  // namespace

void register_trace_command(CLI::App& app) {
  auto options = std::make_shared<TraceOptions>();
  CLI::App* command = app.add_subcommand("trace", "Dividing lines: states at recombination for dtheta_m0 on the separation line");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path")->required();
  command->add_option("--v0", options->v0_list, "comma-separated dtheta_m0 values (default: the thesis's grid)");
  command->add_flag("--json", options->json, "print one JSON document");
  command->callback([options] { run_trace(*options); });
}

}  // namespace backlash::cli
