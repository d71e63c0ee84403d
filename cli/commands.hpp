// backlash/cli/commands.hpp — each subcommand of `backlash` registers itself.
//
// A command's callback throws backlash::cli::UsageError (or any
// std::exception) on bad input; main() prints "backlash: error: <what>" on one
// line to stderr and exits 2 (usage / bad input) or 1 (other failures).
// A command writes nothing to stdout or to files before its input is known good.
#pragma once

#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

namespace backlash::cli {

/// Bad flags or arguments (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void register_derive_command(CLI::App& app);   // cli/derive_command.cpp
void register_report_command(CLI::App& app);   // cli/report_command.cpp

}  // namespace backlash::cli
