// `backlash import FILE.mat --out FILE.csv [--format emps]` — a measured record
// of a real drive in the project's CSV (docs/design.md, "Measured data (CSV)"), for the
// discrepancy workflow's measured-drive experiments.
//
// EMPS (measurements/emps.hpp): t → t [s], qm → theta_out [m], the drive force
// on the mechanism → drive [N] = gtau·vir, plus pulses_N only if the data show
// the pulses are not already in vir (in the published validation record they
// are).  The CSV is written atomically; on any error nothing is written and
// nothing is printed on stdout (one line on stderr, exit 2).
#include "commands.hpp"

#include "backlash/api/backlash.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

namespace backlash::cli {

namespace {

struct ImportOptions {
  std::string input;
  std::string out;
  std::string format = "emps";
};

void run_import(const ImportOptions& options) {
  if (options.format != "emps") throw UsageError("--format: unknown format '" + options.format + "' (known: emps)");
  std::error_code ignored;
  if (std::filesystem::equivalent(options.input, options.out, ignored))
    throw UsageError("--out: " + options.out + " is the input file");
  api::Import imported;
  try {
    imported = api::import_record(options.input, options.out);  // the facade: read, convert, write atomically
  } catch (const measurements::MeasuredDataError& error) {
    throw UsageError(error.what());
  }
  print(imported.text());
}

}  // namespace

void register_import_command(CLI::App& app) {
  auto options = std::make_shared<ImportOptions>();
  CLI::App* command =
      app.add_subcommand("import", "Convert a measured record (EMPS .mat) into the project's CSV (t, theta_out, drive)");
  command->add_option("FILE", options->input, "the record to import (EMPS: a MATLAB .mat file)")->required();
  command->add_option("--out", options->out, "the CSV to write (atomically; an existing regular file is replaced)")
      ->required();
  command->add_option("--format", options->format, "format of FILE: emps (default)");
  command->callback([options] { run_import(*options); });
}

}  // namespace backlash::cli
