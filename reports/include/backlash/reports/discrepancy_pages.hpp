// backlash/reports/discrepancy_pages.hpp — the discrepancy workflow's results as files
// (target backlash_discrepancy_pages: no GiNaC).  The workflow (discrepancy/) computes and
// returns results only; this lays them out: the JSON document of `discrepancy --json`, the
// Markdown page of `discrepancy --out DIR` with its figures (SVG drawn by gnuplot through
// reports/plot.hpp, the project's one plotting route: the same result gives the same
// bytes; without gnuplot the figures are left out and the page says why), and the
// corrected model as a case file (docs/discrepancy.md, "Output").  No timings in the files.
//
// The functions keep the workflow's namespace (backlash::discrepancy): they are the
// presentation of its result types.  The facade reaches them through backlash/api/
// discrepancy_pages.hpp (the same target).
#pragma once

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/model/case_spec.hpp"

#include <string>
#include <utility>
#include <vector>

namespace backlash::discrepancy {

// ------------------------------------------------------------------ a step record

/// The files of `discrepancy --out DIR`, by name: discrepancy.md (the page), figures
/// (measured_vs_models.svg, residual.svg, candidates.svg), discrepancy.json, corrected.toml.
/// `data_name`: the record's file name as the page cites it; `step`: the step A [rad] compared.
std::vector<std::pair<std::string, std::string>> report_files(const model::CaseSpec& model,
                                                              const std::string& data_name,
                                                              const DiscrepancyResult& result, double step);

/// The JSON document of `discrepancy --json` (docs/design.md, "JSON keys", and more).
std::string to_json(const model::CaseSpec& model, const DiscrepancyResult& result, double step);

/// The corrected model as a case file: the nominal file's parameters, the backlash if it was
/// refitted, and an [effects] table with the named effects (exact decimals of the fitted values).
std::string corrected_case_file(const model::CaseSpec& model, const DiscrepancyResult& result, double step);

// ------------------------------------------------------------------ a measured drive

/// The files of `discrepancy --out DIR` for a measured drive: discrepancy.md, discrepancy.json,
/// corrected.toml, torque_residual_vs_velocity.svg, torque_over_time.svg, position_window.svg,
/// candidates.svg (and validation_position_window.svg with a validation record).
std::vector<std::pair<std::string, std::string>> drive_report_files(const model::CaseSpec& model,
                                                                    const std::string& data_name,
                                                                    const std::string& validation_name,
                                                                    const DriveDiscrepancyResult& result);

/// The JSON of `discrepancy --json` (docs/design.md, "JSON keys"; torque RMS in rms_before/rms_after).
std::string drive_to_json(const model::CaseSpec& model, const DriveDiscrepancyResult& result);

/// The corrected model as a case file: refitted nominal parameters, the named effects.
std::string drive_corrected_case_file(const model::CaseSpec& model, const DriveDiscrepancyResult& result);

}  // namespace backlash::discrepancy
