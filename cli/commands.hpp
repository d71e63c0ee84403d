// backlash/cli/commands.hpp — each subcommand of `backlash` registers itself.
//
// A command's callback throws backlash::cli::UsageError (or any
// std::exception) on bad input; main() prints "backlash: error: <what>" on one
// line to stderr and exits 2 (usage / bad input) or 1 (other failures).
// A command writes nothing to stdout or to files before its input is known good.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace backlash::cli {

/// Bad flags or arguments (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation that ended before its end time without the model having stopped by
/// itself (numeric::stopped_early): the output printed so far is correct and complete up to
/// `t`; main() says so on stderr in one line and exits 3.
class StoppedEarly : public std::runtime_error {
 public:
  StoppedEarly(double t, const std::string& status, const std::string& reason)
      : std::runtime_error("stopped early at t = " + number(t) + " (" + status + "): " + reason) {}

 private:
  static std::string number(double t) {
    char text[32];
    std::snprintf(text, sizeof text, "%.10g", t);
    return text;
  }
};

void register_derive_command(CLI::App& app);   // cli/derive_command.cpp
void register_report_command(CLI::App& app);   // cli/report_command.cpp
void register_codegen_command(CLI::App& app);  // cli/codegen_command.cpp
void register_validate_command(CLI::App& app); // cli/validate_command.cpp
void register_trace_command(CLI::App& app);    // cli/trace_command.cpp
void register_simulate_command(CLI::App& app); // cli/simulate_command.cpp
void register_limit_cycle_command(CLI::App& app);  // cli/limit_cycle_command.cpp
void register_sweep_command(CLI::App& app);    // cli/sweep_command.cpp
void register_import_command(CLI::App& app);   // cli/import_command.cpp
void register_discrepancy_command(CLI::App& app);  // cli/discrepancy_command.cpp
void register_map_command(CLI::App& app);      // cli/map_command.cpp

}  // namespace backlash::cli
