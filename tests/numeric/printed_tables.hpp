// tests/numeric/printed_tables.hpp — compare a computed value with a number
// printed in one of the thesis's dividing-line, step-response or limit-cycle
// tables, at the printed precision.
//
// Same rule as the equation tests (tests/symbolic/thesis_printed.hpp), for
// values computed in double precision from the validated closed forms (their
// error, ≤ 1e-9 by the validation gate, is far below any printed digit):
// a printed value agrees when |value − printed| ≤ ½ unit of its last digit;
// otherwise reports/errata/<ledger> must record it (same table, case, quantity,
// printed text) with `exact_decimal` equal to the computed value within 1e-8.
#pragma once

#include "backlash/numeric/validation.hpp"

#include <string>
#include <vector>

namespace backlash::testing {

/// A thesis case's generated evaluator through the validation gate (cached per test process).
const numeric::ValidatedEvaluator& validated_thesis_case(const std::string& case_id);

struct PrintedCell {
  std::string table, case_id, v0, quantity, printed;
};

/// The transcribed cells of tests/numeric/data/thesis_dividing_line_tables.toml for one table.
std::vector<PrintedCell> printed_cells(const std::string& table);

/// `ledger` is a file name under reports/errata/.  A NaN value means the printed
/// quantity does not exist; the ledger must then record exact_decimal = "none".
void expect_printed_value(const std::string& ledger, const std::string& table, const std::string& case_id,
                          const std::string& quantity, double value, const std::string& printed);

/// A decimal as printed ("-.0504") as a double.
double printed_number(const std::string& text);

}  // namespace backlash::testing
