// reports/src/discrepancy/case_file_text.hpp (internal) — the corrected case file's text
// pieces (case_file.cpp): the shortest decimal that reads back as the same double, a TOML
// basic string (backlash/output/text.hpp), and the original exact value when the fit kept it
// (else the decimal).
#pragma once

#include "backlash/model/case_spec.hpp"
#include "backlash/output/text.hpp"

#include <string>

namespace backlash::discrepancy::detail {

std::string decimal(double value);
using output::toml_string;
std::string exact_or(const model::Rational& original, double value);

}  // namespace backlash::discrepancy::detail
