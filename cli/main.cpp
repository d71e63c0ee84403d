// backlash — command-line entry point.
//
// Every subcommand registers itself (cli/commands.hpp).  Errors become one line
// on stderr, "backlash: error: <what>", and the exit code tells their kind:
//   0  success, and --help (CLI11 prints it through app.exit)
//   2  bad usage or bad input (CLI11 parse errors, UsageError, a bad --out target (output::OutputError
//      of kind bad_target; a failed write is 1), and what the facade calls bad
//      input, api::is_bad_input: its BadInput named by the flag, CaseFileError, MeasuredDataError)
//   1  any other failure
//   3  a simulation stopped before its end time (chattering, event cap, non-finite,
//      unresolved, work limit): what was computed is printed, the reason is on stderr
// CLI11's own failure printer uses two lines and exit codes above 100; parse
// errors are reported here in the one-line form with exit code 2 instead.
// Here, for every command at once: stdout is checked after the command (a full device, a
// closed stream: exit 1, "cannot write the output to stdout: …"), an empty --out is refused
// (exit 2), and SIGINT/SIGTERM/SIGHUP remove the temporaries being written before the process
// ends by the signal (backlash/output/signals.hpp; `map` stops itself and exits 1).
#include "commands.hpp"

#include "backlash/api/backlash.hpp"
#include "backlash/output/output_error.hpp"
#include "backlash/output/signals.hpp"

#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <exception>
#include <iostream>
#include <map>
#include <string>

namespace {

constexpr int exit_code_for_bad_input = 2;
constexpr int exit_code_for_failure = 1;
constexpr int exit_code_for_early_stop = 3;

/// Prints "backlash: error: <message>" as exactly one line on stderr.
int report_error(std::string message, int exit_code, const char* prefix = "backlash: error: ") {
  for (char& character : message)
    if (character == '\n' || character == '\r') character = ' ';
  while (!message.empty() && message.back() == ' ') message.pop_back();
  std::cerr << prefix << message << '\n';
  return exit_code;
}

/// The facade's BadInput in the command line's words: its argument named by the flag
/// ("t_end: must be > 0" → "--t-end: must be > 0"); an argument that is no flag (a file) as it is.
std::string flag_message(const backlash::api::BadInput& error) {
  static const std::map<std::string, std::string> flags{
      {"step", "--step"},       {"t_end", "--t-end"},       {"sample_interval", "--dt"}, {"v0", "--v0"},
      {"vary", "--vary"},       {"from", "--from"},         {"to", "--to"},              {"points", "--points"},
      {"threads", "--threads"}, {"tolerance", "--tolerance"}, {"cutoff", "--cutoff"},    {"window", "--window"},
      {"validation", "--validate"}, {"target", "sweep"},    {"case", "validate"},
      {"gap", "--gap"},         {"other_velocity", "--other-velocity"}};
  const auto flag = flags.find(error.argument());
  return flag == flags.end() ? error.what() : flag->second + ": " + error.problem();
}

/// A closed stdout or stderr would hand its descriptor to the first file opened, which would
/// then receive the output: /dev/null opened read-only takes it instead, so that every write to
/// the stream fails and is reported.
void guard_standard_streams() {
  for (const int fd : {STDOUT_FILENO, STDERR_FILENO}) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    const int null = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (null >= 0 && null != fd) ::dup2(null, fd), ::close(null);
  }
}

/// Every command's --out: an empty path is refused (it would otherwise mean "no --out").
void refuse_empty_out(CLI::App& app) {
  const CLI::Validator not_empty([](const std::string& value) { return value.empty() ? "empty path; give a name" : ""; },
                                 "", "not empty");
  for (CLI::App* command : app.get_subcommands({}))
    if (CLI::Option* out = command->get_option_no_throw("--out")) out->check(not_empty);
}

}  // namespace

int main(int argument_count, char** arguments) {
  CLI::App app{
      "backlash — exact analysis of servo systems with gear backlash: closed-form segment solutions, "
      "dividing lines, limit cycles and step responses for the thesis cases I..VIII or any case file."};
  app.require_subcommand(1);

  backlash::cli::register_derive_command(app);
  backlash::cli::register_report_command(app);
  backlash::cli::register_codegen_command(app);
  backlash::cli::register_validate_command(app);
  backlash::cli::register_trace_command(app);
  backlash::cli::register_simulate_command(app);
  backlash::cli::register_limit_cycle_command(app);
  backlash::cli::register_sweep_command(app);
  backlash::cli::register_import_command(app);
  backlash::cli::register_discrepancy_command(app);
  backlash::cli::register_map_command(app);
  backlash::cli::register_explorer_command(app);
  refuse_empty_out(app);
  guard_standard_streams();
  backlash::output::clean_up_on_signals();

  try {
    app.parse(argument_count, arguments);
  } catch (const CLI::ParseError& parse_error) {
    if (parse_error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(parse_error);
    return report_error(std::string(parse_error.what()) + " (run with --help for usage)", exit_code_for_bad_input);
  } catch (const backlash::cli::StoppedEarly& early) {
    if (const std::string failure = backlash::cli::stdout_failure(); !failure.empty()) return report_error(failure, exit_code_for_failure);
    return report_error(early.what(), exit_code_for_early_stop, "backlash: ");
  } catch (const backlash::cli::UsageError& usage_error) {
    return report_error(usage_error.what(), exit_code_for_bad_input);
  } catch (const backlash::api::BadInput& bad_input) {
    return report_error(flag_message(bad_input), exit_code_for_bad_input);
  } catch (const backlash::output::OutputError& output_error) {  // a bad --out (2) or a failed write (1)
    return report_error(output_error.what(), output_error.exit_code());
  } catch (const std::exception& error) {  // CaseFileError, MeasuredDataError: bad input too
    return report_error(error.what(), backlash::api::is_bad_input(error) ? exit_code_for_bad_input : exit_code_for_failure);
  }
  if (const std::string failure = backlash::cli::stdout_failure(); !failure.empty()) return report_error(failure, exit_code_for_failure);
  return 0;
}
