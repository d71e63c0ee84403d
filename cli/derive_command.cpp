// `backlash derive CASE [--json|--latex]` — the exact derivation of one case
// (CASE = I…VIII or a case-file path), or of every general pole-structure
// branch (CASE = general), through the facade (backlash/api/derive.hpp).
#include "commands.hpp"

#include "backlash/api/derive.hpp"

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
    const api::GeneralDerivation branches = api::derive_general();
    print(options.json ? branches.json : branches.latex);
    return;
  }
  const api::Derivation derivation = api::derive(api::load(options.case_name));
  print(options.json ? derivation.json : options.latex ? derivation.latex : derivation.text);
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
