// backlash/reports/report.hpp — the report `backlash report` writes: for each of
// the thesis's eight cases a page that reads like the chapter it replaces
// (Markdown for GitHub/GitLab and a LaTeX section), the general solutions, the
// errata ledger, every figure of the thesis redrawn (SVG for the web, PDF for report.pdf, its data as CSV),
// the machine-readable outputs (JSON, CSV), and report.pdf when pdflatex is
// installed.  Nothing in a page is typed by hand: the derivations come from
// symbolic/, the numbers from numeric/, the thesis's printed values from the
// data files (thesis_data.hpp).
//
// The output is byte-reproducible (canonical printing, no dates, fixed PDF
// metadata) and atomic (backlash/output/staged_directory.hpp).
#pragma once

#include "backlash/reports/plot.hpp"
#include "backlash/reports/thesis_data.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace backlash::reports {

struct ReportOptions {
  std::filesystem::path out = "report";
  bool pdf = true;  ///< compile report.pdf when pdflatex is installed
};

struct ReportResult {
  std::filesystem::path out;
  std::size_t files = 0;
  bool figures_drawn = false;
  std::string figures_note;  ///< why not, when not drawn
  bool pdf_written = false;
  std::string pdf_note;      ///< "report.pdf: 91 pages", or why there is none
};

/// Everything of the report that is computed (no files written, no tools run).
struct BuiltReport {
  std::map<std::string, std::string> files;  ///< relative path → content
  std::vector<Plot> figures;                 ///< drawn as figures/NAME.{svg,pdf,csv}
  std::string latex_document;                ///< report.tex
  /// Per case: the thesis's equation numbers of its section (from the data file) and its page.
  std::map<std::string, std::vector<int>> case_equations;
  std::map<std::string, std::string> case_pages;  ///< case id → "cases/V.md"
};

BuiltReport build_report(const DataPaths& paths = default_data_paths());

/// Build, draw, compile and move into place.  output::OutputError (bad_target) for an unusable --out
/// (checked before anything is computed); any other failure leaves nothing behind.
ReportResult write_report(const ReportOptions& options);

/// True when `pdflatex` can be run.
bool pdflatex_available();

}  // namespace backlash::reports
