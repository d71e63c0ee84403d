// backlash/cli/commands.hpp — each subcommand of `backlash` registers itself.
//
// A command is a thin shell over the facade (backlash/api/backlash.hpp): it reads its
// flags (CLI11, flags.hpp), calls the facade and prints what the result writes (json(),
// csv(), text()).  Its callback throws backlash::cli::UsageError, the facade's exceptions
// or any std::exception; main() prints "backlash: error: <what>" on one line to stderr and
// exits 2 (usage / bad input: UsageError, api::is_bad_input) or 1 (other failures); 3 for
// StoppedEarly.  A command writes nothing to stdout or to files before its input is known
// good.  A new command: its register_…_command here and one line in main.cpp.
#pragma once

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace backlash::cli {

/// Bad flags or arguments (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation that ended before its end time without the model having stopped by
/// itself (api::Simulation::stopped_early): the output printed so far is correct and complete
/// up to the stop; main() prints `message` ("stopped early at t = …") on stderr in one line
/// and exits 3.
class StoppedEarly : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writes `text` to stdout as it is; a failed write is an error (exit 1).
inline void print(std::string_view text) {
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size())
    throw std::runtime_error("cannot write the output");
}

/// Why stdout did not take everything written to it ("" when it did): std::cout and stdout
/// flushed and checked.  main() checks it after every command (exit 1).
inline std::string stdout_failure() {
  errno = 0;
  std::cout.flush();
  const bool failed = std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout;
  if (!failed) return "";
  const int error_number = errno;
  return std::string("cannot write the output to stdout") + (error_number ? ": " + std::string(std::strerror(error_number)) : "");
}

/// Flushes stdout before a command goes on to stderr (a summary line): its failure is an error (exit 1).
inline void flush_stdout() {
  if (std::string failure = stdout_failure(); !failure.empty()) throw std::runtime_error(failure);
}

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
void register_explorer_command(CLI::App& app); // cli/explorer_command.cpp

}  // namespace backlash::cli
