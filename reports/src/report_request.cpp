// report_request.cpp — api::write_report (backlash/api/report.hpp), `backlash report` on the facade: the report layer (reports/report.hpp)
// reads its numbers from api::Model and api::sweep, its derivations from api::derive_exact.
#include "backlash/api/report.hpp"

#include "backlash/reports/report.hpp"

namespace backlash::api {

Report write_report(const ReportRequest& request) {
  reports::ReportOptions options;
  options.out = request.out;
  options.pdf = request.pdf;
  const reports::ReportResult written = reports::write_report(options);
  Report out;
  out.out = written.out;
  out.files = written.files;
  out.figures_drawn = written.figures_drawn;
  out.figures_note = written.figures_note;
  out.pdf_note = written.pdf_note;
  return out;
}

}  // namespace backlash::api
