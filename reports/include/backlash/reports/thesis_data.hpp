// backlash/reports/thesis_data.hpp — the thesis's printed numbers and the
// report's data files, read (never typed into code):
//   reports/errata/*.toml                          the errata ledger
//   reports/data/thesis_cases.toml                 sections 6–13: equation numbers, slots,
//                                                  tables, figures, worked trajectories,
//                                                  section 14's printed magnitudes
//   reports/data/thesis_figures.toml               the figures the report redraws
//   reports/data/thesis_step_tables.toml           Tables 5 and 10
//   tests/numeric/data/thesis_dividing_line_tables.toml  Tables 4 … 31, cell by cell
// A malformed file is an error naming the file.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace backlash::reports {

struct DataPaths {
  std::filesystem::path errata_directory;
  std::filesystem::path data_directory;
  std::filesystem::path dividing_line_tables;
};
/// The files of the data folder (model/data_dir.hpp, found at run time): errata/,
/// data/ and data/thesis_dividing_line_tables.toml of share/backlash — in the build
/// tree links to reports/errata, reports/data/*.toml and
/// tests/numeric/data/thesis_dividing_line_tables.toml.
DataPaths default_data_paths();

struct Erratum {
  std::string file, where, case_id, quantity, printed, exact, exact_decimal, cause;
};
std::vector<Erratum> load_errata(const std::filesystem::path& directory);
/// The entry for (where, case, quantity), or null.
const Erratum* find_erratum(const std::vector<Erratum>& errata, const std::string& where, const std::string& case_id,
                            const std::string& quantity);

struct Trajectory {
  std::string kind;      ///< "step" | "state"
  std::string step;      ///< kind step
  std::string theta_o, dtheta_o;  ///< kind state
  std::string quote;
};

struct ThesisCase {
  std::string id, title, summary, limit_cycle_printed;
  int section = 0;
  std::vector<int> equations, tables, figures;
  std::map<std::string, std::string> slots;
  std::vector<Trajectory> trajectories;
};
std::vector<ThesisCase> load_thesis_cases(const std::filesystem::path& file);

struct FigureSpec {
  int number = 0;
  std::string kind, case_id, dtheta_m0, t_end, sweep, what;
  std::vector<std::string> dividers, trajectories;
};
std::vector<FigureSpec> load_figures(const std::filesystem::path& file);

struct StepPoint {
  std::string table, case_id, step, t, quantity, printed;
};
std::vector<StepPoint> load_step_points(const std::filesystem::path& file);

struct DividingLineCell {
  std::string table, case_id, v0, quantity, printed;
};
std::vector<DividingLineCell> load_dividing_line_cells(const std::filesystem::path& file);

/// A number as the thesis prints it (".52", "-.0504") as a double.
double printed_number(const std::string& text);
/// Digits after the decimal point ("1.030" → 3, "1" → 0).
int printed_decimals(const std::string& text);
/// |value − printed| ≤ ½ unit of the printed last digit.
bool agrees_with_printed(double value, const std::string& printed);

}  // namespace backlash::reports
