// tests/symbolic/thesis_printed.hpp — compare an exact derived value with a
// number printed in the thesis, at the thesis's printed precision.
//
// A printed value "agrees" when |exact − printed| ≤ ½ unit of its last printed
// decimal (it is the exact value correctly rounded).  Otherwise it is an
// erratum, and the test passes only if reports/errata/ledger.toml records it
// (same place, case, quantity and printed text) with an `exact` value equal to
// the derived one (compared at 50 digits; rationals exactly).  A ledger entry
// for a value that agrees is reported as stale.  Tolerances are never widened
// toward a printed number.
#pragma once

#include "backlash/symbolic/exact.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace backlash::testing {

/// Where: "Eq92", "Table17"; quantity: a short stable label ("coefficient of e^{-t/5}").
void expect_printed(const std::string& where, const std::string& case_id, const std::string& quantity,
                    const GiNaC::ex& exact, const std::string& printed,
                    const symbolic::RadicalList& radicals = {});

/// Angles in degrees compare modulo 180° (±90° name the same line).
void expect_printed_angle(const std::string& where, const std::string& case_id, const std::string& quantity,
                          const GiNaC::ex& exact_degrees, const std::string& printed);

/// A decimal as written ("-.125") as the exact rational (never through a double).
GiNaC::numeric exact_decimal(const std::string& text);

/// "where" of every ledger entry (e.g. "Eq51", "Table17").
std::vector<std::string> ledger_places();

}  // namespace backlash::testing
