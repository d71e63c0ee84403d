// validate.cpp — the validation gates' reports: every evaluator of a case and/or of every
// pole-structure branch against Boost.Odeint.
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>

namespace backlash::api {

namespace {

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

/// The gate run on evaluator after evaluator: the text report, the failures, each one's JSON.
struct Gate {
  numeric::ValidationOptions options;
  std::ostringstream text;
  std::vector<std::string> failures;

  nlohmann::json run(const numeric::EvaluatorPtr& evaluator, const std::string& where) {
    const numeric::ValidationResult result = numeric::validate(evaluator, options);
    const numeric::ValidationReport& report = result.report();
    if (!result.passed()) failures.push_back(where + ": " + report.evaluator + " (" + report.failures() + ")");
    print_report(text, report);
    return to_json(report);
  }
};

/// A case's evaluators: its generated one (a thesis case with its own numbers), the stable
/// parametric one, the direct per-branch formulas.
void validate_case(Gate& gate, const Case& source, nlohmann::json& document) {
  const model::CaseSpec& spec = source.spec();
  const numeric::Parameters p = source.parameters();
  std::vector<numeric::EvaluatorPtr> evaluators;
  const numeric::EvaluatorPtr primary = numeric::case_evaluator(spec);
  evaluators.push_back(primary);
  if (primary->kind() != "parametric") evaluators.push_back(numeric::parametric_evaluator(p));
  evaluators.push_back(numeric::direct_branch_evaluator(p));
  gate.text << "case " << spec.id << " (" << spec.name << "), tolerance " << gate.options.tolerance << "\n";
  nlohmann::json list = nlohmann::json::array();
  for (const auto& e : evaluators) list.push_back(gate.run(e, "case " + spec.id));
  document["case"] = spec.id;
  document["parameters"] = parameters_json(p);
  document["evaluators"] = list;
}

/// The parametric and direct evaluators at a representative point of every pole-structure branch.
void validate_branches(Gate& gate, nlohmann::json& document) {
  nlohmann::json list = nlohmann::json::array();
  for (const numeric::BranchRepresentative& rep : numeric::branch_representatives()) {
    const std::string name = numeric::branch_name(rep.branch);
    gate.text << "branch " << name << " (" << rep.description << ")\n";
    nlohmann::json evaluators = nlohmann::json::array();
    evaluators.push_back(gate.run(numeric::parametric_evaluator(rep.parameters), "branch " + name));
    evaluators.push_back(gate.run(numeric::direct_branch_evaluator(rep.parameters), "branch " + name));
    list.push_back({{"branch", name},
                    {"description", rep.description},
                    {"parameters", parameters_json(rep.parameters)},
                    {"evaluators", evaluators}});
  }
  document["branches"] = list;
}

}  // namespace

Validation validate(const std::optional<Case>& source, bool branches, double tolerance) {
  if (!source && !branches) throw BadInput("case", "give a case (I..VIII or a case file) and/or the branches");
  if (!(tolerance > 0)) throw BadInput("tolerance", "must be positive");
  if (!std::isfinite(tolerance)) throw BadInput("tolerance", "must be finite, got " + detail::number_text(tolerance));
  if (source) detail::check_parameter_scales(source->spec());  // what double precision cannot compute, before any work
  Gate gate;
  gate.options.tolerance = tolerance;
  nlohmann::json document;
  if (source) validate_case(gate, *source, document);
  if (branches) validate_branches(gate, document);
  document["tolerance"] = gate.options.tolerance;
  Validation out;
  out.failures = std::move(gate.failures);
  document["passed"] = out.failures.empty();
  out.document = detail::document(document);
  out.report = gate.text.str() + (out.failures.empty() ? "all evaluators passed\n" : "");
  return out;
}

std::string Validation::failure_message() const {
  std::string joined;
  for (const std::string& f : failures) joined += (joined.empty() ? "" : "; ") + f;
  return "validation failed: " + joined;
}

}  // namespace backlash::api
