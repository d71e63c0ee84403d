// `backlash validate CASE [--json]` and `backlash validate --branches [--json]`
// — the validation gate: every evaluator against Boost.Odeint, max abs error
// per state, where it occurs, pass/fail.  Exit 0 only when everything passes.
//
// For a case: its generated evaluator (when the case is compiled in with the
// same numbers), the stable parametric evaluator and the direct generated
// formulas of its branches.  With --branches: the parametric and direct
// evaluators at a representative point of each of the 14 pole-structure branches.
#include "commands.hpp"
#include "numeric_case.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/validation.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

namespace backlash::cli {

namespace {

struct ValidateOptions {
  std::string case_name;
  bool json = false;
  bool branches = false;
  double tolerance = 1e-9;
};

nlohmann::json to_json(const numeric::ValidationReport& r) {
  nlohmann::json states = nlohmann::json::array();
  for (const numeric::StateError& s : r.states) {
    nlohmann::json at{{"t", s.at_t}};
    if (s.contact) {
      at["theta_o0"] = s.at_theta_o0;
      at["dtheta_o0"] = s.at_dtheta_o0;
    } else if (s.state != "cot_phi") {
      at["dtheta_m0"] = s.at_dtheta_m0;
    }
    states.push_back({{"state", s.state},
                      {"max_abs_error", s.max_abs_error},
                      {"at", at},
                      {"samples", s.samples},
                      {"passed", s.passed}});
  }
  return {{"evaluator", r.evaluator},
          {"kind", r.kind},
          {"branches", {{"contact", numeric::branch_name(r.branches.contact)}, {"free", numeric::branch_name(r.branches.free)}}},
          {"status", numeric::to_string(r.status)},
          {"passed", r.passed()},
          {"tolerance", r.tolerance},
          {"free_horizon", r.free_horizon},
          {"contact_horizon", r.contact_horizon},
          {"free_trajectories", r.free_trajectories},
          {"contact_trajectories", r.contact_trajectories},
          {"states", states}};
}

nlohmann::json parameters_json(const numeric::Parameters& p) {
  return {{"Jm", p.Jm}, {"Fm", p.Fm}, {"JL", p.JL}, {"FL", p.FL}, {"K", p.K}, {"theta_R", p.theta_R},
          {"backlash", p.backlash}, {"measured_at", model::to_string(p.measured_at)}};
}

void print_report(std::ostream& out, const numeric::ValidationReport& r) {
  out << "  " << r.evaluator << " [" << r.kind << "], branches " << numeric::branch_name(r.branches.contact) << " / "
      << numeric::branch_name(r.branches.free) << ": " << (r.passed() ? "pass" : "FAIL") << "\n";
  std::istringstream lines(r.summary());
  for (std::string line; std::getline(lines, line);) out << "    " << line << "\n";
}

void run_validate(const ValidateOptions& options) {
  if (options.case_name.empty() && !options.branches)
    throw UsageError("validate: give a CASE (I..VIII or a case file) and/or --branches");
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    throw UsageError("--tolerance: must be a finite number > 0");
  numeric::ValidationOptions gate;
  gate.tolerance = options.tolerance;

  std::optional<model::CaseSpec> spec;
  if (!options.case_name.empty()) {
    spec = model::load_case(options.case_name);  // bad input fails before any output
    check_parameter_scales(*spec);                // and what double precision cannot compute, before any work
  }

  nlohmann::json document;
  std::ostringstream text;
  std::vector<std::string> failures;
  auto run = [&](const numeric::EvaluatorPtr& evaluator, const std::string& where) {
    const numeric::ValidationResult result = numeric::validate(evaluator, gate);
    if (!result.passed())
      failures.push_back(where + ": " + result.report().evaluator + " (" + result.report().failures() + ")");
    print_report(text, result.report());
    return to_json(result.report());
  };

  if (spec) {
    const numeric::Parameters p = numeric::parameters_of(*spec);
    std::vector<numeric::EvaluatorPtr> evaluators;
    const numeric::EvaluatorPtr primary = numeric::case_evaluator(*spec);
    evaluators.push_back(primary);
    if (primary->kind() != "parametric") evaluators.push_back(numeric::parametric_evaluator(p));
    evaluators.push_back(numeric::direct_branch_evaluator(p));
    text << "case " << spec->id << " (" << spec->name << "), tolerance " << gate.tolerance << "\n";
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : evaluators) list.push_back(run(e, "case " + spec->id));
    document["case"] = spec->id;
    document["parameters"] = parameters_json(p);
    document["evaluators"] = list;
  }
  if (options.branches) {
    nlohmann::json list = nlohmann::json::array();
    for (const numeric::BranchRepresentative& rep : numeric::branch_representatives()) {
      const std::string name = numeric::branch_name(rep.branch);
      text << "branch " << name << " (" << rep.description << ")\n";
      nlohmann::json evaluators = nlohmann::json::array();
      evaluators.push_back(run(numeric::parametric_evaluator(rep.parameters), "branch " + name));
      evaluators.push_back(run(numeric::direct_branch_evaluator(rep.parameters), "branch " + name));
      list.push_back({{"branch", name},
                      {"description", rep.description},
                      {"parameters", parameters_json(rep.parameters)},
                      {"evaluators", evaluators}});
    }
    document["branches"] = list;
  }
  document["tolerance"] = gate.tolerance;
  document["passed"] = failures.empty();
  // A failing gate is one line on stderr naming what failed and by how much (exit 1), with
  // nothing on stdout: the report is the answer only when the gate passed.
  if (!failures.empty()) {
    std::string joined;
    for (const auto& f : failures) joined += (joined.empty() ? "" : "; ") + f;
    throw std::runtime_error("validation failed: " + joined);
  }
  if (options.json)
    std::cout << document.dump(2) << "\n";
  else
    std::cout << text.str() << "all evaluators passed\n";
}

}  // namespace

void register_validate_command(CLI::App& app) {
  auto options = std::make_shared<ValidateOptions>();
  CLI::App* command = app.add_subcommand(
      "validate", "Check the evaluators against Boost.Odeint: max abs error per state, where, pass/fail");
  command->add_option("CASE", options->case_name, "I..VIII or a case file path");
  command->add_flag("--branches", options->branches,
                    "validate the parametric and direct evaluators of every pole-structure branch");
  command->add_flag("--json", options->json, "print one JSON document");
  command->add_option("--tolerance", options->tolerance, "max abs error allowed per state (default 1e-9)");
  command->callback([options] { run_validate(*options); });
}

}  // namespace backlash::cli
