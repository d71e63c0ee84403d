// backlash/api/discrepancy_pages.hpp — a discrepancy's result (backlash/api/backlash.hpp:
// api::discrepancy) as files and documents: the JSON of `discrepancy --json`, the page,
// figures, JSON and corrected case file of `discrepancy --out DIR` (target
// backlash::discrepancy_pages, no GiNaC).  The workflow computes (discrepancy/, through the
// facade); this layout is built on the facade's result, and the facade links nothing of it: a
// program asking for these links backlash::discrepancy_pages.
//
//   const api::Discrepancy found = api::discrepancy(api::load("V"), api::read_record("d.csv"));
//   std::cout << api::discrepancy_json(found);   // = `backlash discrepancy ... --json`
#pragma once

#include "backlash/api/backlash.hpp"

#include <string>
#include <utility>
#include <vector>

namespace backlash::api {

/// `discrepancy --json` (docs/design.md, "JSON keys"), final newline included.
std::string discrepancy_json(const Discrepancy& found);

/// The files of `discrepancy --out DIR` by name (discrepancy.md, its SVG figures,
/// discrepancy.json, corrected.toml); `data_name`, `validation_name`: the records' file
/// names as the page cites them.
std::vector<std::pair<std::string, std::string>> discrepancy_files(const Discrepancy& found, const std::string& data_name,
                                                                   const std::string& validation_name = "");

/// The corrected model as a case file (loads and simulates as it is).
std::string corrected_case_file(const Discrepancy& found);

}  // namespace backlash::api
