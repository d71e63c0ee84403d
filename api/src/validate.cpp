// validate.cpp — the validation gates' reports: every evaluator of a case and/or of every
// pole-structure branch against Boost.Odeint.
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include <nlohmann/json.hpp>

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

}  // namespace

Validation validate(const std::optional<Case>& source, bool branches, double tolerance) {
  if (!source && !branches) throw BadInput("case", "give a case (I..VIII or a case file) and/or the branches");
  if (!(tolerance > 0)) throw BadInput("tolerance", "must be positive");
  numeric::ValidationOptions gate;
  gate.tolerance = tolerance;

  Validation out;
  nlohmann::json document;
  std::ostringstream text;
  auto run = [&](const numeric::EvaluatorPtr& evaluator, const std::string& where) {
    const numeric::ValidationResult result = numeric::validate(evaluator, gate);
    if (!result.passed()) out.failures.push_back(where + ": " + result.report().evaluator);
    print_report(text, result.report());
    return to_json(result.report());
  };

  if (source) {
    const model::CaseSpec& spec = source->spec();
    const numeric::Parameters p = source->parameters();
    std::vector<numeric::EvaluatorPtr> evaluators;
    const numeric::EvaluatorPtr primary = numeric::case_evaluator(spec);
    evaluators.push_back(primary);
    if (primary->kind() != "parametric") evaluators.push_back(numeric::parametric_evaluator(p));
    evaluators.push_back(numeric::direct_branch_evaluator(p));
    text << "case " << spec.id << " (" << spec.name << "), tolerance " << gate.tolerance << "\n";
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : evaluators) list.push_back(run(e, "case " + spec.id));
    document["case"] = spec.id;
    document["parameters"] = parameters_json(p);
    document["evaluators"] = list;
  }
  if (branches) {
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
  document["passed"] = out.failures.empty();
  out.document = detail::document(document);
  out.report = text.str() + (out.failures.empty() ? "all evaluators passed\n" : "");
  return out;
}

}  // namespace backlash::api
