// `backlash validate CASE [--json]` and `backlash validate --branches [--json]`
// — the validation gate: every evaluator against Boost.Odeint, max abs error
// per state, where it occurs, pass/fail (through the facade: api::validate).
// Exit 0 only when everything passes; a failing gate is one line on stderr naming what
// failed and by how much (exit 1), with nothing on stdout.
//
// For a case: its generated evaluator (when the case is compiled in with the
// same numbers), the stable parametric evaluator and the direct generated
// formulas of its branches.  With --branches: the parametric and direct
// evaluators at a representative point of each of the 14 pole-structure branches.
#include "commands.hpp"
#include "flags.hpp"

#include "backlash/api/backlash.hpp"

#include <memory>
#include <optional>

namespace backlash::cli {

namespace {

struct ValidateOptions {
  std::string case_name;
  bool json = false;
  bool branches = false;
  std::string tolerance = "1e-9";
};

void run_validate(const ValidateOptions& options) {
  const double tolerance = parse_number(options.tolerance, "--tolerance");
  std::optional<api::Case> source;
  if (!options.case_name.empty()) source = api::load(options.case_name);  // bad input fails before any output
  const api::Validation validation = api::validate(source, options.branches, tolerance);
  if (!validation.passed()) throw std::runtime_error(validation.failure_message());
  print(options.json ? validation.json() : validation.text());
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
