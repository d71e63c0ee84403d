// backlash/api/report.hpp — `backlash report` on the facade (target backlash_reports, the report
// layer built on the numeric facade and the GiNaC facade, backlash/api/derive.hpp; the facade
// links nothing of it).
//
// The report: for each of the thesis's eight cases a page (Markdown + LaTeX) that reads like
// the chapter it replaces, the general solutions, the errata ledger, every thesis figure
// redrawn (gnuplot: SVG, PDF, their data as CSV), the machine-readable outputs and
// report.pdf when pdflatex is installed (reports/report.hpp lays it out).  Every number of
// it is a facade result: per case an api::Model (backlash/api/backlash.hpp) gives the
// validation report, the dividing lines (Model::trace), the step responses and the thesis's
// second inputs (Model::simulate, Model::simulate_from), the limit cycle and its orbit
// (Model::limit_cycle, Model::simulate_from); api::sweep gives figs. 31 and 32; the exact
// derivation and the evaluator header come from api::derive_exact (derive.hpp).
//
// The output is byte-reproducible (canonical printing, no dates, fixed PDF metadata) and
// atomic: the folder appears all at once, or not at all.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

namespace backlash::api {

struct ReportRequest {
  std::filesystem::path out = "report";  ///< the output folder, replaced as a whole
  bool pdf = true;                       ///< compile report.pdf when pdflatex is installed
};

struct Report {
  std::filesystem::path out;
  std::size_t files = 0;     ///< files written
  bool figures_drawn = false;
  std::string figures_note;  ///< why the figures were not drawn (gnuplot missing), when not
  std::string pdf_note;      ///< "report.pdf: 91 pages", or why there is none
};

/// Computes, draws, compiles and moves the report into place.  reports::BadInput (one line,
/// a bad-input error: exit 2) for an unusable `out`, checked before anything is computed;
/// any other failure leaves nothing behind.
Report write_report(const ReportRequest& request);

}  // namespace backlash::api
