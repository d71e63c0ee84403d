// The report: every case's page, the general solutions, the errata ledger, the
// index, the figures, the machine-readable outputs and report.pdf.
#include "backlash/reports/report.hpp"

#include "backlash/output/staged_directory.hpp"
#include "backlash/output/target.hpp"
#include "backlash/output/text.hpp"
#include "backlash/symbolic/derivation_output.hpp"
#include "backlash/symbolic/escape.hpp"
#include "backlash/symbolic/general_derivation.hpp"
#include "backlash/symbolic/pretty.hpp"
#include "report_parts.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

namespace backlash::reports {

namespace doc = symbolic::doc;
using doc::Rich;
namespace fs = std::filesystem;

namespace {

constexpr const char* pdf_status_token = "@@PDFSTATUS@@";
constexpr const char* figures_status_token = "@@FIGURESSTATUS@@";

std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.12g", v);
  return buffer;
}

std::string markdown(const doc::Document& d, const std::string& root) {
  doc::MarkdownOptions o;
  o.root = root;
  return doc::to_markdown(d, o);
}

// The ledger's exact value as mathematics: its closed form (GiNaC syntax in the file,
// "-180*atan(5/54)*Pi^(-1)") parsed and printed like every other formula, then its decimal.
Rich exact_cell(const Erratum& e) {
  if (e.exact.empty()) return doc::text(e.exact_decimal);
  try {
    GiNaC::symtab constants;
    constants["Pi"] = GiNaC::Pi;
    GiNaC::parser reader(constants, true);  // strict: a name that is not a constant is an error
    const std::string closed = symbolic::pretty::latex(reader(e.exact));
    return doc::math(e.exact_decimal.empty() ? closed : closed + " = " + e.exact_decimal);
  } catch (const std::exception&) {
    throw std::runtime_error("reports/errata/" + e.file + ": " + e.where + ", case " + e.case_id + ": exact = \"" + e.exact +
                             "\" is not a closed form");
  }
}

doc::Document errata_document(const std::vector<Erratum>& errata, int level) {
  doc::Document out;
  out.push_back(doc::paragraph(doc::text(
      "Every number printed in the thesis that differs from the exact value beyond its printed precision, with the exact "
      "value and a likely cause.  Source: reports/errata/*.toml; each entry is checked by the test named after its place "
      "(tests/symbolic, tests/numeric), which recomputes the exact value.  " + std::to_string(errata.size()) + " entries.")));
  std::string file;
  std::vector<std::vector<Rich>> rows;
  const auto flush = [&] {
    if (rows.empty()) return;
    doc::Block t = doc::table({doc::text("where"), doc::text("case"), doc::text("quantity"), doc::text("printed"), doc::text("exact"),
                               doc::text("likely cause")},
                              rows, "llllll");
    // 14.6 cm of columns and 12 column gaps (2.5 cm) inside the 17.4 cm text width
    t.latex_columns = ">{\\raggedright\\arraybackslash}p{1.3cm}p{0.7cm}>{\\raggedright\\arraybackslash}p{2.9cm}p{1.0cm}"
                      ">{\\raggedright\\arraybackslash}p{2.8cm}>{\\raggedright\\arraybackslash}p{5.9cm}";
    t.small = true;
    out.push_back(t);
    rows.clear();
  };
  std::map<std::string, std::size_t> counts;
  for (const Erratum& e : errata) ++counts[e.file];
  for (const Erratum& e : errata) {
    if (e.file != file) {
      flush();
      file = e.file;
      out.push_back(doc::heading(level, doc::text(file + " (" + std::to_string(counts[file]) + " entries)")));
    }
    rows.push_back({doc::text(readable(e.where)), doc::text(e.case_id), doc::text(readable(e.quantity)), doc::text(e.printed),
                    exact_cell(e), doc::text(readable(e.cause))});
  }
  flush();
  return out;
}

doc::Document general_page(const std::vector<symbolic::GeneralBranch>& branches) {
  doc::Document out;
  out.push_back(doc::heading(1, doc::text("The general solutions (thesis sections 3–5)"), "general"));
  out.push_back(doc::paragraph(doc::link("index", "README.md") + doc::text(" · ") + doc::link("errata ledger", "errata.md")));
  out.push_back(doc::paragraph(
      doc::text("With ") + doc::math("J_m, F_m, J_L, F_L, K, \\theta_R") +
      doc::text(" symbolic, the inverse transforms depend on the pole structure, and the sign of a symbolic discriminant "
                "cannot be decided; so each pole-structure branch is derived in a parametrisation that makes its structure "
                "explicit (") +
      doc::math("\\omega_c, \\delta_c, \\omega_m, \\delta_m") +
      doc::text(" replace K), verified exactly, and each thesis case is reproduced term by term by the branch the engine selects "
                "for it.  The thesis's general equations: contact ") +
      doc::math("J\\ddot\\theta_o + F\\dot\\theta_o + K\\theta_o = K\\theta_R") + doc::text(" (eqs. 15, 25); free motor ") +
      doc::math("J_m\\ddot\\theta_m + F_m\\dot\\theta_m + K\\theta_m = K\\theta_R") + doc::text(" (eq. 16, output at the motor) or ") +
      doc::math("J_m\\ddot\\theta_m + F_m\\dot\\theta_m = K(\\theta_R - \\theta_L)") + doc::text(" (eq. 39, output at the load); "
                                                                                                   "free load ") +
      doc::math("J_L\\ddot\\theta_L + F_L\\dot\\theta_L = 0") + doc::text(" (eq. 17); separation line ") +
      doc::math("\\theta_{m0} = \\theta_R + \\cot\\varphi\\,\\dot\\theta_{m0}") + doc::text(" (eq. 19); momentum ") +
      doc::math("(J_m + J_L)\\dot\\theta_o = J_m\\dot\\theta_m + J_L\\dot\\theta_L") + doc::text(" (eq. 24).")));
  // The thesis's general forms, in its notation (cot φ for 1/tan φ); each is checked against the
  // derivation of every branch by the test named after it (tests/symbolic/exam_thesis_equations.cpp).
  const auto eq = [&](const std::string& body, const std::string& tag) { out.push_back(doc::equation(body + " \\tag{" + tag + "}")); };
  out.push_back(doc::heading(2, doc::text("The thesis's general equations")));
  out.push_back(doc::paragraph(doc::text("Contact, and the stability constant of its log-spiral trajectories (a = F/2J, ") +
                               doc::math("\\omega_c^2 = K/J - a^2") + doc::text("):")));
  eq("J\\ddot\\theta_o + F\\dot\\theta_o + K\\theta_o = K\\theta_R,\\qquad J = J_m + J_L,\\ F = F_m + F_L", "15, 25");
  eq("C = \\frac{1}{\\omega_c}\\sqrt{\\dot\\theta_o^2 - \\frac{F}{J}\\dot\\theta_o(\\theta_R - \\theta_o) + \\frac{K}{J}(\\theta_R - \\theta_o)^2}\\,"
     "\\exp\\left(\\frac{a}{\\omega_c}\\arctan\\frac{\\dot\\theta_o - a(\\theta_R - \\theta_o)}{\\omega_c(\\theta_R - \\theta_o)}\\right)",
     "38");
  out.push_back(doc::paragraph(doc::text("Free motion from the separation line; the motor alone, output at the motor:")));
  eq("J_m\\ddot\\theta_m + F_m\\dot\\theta_m + K\\theta_m = K\\theta_R", "16");
  eq("J_L\\ddot\\theta_L + F_L\\dot\\theta_L = 0", "17");
  eq("\\Theta_m(s)\\left(s^2 + \\frac{F_m}{J_m}s + \\frac{K}{J_m}\\right) = \\frac{K\\theta_R}{J_m s} + s\\theta_{m0} + \\frac{F_m}{J_m}\\theta_{m0} + \\dot\\theta_{m0}", "18");
  eq("\\theta_{m0} = \\theta_R + \\cot\\varphi\\,\\dot\\theta_{m0},\\qquad \\cot\\varphi = \\frac{J_m F_L - F_m J_L}{K J_L}", "19");
  eq("\\Theta_m(s) = \\frac{K\\theta_R}{J_m s\\left(s^2 + \\frac{F_m}{J_m}s + \\frac{K}{J_m}\\right)} + \\frac{\\theta_{m0}\\left(s + \\frac{F_m}{J_m}\\right) + \\dot\\theta_{m0}}{s^2 + \\frac{F_m}{J_m}s + \\frac{K}{J_m}}", "20");
  eq("\\dot\\Theta_m(s) = s\\,\\Theta_m(s) - \\theta_{m0} = \\frac{\\dot\\theta_{m0}\\,s + \\frac{K}{J_m}\\left(\\theta_R - \\theta_{m0}\\right)}{s^2 + \\frac{F_m}{J_m}s + \\frac{K}{J_m}}", "21");
  out.push_back(doc::paragraph(doc::text("(The printed eq. 21 multiplies all of eq. 20 by s: without ") + doc::math("-\\theta_{m0}") +
                               doc::text(" it is improper and its inverse would carry an impulse; the form above is the one "
                                         "test Eq21_General_MotorAloneVelocityLaplace checks.)")));
  eq("\\Theta_L(s) = \\frac{\\theta_{m0}\\left(s + \\frac{F_L}{J_L}\\right) + \\dot\\theta_{m0}}{s\\left(s + \\frac{F_L}{J_L}\\right)},\\qquad "
     "\\dot\\Theta_L(s) = \\frac{\\dot\\theta_{m0}}{s + \\frac{F_L}{J_L}}", "22, 23");
  eq("(J_m + J_L)\\dot\\theta_o = J_m\\dot\\theta_m + J_L\\dot\\theta_L", "24");
  out.push_back(doc::paragraph(doc::text("Output at the load: the motor is driven open loop by the load's error,")));
  eq("J_m\\ddot\\theta_m + F_m\\dot\\theta_m = K(\\theta_R - \\theta_L)", "39");
  eq("\\Theta_m(s) = -\\frac{\\frac{K}{J_m}\\cot\\varphi\\,\\dot\\theta_{m0}}{s^2\\left(s + \\frac{F_m}{J_m}\\right)} - \\frac{\\frac{K}{J_m}\\dot\\theta_{m0}}{s^2\\left(s + \\frac{F_m}{J_m}\\right)\\left(s + \\frac{F_L}{J_L}\\right)} + "
     "\\frac{\\dot\\theta_{m0}}{s\\left(s + \\frac{F_m}{J_m}\\right)} + \\frac{\\theta_{m0}}{s}", "40");
  eq("\\dot\\Theta_m(s) = -\\frac{\\frac{K}{J_m}\\cot\\varphi\\,\\dot\\theta_{m0}}{s\\left(s + \\frac{F_m}{J_m}\\right)} - \\frac{\\frac{K}{J_m}\\dot\\theta_{m0}}{s\\left(s + \\frac{F_m}{J_m}\\right)\\left(s + \\frac{F_L}{J_L}\\right)} + "
     "\\frac{\\dot\\theta_{m0}}{s + \\frac{F_m}{J_m}}", "41");
  out.push_back(doc::heading(2, doc::text("The solutions, branch by branch")));
  for (doc::Block& b : symbolic::general_document(branches, 3)) out.push_back(std::move(b));
  return out;
}

std::string latex_preamble() {
  return R"(\documentclass[10pt,a4paper]{article}
\usepackage[utf8]{inputenc}
\usepackage{amsmath,amssymb}
\usepackage[margin=1.8cm]{geometry}
\usepackage{graphicx}
\usepackage{longtable,booktabs,array}
\usepackage{float}
\usepackage{caption}
\pdfinfoomitdate=1
\pdftrailerid{}
\pdfsuppressptexinfo=-1
\allowdisplaybreaks
\setlength{\emergencystretch}{4em}
\setlength{\parindent}{0pt}
\setlength{\parskip}{4pt}
\setcounter{secnumdepth}{2}
\setcounter{tocdepth}{1}
\title{Dividing lines for backlash, exactly:\\ the thesis's eight cases derived, traced and checked}
\author{generated by \texttt{backlash report}}
\date{}
\begin{document}
\maketitle
\tableofcontents
\clearpage
)";
}

}  // namespace

bool pdflatex_available() { return std::system("command -v pdflatex > /dev/null 2>&1") == 0; }

namespace {
struct PhaseTimer {
  const char* what;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  explicit PhaseTimer(const char* w) : what(w) {}
  ~PhaseTimer() {
    if (std::getenv("BACKLASH_REPORT_TIMING"))
      std::cerr << what << ": " << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s\n";
  }
};

// The LaTeX document being assembled, page after page.
struct LatexBook {
  std::ostringstream text;
  doc::LatexOptions options;
  LatexBook() {
    text << latex_preamble();
    options.top_level = 1;  // page heading 1 → \section
  }
  void add(const doc::Document& page) { text << "\\clearpage\n" << doc::to_latex(page, options); }
};

std::string validation_json(const CaseResult& c) {
  nlohmann::json v{{"case", c.spec.id}, {"evaluator", c.validation().report().evaluator}, {"passed", c.validation().passed()}};
  for (const numeric::StateError& s : c.validation().report().states)
    v["states"].push_back({{"state", s.state}, {"max_abs_error", s.max_abs_error}, {"at_t", s.at_t}, {"passed", s.passed}});
  return v.dump(2) + "\n";
}

std::string dividing_lines_csv(const CaseResult& c) {
  std::ostringstream lines;
  lines << "v0,status,t,theta_m,dtheta_m,theta_L,dtheta_L,theta_o,dtheta_o\n";
  for (const numeric::DividingLines* l : {&c.lines_negative, &c.lines_positive})
    for (const numeric::DividingLinePoint& q : l->points)
      lines << csv_number(q.dtheta_m0) << "," << numeric::to_string(q.status) << "," << csv_number(q.t) << "," << csv_number(q.theta_m) << ","
            << csv_number(q.dtheta_m) << "," << csv_number(q.theta_L) << "," << csv_number(q.dtheta_L) << "," << csv_number(q.theta_o)
            << "," << csv_number(q.dtheta_o) << "\n";
  return lines.str();
}

std::string step_response_csv(const TrajectoryRun& run) {
  std::ostringstream csv;
  csv << "t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode\n";
  for (const numeric::TrajectorySample& s : run.result.samples)
    csv << csv_number(s.t) << "," << csv_number(s.theta_o) << "," << csv_number(s.dtheta_o) << "," << csv_number(s.theta_m) << ","
        << csv_number(s.dtheta_m) << "," << csv_number(s.theta_L) << "," << csv_number(s.dtheta_L) << ","
        << (s.in_contact ? "contact" : "free") << "\n";
  return csv.str();
}

// A run's label as a file name: letters, digits, '.' and '-' kept, anything else '_'.
std::string file_label(std::string name) {
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-') ch = '_';
  return name;
}

// One case: its page (Markdown and LaTeX), its figures and its machine-readable outputs.
void add_case(BuiltReport& report, LatexBook& latex, const CaseResult& c, const ThesisData& data) {
  const std::string& id = c.spec.id;
  PhaseTimer case_timer("  case page");
  const doc::Document page = case_document(c, data);
  report.files["cases/" + id + ".md"] = markdown(page, "../");
  report.case_pages[id] = "cases/" + id + ".md";
  report.case_equations[id] = c.thesis->equations;
  latex.add(page);
  for (Plot& plot : case_figures(c, data)) report.figures.push_back(std::move(plot));

  report.files["derivations/" + id + ".json"] = symbolic::to_json(c.derivation).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  report.files["derivations/" + id + ".tex"] = symbolic::to_latex(c.derivation);
  report.files["validation/" + id + ".json"] = validation_json(c);
  report.files["dividing_lines/" + id + ".csv"] = dividing_lines_csv(c);
  for (const TrajectoryRun& run : c.runs) report.files["step_responses/" + id + "_" + file_label(run.label) + ".csv"] = step_response_csv(run);
}

// The general solutions: their page and the branches' JSON and LaTeX.
void add_general(BuiltReport& report, LatexBook& latex, const std::vector<symbolic::GeneralBranch>& branches) {
  PhaseTimer timer("general page");
  const doc::Document page = general_page(branches);
  report.files["general.md"] = markdown(page, "");
  latex.add(page);
  nlohmann::json all = nlohmann::json::array();
  std::string tex;
  for (const symbolic::GeneralBranch& b : branches) {
    all.push_back(symbolic::to_json(b));
    tex += symbolic::to_latex(b) + "\n";
  }
  report.files["derivations/general.json"] = all.dump(2) + "\n";
  report.files["derivations/general.tex"] = tex;
}

std::string sweep_csv(const SweepResult& s) {
  std::ostringstream csv;
  csv << "series,x,Jm,Fm,JL,FL,status,peak_to_peak,period,multiplier\n";
  for (const numeric::SweepRow& r : s.rows) {
    const numeric::Parameters& q = r.point.parameters;
    csv << symbolic::escape::csv_field(r.point.series) << "," << csv_number(r.point.x) << "," << csv_number(q.Jm) << "," << csv_number(q.Fm)
        << "," << csv_number(q.JL) << "," << csv_number(q.FL) << "," << symbolic::escape::csv_field(numeric::to_string(r.status));
    if (r.status == numeric::SweepStatus::LimitCycle)
      csv << "," << csv_number(r.cycle.peak_to_peak) << "," << csv_number(r.cycle.period) << "," << csv_number(r.cycle.multiplier) << "\n";
    else
      csv << ",,,\n";
  }
  return csv.str();
}

// The errata ledger's own page.
void add_errata(BuiltReport& report, LatexBook& latex, const ThesisData& data) {
  doc::Document page{doc::heading(1, doc::text("The errata ledger"), "errata"), doc::paragraph(doc::link("index", "README.md"))};
  for (doc::Block& b : errata_document(data.errata, 2)) page.push_back(std::move(b));
  report.files["errata.md"] = markdown(page, "");
  latex.add(page);
}

// The index's row of one case: its limit cycle beside the thesis's and the describing function's.
std::vector<Rich> case_summary_row(const CaseResult& c, const ThesisData& data) {
  std::size_t errata_count = 0;
  for (const Erratum& e : data.errata) errata_count += e.case_id == c.spec.id ? 1 : 0;
  const bool cycle = c.cycle.status == numeric::CycleStatus::LimitCycle;
  std::string comparison;
  if (cycle && c.thesis->limit_cycle_printed != "none")
    comparison = sig(100 * (printed_number(c.thesis->limit_cycle_printed) / c.cycle.peak_to_peak - 1), 3) + "%";
  else if (!cycle && c.thesis->limit_cycle_printed == "none")
    comparison = "agree: none";
  else
    comparison = "DISAGREE";
  const auto predicted = c.describing_function.predicted();
  return {doc::link(c.spec.id, "cases/" + c.spec.id + ".md"), doc::text(std::to_string(c.thesis->section)),
          doc::text(model::to_string(c.spec.measured_at)), doc::text(cycle ? "yes" : "none"),
          doc::text(cycle ? fixed(c.cycle.peak_to_peak, 6) : "—"), doc::text(c.thesis->limit_cycle_printed),
          doc::text(comparison),
          doc::text(c.describing_function.applicable ? (predicted ? fixed(predicted->load_peak_to_peak, 6) : "none") : "n/a"),
          doc::text(std::to_string(errata_count))};
}

// The index's opening and its table of the eight cases.
void index_cases(doc::Document& index, const std::vector<CaseResult>& cases, const ThesisData& data) {
  index.push_back(doc::heading(1, doc::text("backlash report: the thesis's eight cases, exactly")));
  index.push_back(doc::paragraph(doc::text(
      "Generated by backlash report from the thesis Dividing lines for backlash in the phase plane (the cases in cases/, "
      "the thesis's printed numbers in the data files and the errata ledger).  Each case has a page that replaces its "
      "section of the thesis: the model, the derivation step by step with the thesis's equation numbers, the separation "
      "line and isoclines, the dividing lines beside the thesis's tables, the step responses and the limit cycle beside "
      "the thesis's numbers, the describing-function prediction, and the validated generated evaluator.  Every number "
      "is computed; none is typed by hand.")));
  index.push_back(doc::paragraph(doc::text(pdf_status_token)));
  index.push_back(doc::paragraph(doc::text(figures_status_token)));
  index.push_back(doc::heading(2, doc::text("The eight cases")));
  std::vector<std::vector<Rich>> rows;
  for (const CaseResult& c : cases) rows.push_back(case_summary_row(c, data));
  index.push_back(doc::table({doc::text("case"), doc::text("section"), doc::text("output at"), doc::text("limit cycle"),
                              doc::text("exact magnitude (peak-to-peak θo)"), doc::text("thesis (section 14)"),
                              doc::text("thesis vs exact"), doc::text("describing function"), doc::text("errata")},
                             rows, "lrllrrrrr"));
  index.back().latex_columns = "lrllp{2.2cm}p{1.6cm}p{1.6cm}p{2.2cm}r";
  index.push_back(doc::paragraph(
      doc::text("The describing function (the classical prediction, see each case page) gives the same magnitude for every "
                "case with the same total inertia, friction, gain and backlash, whatever their split between motor and load; "
                "the exact cycles differ.")));
}

// The index's list of pages and files, the table of the redrawn figures and the errata ledger.
void index_files(doc::Document& index, std::size_t branch_count, const ThesisData& data) {
  index.push_back(doc::heading(2, doc::text("Pages and files")));
  index.push_back(doc::list({doc::link("general solutions", "general.md") +
                                 doc::text(": the " + std::to_string(branch_count) + " pole-structure branches (sections 3–5)"),
                             doc::link("errata ledger", "errata.md") + doc::text(": every printed number that differs, with its cause"),
                             doc::text("report.pdf: all of it as one document (when pdflatex is installed)"),
                             doc::text("derivations/CASE.json, .tex; validation/CASE.json; dividing_lines/CASE.csv; "
                                       "step_responses/CASE_*.csv; sweeps/fig31.csv, fig32.csv; figures/NAME.svg, .pdf, .csv "
                                       "(the data of every figure)")}));
  index.push_back(doc::heading(2, doc::text("The thesis's figures, redrawn")));
  std::vector<std::vector<Rich>> figure_rows;
  for (const FigureSpec& f : data.figures)
    figure_rows.push_back({doc::text(std::to_string(f.number)), doc::text(f.case_id.empty() ? "—" : f.case_id), doc::text(f.what),
                           doc::link(figure_name(f) + ".svg", "figures/" + figure_name(f) + ".svg")});
  index.push_back(doc::table({doc::text("fig."), doc::text("case"), doc::text("what the thesis shows"), doc::text("file")},
                             figure_rows, "rlll"));
  index.back().latex_columns = "rlp{9cm}p{5cm}";
  index.back().small = true;
  index.push_back(doc::heading(2, doc::text("The errata ledger in full")));
  for (doc::Block& b : errata_document(data.errata, 3)) index.push_back(std::move(b));
}

}  // namespace

BuiltReport build_report(const DataPaths& paths) {
  BuiltReport report;
  const ThesisData data = load_thesis_data(paths);
  std::vector<CaseResult> cases;
  {
    PhaseTimer timer("compute cases");
    for (const std::string& id : model::thesis_case_ids()) cases.push_back(compute_case(id, data));
  }
  std::vector<symbolic::GeneralBranch> branches;
  {
    PhaseTimer timer("general branches");
    branches = symbolic::derive_general_branches();
  }
  std::vector<SweepResult> sweeps;
  {
    PhaseTimer timer("sweeps");
    sweeps = compute_sweeps();
  }

  LatexBook latex;
  PhaseTimer pages_timer("pages");
  for (const CaseResult& c : cases) add_case(report, latex, c, data);
  add_general(report, latex, branches);
  // the sweeps (figs. 31, 32)
  for (Plot& plot : sweep_figures(sweeps, cases, data)) report.figures.push_back(std::move(plot));
  for (const SweepResult& s : sweeps) report.files["sweeps/" + s.name + ".csv"] = sweep_csv(s);
  add_errata(report, latex, data);
  doc::Document index;
  index_cases(index, cases, data);
  index_files(index, branches.size(), data);
  report.files["README.md"] = markdown(index, "");

  latex.text << "\\end{document}\n";
  report.latex_document = latex.text.str();
  for (const Plot& plot : report.figures) report.files["figures/" + plot.name + ".csv"] = figure_csv(plot);
  return report;
}

namespace {

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// One pdflatex pass in `dir`; the log's text.
bool run_pdflatex(const fs::path& dir, std::string& log) {
  const std::string command = "cd " + output::shell_word(dir.string()) +
                              " && SOURCE_DATE_EPOCH=0 FORCE_SOURCE_DATE=1 pdflatex -interaction=nonstopmode -halt-on-error "
                              "report.tex > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  log = read_text(dir / "report.log");
  return status == 0;
}

}  // namespace

ReportResult write_report(const ReportOptions& options) {
  output::check_target(options.out, output::Target::folder);
  BuiltReport report = build_report();
  output::StagedDirectory stage(options.out);
  ReportResult result;

  // figures first (the pages refer to them)
  const std::optional<std::string> figure_failure = render_figures(report.figures, stage.path());
  result.figures_drawn = !figure_failure;
  result.figures_note = figure_failure ? "The figures were not drawn: " + *figure_failure + " (their data is in figures/*.csv)."
                                       : std::to_string(report.figures.size()) + " figures drawn with gnuplot (figures/*.svg for "
                                                                                "the web, *.pdf for report.pdf, *.csv their data).";
  // the PDF
  std::string pdf_note;
  if (!options.pdf) {
    pdf_note = "report.pdf was not requested.";
  } else if (!pdflatex_available()) {
    pdf_note = "report.pdf was not compiled: pdflatex is not installed (Debian: texlive-latex-recommended); the LaTeX source is report.tex.";
    std::cerr << "backlash: note: " << pdf_note << "\n";
  } else if (!result.figures_drawn) {
    pdf_note = "report.pdf was not compiled: its figures could not be drawn; the LaTeX source is report.tex.";
    std::cerr << "backlash: note: " << pdf_note << "\n";
  } else {
    stage.write("report.tex", report.latex_document);
    std::string log;
    bool ok = run_pdflatex(stage.path(), log);
    if (ok && (log.find("Rerun to get") != std::string::npos || log.find("Label(s) may have changed") != std::string::npos ||
               log.find("No file report.toc") != std::string::npos))
      ok = run_pdflatex(stage.path(), log);
    if (!ok) {
      std::string error;
      const auto at = log.find("\n!");
      if (at != std::string::npos) error = log.substr(at + 1, log.find('\n', at + 2) - at - 1);
      throw std::runtime_error("pdflatex failed on report.tex: " + (error.empty() ? std::string("see its log") : error));
    }
    std::smatch m;
    const std::regex pages("Output written on report\\.pdf \\(([0-9]+) pages?");
    result.pdf_written = true;
    pdf_note = std::regex_search(log, m, pages) ? "report.pdf: compiled with pdflatex, " + m[1].str() + " pages." : "report.pdf: compiled with pdflatex.";
    for (const char* extension : {".aux", ".log", ".toc", ".out"}) fs::remove(stage.path() / (std::string("report") + extension));
  }
  if (!result.pdf_written) stage.write("report.tex", report.latex_document);
  result.pdf_note = pdf_note;

  // the pages, with the status lines filled in
  for (auto& [path, content] : report.files) {
    std::string text = content;
    if (path == "README.md") {
      text.replace(text.find(pdf_status_token), std::string(pdf_status_token).size(), symbolic::escape::markdown_text(pdf_note));
      text.replace(text.find(figures_status_token), std::string(figures_status_token).size(),
                   symbolic::escape::markdown_text(result.figures_note));
    }
    stage.write(path, text);
  }
  result.files = report.files.size() + (result.figures_drawn ? 2 * report.figures.size() : 0) + 1 + (result.pdf_written ? 1 : 0);
  stage.commit();
  result.out = options.out;
  return result;
}

}  // namespace backlash::reports
