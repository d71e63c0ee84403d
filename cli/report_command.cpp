// `backlash report [--out DIR] [--no-pdf]` — the main job: all eight thesis cases,
// derived, validated, traced, simulated, compared with the thesis and written
// as a report (reports/report.hpp): case pages (Markdown + LaTeX), the general
// solutions, the errata ledger, every thesis figure redrawn, report.pdf.
// This file only parses the flags; the report comes through the facade
// (api/report.hpp: api::write_report), which lays it out with reports/.
// Bad --out: one-line error, exit 2, nothing written.  The output folder
// appears all at once (or not at all).
#include "commands.hpp"

#include "backlash/api/report.hpp"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>

namespace backlash::cli {

namespace {

struct ReportCommandOptions {
  std::string out = "report";
  bool no_pdf = false;
};

void run_report(const ReportCommandOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  api::ReportRequest request;
  request.out = options.out;
  request.pdf = !options.no_pdf;
  const api::Report result = api::write_report(request);  // a bad --out: OutputError, exit 2 (main.cpp)
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  char timing[32];
  std::snprintf(timing, sizeof timing, "%.2f", seconds);
  std::cout << "report written to " << options.out << " (" << result.files << " files, " << timing << " s)\n"
            << result.pdf_note << "\n";
  if (!result.figures_drawn) std::cout << result.figures_note << "\n";
}

}  // namespace

void register_report_command(CLI::App& app) {
  auto options = std::make_shared<ReportCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "report", "Derive, generate, validate, trace, simulate and report all eight thesis cases (the main job)");
  command->add_option("--out", options->out, "output folder (default: report); replaced as a whole");
  command->add_flag("--no-pdf", options->no_pdf, "do not compile report.pdf");
  command->callback([options] { run_report(*options); });
}

}  // namespace backlash::cli
