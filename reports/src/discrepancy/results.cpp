// results.cpp — api::discrepancy_json / discrepancy_files (backlash/api/discrepancy_pages.hpp): a discrepancy's result laid out by the report layer's GiNaC-free
// part (reports/discrepancy_pages.hpp): the step record's pages or the measured drive's.
#include "backlash/api/discrepancy_pages.hpp"

#include "backlash/reports/discrepancy_pages.hpp"

namespace backlash::api {

std::string discrepancy_json(const Discrepancy& found) {
  if (const discrepancy::DiscrepancyResult* step = found.step_result())
    return discrepancy::to_json(found.model(), *step, found.step());
  return discrepancy::drive_to_json(found.model(), *found.drive_result());
}

std::vector<std::pair<std::string, std::string>> discrepancy_files(const Discrepancy& found, const std::string& data_name,
                                                                   const std::string& validation_name) {
  if (const discrepancy::DiscrepancyResult* step = found.step_result())
    return discrepancy::report_files(found.model(), data_name, *step, found.step());
  return discrepancy::drive_report_files(found.model(), data_name, validation_name, *found.drive_result());
}

std::string corrected_case_file(const Discrepancy& found) {
  if (const discrepancy::DiscrepancyResult* step = found.step_result())
    return discrepancy::corrected_case_file(found.model(), *step, found.step());
  return discrepancy::drive_corrected_case_file(found.model(), *found.drive_result());
}

}  // namespace backlash::api
