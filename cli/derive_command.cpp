// `backlash derive CASE [--json|--latex]` — the exact derivation of one case
// (CASE = I…VIII or a case-file path), or of every general pole-structure
// branch (CASE = general).
#include "commands.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/derivation_output.hpp"
#include "backlash/symbolic/forced_modes.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <iostream>
#include <memory>

namespace backlash::cli {

namespace {

struct DeriveOptions {
  std::string case_name;
  bool json = false;
  bool latex = false;
};

void run_derive(const DeriveOptions& options) {
  if (options.case_name == "general") {
    const auto branches = symbolic::derive_general_branches();
    if (options.json) {
      nlohmann::json all = nlohmann::json::array();
      for (const auto& branch : branches) all.push_back(symbolic::to_json(branch));
      std::cout << all.dump(2) << "\n";
    } else {
      for (const auto& branch : branches) std::cout << symbolic::to_latex(branch) << "\n";
    }
    return;
  }
  const model::CaseSpec spec = model::load_case(options.case_name);
  const symbolic::CaseDerivation derivation = symbolic::derive_case(spec);
  if (options.json) {
    nlohmann::json document = symbolic::to_json(derivation);
    // The modes the effects add (constant torques, the closed motor loop, coupled free flight).
    document["forced_modes"] = symbolic::forced_modes_json(symbolic::derive_forced_modes(derivation));
    std::cout << document.dump(2) << "\n";
  } else if (options.latex) {
    std::cout << symbolic::to_latex(derivation) << symbolic::forced_modes_latex(symbolic::derive_forced_modes(derivation));
  }
  else
    std::cout << symbolic::to_text(derivation);
}

}  // namespace

void register_derive_command(CLI::App& app) {
  auto options = std::make_shared<DeriveOptions>();
  CLI::App* command = app.add_subcommand(
      "derive", "Exact inverse-Laplace solutions of every segment, separation line, isoclines, verification status");
  command->add_option("CASE", options->case_name, "I..VIII, a case file path, or 'general' for the parametric branches")
      ->required();
  auto* json = command->add_flag("--json", options->json, "print one JSON document");
  auto* latex = command->add_flag("--latex", options->latex, "print LaTeX");
  json->excludes(latex);
  command->callback([options] { run_derive(*options); });
}

}  // namespace backlash::cli
