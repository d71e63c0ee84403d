// `backlash trace CASE [--v0 LIST] [--json]` — the dividing lines: for each
// θ̇m0 on the separation line, the recombination time and the states of motor
// and load just before the impact and of the recombined system just after it
// (through the facade: api::Model::trace).
#include "commands.hpp"
#include "flags.hpp"

#include "backlash/api/backlash.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <optional>

namespace backlash::cli {

namespace {

struct TraceOptions {
  std::string case_name;
  std::optional<std::string> v0_list;
  bool json = false;
};

void run_trace(const TraceOptions& options) {
  std::optional<std::vector<double>> v0;
  if (options.v0_list) {
    if (options.v0_list->empty()) throw UsageError("--v0: empty list");
    v0 = parse_number_list(*options.v0_list, "--v0");
  }
  const api::Model model(api::load(options.case_name));
  const api::Trace lines = v0 ? model.trace(*v0) : model.trace();
  print(options.json ? lines.json() : lines.text());
  // A point its search could not decide is a work limit, as `simulate`'s work_limit: the output
  // above is complete (those points with status work_limit), and the command exits 3 with the reason.
  const auto& points = lines.lines.points;
  const auto unresolved = std::count_if(points.begin(), points.end(), [](const numeric::DividingLinePoint& p) {
    return p.status == numeric::RecombinationStatus::Unresolved;
  });
  if (unresolved > 0)
    throw StoppedEarly(std::to_string(unresolved) + " of " + std::to_string(points.size()) +
                       " dividing-line points unresolved (work_limit): " + lines.lines.work_limit);
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
