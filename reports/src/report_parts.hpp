// reports/src/report_parts.hpp — the pieces of the report (internal).
#pragma once

#include "backlash/api/backlash.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/dividing_lines.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"
#include "backlash/numeric/validation.hpp"
#include "backlash/reports/describing_function.hpp"
#include "backlash/reports/plot.hpp"
#include "backlash/reports/thesis_data.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/document.hpp"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace backlash::reports {

/// The thesis's data the report reads once.
struct ThesisData {
  std::vector<Erratum> errata;
  std::vector<ThesisCase> cases;
  std::vector<FigureSpec> figures;
  std::vector<StepPoint> step_points;
  std::vector<DividingLineCell> dividing_line_cells;
  const ThesisCase& thesis_case(const std::string& id) const;
};
ThesisData load_thesis_data(const DataPaths& paths);

/// A trajectory the case page shows: the case file's step or one of the thesis's others.
struct TrajectoryRun {
  std::string label;        ///< "step 0.62"
  std::string source;       ///< "case file [experiment]" or the thesis's words
  bool is_step = true;
  double step = 0;          ///< is_step
  double theta_o0 = 0, dtheta_o0 = 0;  ///< !is_step: start on the separation line
  numeric::SimulationResult result;
};

/// One case's results, every number a facade result (api/report.hpp): `model` is the
/// validated api::Model the page asks for more (a table's dividing-line point, a state at a
/// printed time); the derivation and the header come from api::derive_exact.
struct CaseResult {
  model::CaseSpec spec;
  const ThesisCase* thesis = nullptr;
  std::shared_ptr<const api::Model> model;
  symbolic::CaseDerivation derivation;
  numeric::Parameters parameters;
  numeric::DividingLines lines_positive, lines_negative;  ///< loci of both faces
  std::vector<TrajectoryRun> runs;                       ///< [0]: the case file's step
  numeric::LimitCycle cycle;
  std::vector<numeric::TrajectorySample> cycle_orbit;    ///< one period from the separation point
  DescribingFunctionPrediction describing_function;
  std::string generated_header;                          ///< codegen's header for the case
  const numeric::ValidationResult& validation() const { return model->validation(); }
  const numeric::ValidatedEvaluator& evaluator() const { return model->evaluator(); }
};

CaseResult compute_case(const std::string& id, const ThesisData& data);

/// The figures of one case (thesis figures and the extra step-response figure).
std::vector<Plot> case_figures(const CaseResult& c, const ThesisData& data);
/// The sweep figures (31, 32) and their CSV.
struct SweepResult {
  std::string name;  ///< "fig31" | "fig32"
  std::vector<numeric::SweepRow> rows;
};
std::vector<SweepResult> compute_sweeps();
std::vector<Plot> sweep_figures(const std::vector<SweepResult>& sweeps, const std::vector<CaseResult>& cases,
                                const ThesisData& data);

/// The file stem (under figures/) of a thesis figure.
std::string figure_name(const FigureSpec& spec);
/// The thesis figures of a case, in the data file's order.
std::vector<const FigureSpec*> figures_of(const ThesisData& data, const std::string& case_id);

/// The case's page.
symbolic::doc::Document case_document(const CaseResult& c, const ThesisData& data);

/// Formatting helpers.
std::string fixed(double v, int decimals);
std::string sig(double v, int significant = 6);
std::string roman_to_anchor(const std::string& id);
/// A data file's text as a reader's: the ledger's keys and causes name quantities as
/// identifiers ("Table20", "dtheta_m0", "theta_L dot", "Eq38"); pages print "Table 20",
/// "θ̇m0", "θ̇L", "eq. 38".
std::string readable(const std::string& text);

}  // namespace backlash::reports
