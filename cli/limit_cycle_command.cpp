// `backlash limit-cycle CASE [--json]` — the limit cycle (fixed point of the
// half-cycle return map on the separation line, or of the full return map with effects)
// or its absence, through the facade (api::Model::limit_cycle).
#include "commands.hpp"

#include "backlash/api/backlash.hpp"

#include <memory>

namespace backlash::cli {

namespace {

struct LimitCycleOptions {
  std::string case_name;
  bool json = false;
};

void run_limit_cycle(const LimitCycleOptions& options) {
  const api::Cycle cycle = api::Model(api::load(options.case_name)).limit_cycle();
  print(options.json ? cycle.json() : cycle.text());
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
