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

#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/measured_record.hpp"

#include <fmt/format.h>

#include <algorithm>
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

const char* describe(measurements::EmpsPulses pulses) {
  switch (pulses) {
    case measurements::EmpsPulses::none: return "none";
    case measurements::EmpsPulses::contained: return "already contained in vir (it steps with every edge): not added";
    case measurements::EmpsPulses::added: return "not in vir: added to gtau*vir";
  }
  return "?";
}

void run_import(const ImportOptions& options) {
  if (options.format != "emps") throw UsageError("--format: unknown format '" + options.format + "' (known: emps)");
  std::error_code ignored;
  if (std::filesystem::equivalent(options.input, options.out, ignored))
    throw UsageError("--out: " + options.out + " is the input file");

  measurements::EmpsRecord emps;
  measurements::EmpsPulses pulses{};
  measurements::MeasuredRecord record;
  try {
    emps = measurements::read_emps(options.input);
    pulses = measurements::emps_pulses_in_vir(emps);
    record = measurements::to_measured_record(emps);
    measurements::write_measured_csv(record, options.out);
  } catch (const measurements::MeasuredDataError& error) {
    throw UsageError(error.what());
  }

  const std::size_t samples = record.size();
  const double duration = record.t.back() - record.t.front();
  double shortest_step = record.t[1] - record.t[0], longest_step = shortest_step;
  for (std::size_t index = 2; index < samples; ++index) {
    const double step = record.t[index] - record.t[index - 1];
    shortest_step = std::min(shortest_step, step);
    longest_step = std::max(longest_step, step);
  }
  fmt::print("imported {} (EMPS) into {}\n", options.input, options.out);
  fmt::print("  samples      {}\n", samples);
  fmt::print("  duration     {:.10g} s (t = {:.10g} ... {:.10g})\n", duration, record.t.front(), record.t.back());
  fmt::print("  sample rate  {:.6g} Hz (steps {:.6g} ... {:.6g} s)\n", static_cast<double>(samples - 1) / duration,
             shortest_step, longest_step);
  fmt::print("  gtau         {} N/V (kp = {}, kv = {})\n", emps.gtau, emps.kp, emps.kv);
  fmt::print("  columns      t [s], theta_out = qm [m], drive = {} [N]\n",
             pulses == measurements::EmpsPulses::added ? "gtau*vir + pulses_N" : "gtau*vir");
  fmt::print("  pulses_N     {}\n", describe(pulses));
  fmt::print("suggested [experiment] for a measured-drive model file (data: {}):\n", options.out);
  fmt::print("[experiment]\nkind = \"drive\"\ndrive_gain = 1\n");
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
