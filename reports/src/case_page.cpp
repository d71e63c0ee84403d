// One case's page: the derivation (symbolic/derivation_output) followed by the
// dividing lines, step responses, limit cycle, describing function and the
// generated evaluator — each beside the thesis's printed numbers.
#include "report_parts.hpp"

#include "backlash/symbolic/derivation_output.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace backlash::reports {

namespace doc = symbolic::doc;
using doc::Rich;

namespace {

// Decimals of `printed` that the exact value reproduces (rounded), 0 … printed decimals; −1 if not even the integer part.
int agreeing_decimals(double exact, const std::string& printed) {
  const double p = printed_number(printed);
  const int d = printed_decimals(printed);
  int best = -1;
  for (int k = 0; k <= d; ++k)
    if (std::fabs(exact - p) <= 0.5 * std::pow(10.0, -k) * (1 + 1e-9)) best = k;
  return best;
}

std::string latex_quantity(const std::string& quantity) {
  static const std::map<std::string, std::string> names{
      {"t", "t"},
      {"t (load part)", "t\\ (\\text{load part})"},
      {"theta_m", "\\theta_m"},
      {"dtheta_m", "\\dot\\theta_m"},
      {"theta_L", "\\theta_L"},
      {"dtheta_L", "\\dot\\theta_L"},
      {"dtheta_o", "\\dot\\theta_o"},
      {"theta_o", "\\theta_o"},
      {"theta_m - 1", "\\theta_m - 1"},
      {"theta_L - 1", "\\theta_L - 1"},
      {"theta_o - 1", "\\theta_o - 1"},
      {"theta_o - theta_o(0)", "\\theta_o - \\theta_o(0)"}};
  const auto found = names.find(quantity);
  return found == names.end() ? "\\text{" + quantity + "}" : found->second;
}

double dividing_value(const numeric::DividingLinePoint& p, const std::string& quantity) {
  if (quantity == "t" || quantity == "t (load part)") return p.t;
  if (quantity == "theta_m") return p.theta_m;
  if (quantity == "dtheta_m") return p.dtheta_m;
  if (quantity == "theta_L") return p.theta_L;
  if (quantity == "dtheta_L") return p.dtheta_L;
  if (quantity == "dtheta_o") return p.dtheta_o;
  if (quantity == "theta_o") return p.theta_o;
  if (quantity == "theta_m - 1") return p.theta_m - 1;
  if (quantity == "theta_L - 1") return p.theta_L - 1;
  if (quantity == "theta_o - 1") return p.theta_o - 1;
  throw std::runtime_error("unknown dividing-line quantity '" + quantity + "'");
}

int table_number(const std::string& table) { return std::atoi(table.c_str() + 5); }  // "Table20"

struct Footnotes {
  std::vector<Rich> items;
  Rich cite(const Erratum& e, const std::string& what) {
    items.push_back(doc::text("[" + std::to_string(items.size() + 1) + "] " + readable(what) + ": printed " + e.printed + ", exact " +
                              (e.exact_decimal.empty() ? e.exact : e.exact_decimal) + ". " + readable(e.cause)));
    return doc::text("erratum [" + std::to_string(items.size()) + "]");
  }
};

Rich agreement_cell(double exact, const std::string& printed, const Erratum* e, const std::string& what, Footnotes& notes) {
  const int d = printed_decimals(printed);
  const int k = agreeing_decimals(exact, printed);
  if (k == d) return doc::text("agrees (" + std::to_string(d) + " of " + std::to_string(d) + " decimals)");
  Rich r = doc::text(std::to_string(std::max(k, 0)) + " of " + std::to_string(d) + " decimals; ");
  if (e) return r + notes.cite(*e, what);
  return r + doc::bold("not in the ledger");
}

std::string event_kind(const numeric::SimulationEvent& e) {
  std::string kind = numeric::to_string(e.kind);
  if (e.bounce) kind += " (bounce)";
  return kind;
}

doc::Document events_table(const TrajectoryRun& run, std::size_t limit) {
  std::vector<std::vector<Rich>> rows;
  const auto& events = run.result.events;
  for (std::size_t k = 0; k < events.size() && k < limit; ++k)
    rows.push_back({doc::text(fixed(events[k].t, 6)), doc::text(event_kind(events[k])), doc::text(fixed(events[k].theta_o, 6)),
                    doc::text(fixed(events[k].dtheta_o, 6))});
  if (events.size() > limit)
    rows.push_back({doc::text("…"), doc::text(std::to_string(events.size() - limit) + " more events"), doc::text(""), doc::text("")});
  return {doc::table({doc::text("t (s)"), doc::text("event"), doc::math("\\theta_o"), doc::math("\\dot\\theta_o") + doc::text(" after")},
                     rows, "rlrr")};
}

std::string code_excerpt(const std::string& header, const std::string& function) {
  const std::string signature = "inline double " + function + "(";
  const auto at = header.find(signature);
  if (at == std::string::npos) return "";
  auto begin = header.rfind("\n///", at);
  while (begin != std::string::npos && begin > 0) {
    const auto previous = header.rfind("\n///", begin - 1);
    if (previous == std::string::npos || header.find('\n', previous + 1) != begin) break;
    begin = previous;
  }
  begin = begin == std::string::npos ? at : begin + 1;
  const auto end = header.find("\n}\n", at);
  return header.substr(begin, (end == std::string::npos ? header.size() : end + 3) - begin);
}
void append(doc::Document& to, doc::Document from) {
  for (doc::Block& b : from) to.push_back(std::move(b));
}

std::string joined(const std::vector<int>& numbers) {
  std::string out;
  for (std::size_t k = 0; k < numbers.size(); ++k) out += (k ? ", " : "") + std::to_string(numbers[k]);
  return out;
}

// The page's title, its links and what it replaces in the thesis.
doc::Document page_header(const CaseResult& c) {
  const ThesisCase& tc = *c.thesis;
  doc::Document out;
  out.push_back(doc::heading(1, doc::text("Case " + c.spec.id + " (thesis section " + std::to_string(tc.section) + ")"),
                             roman_to_anchor(c.spec.id)));
  out.push_back(doc::paragraph(doc::text("\"" + tc.title + "\"  " + tc.summary)));
  out.push_back(doc::paragraph(doc::link("index", "../README.md") + doc::text(" · ") + doc::link("general solutions", "../general.md") +
                               doc::text(" · ") + doc::link("errata ledger", "../errata.md") + doc::text(" · ") +
                               doc::link("report.pdf", "../report.pdf")));
  out.push_back(doc::paragraph(doc::text("This page replaces the thesis's section " + std::to_string(tc.section) +
                                         ": its equations (" + joined(tc.equations) + ") carry the thesis's numbers as tags, its tables (" +
                                         joined(tc.tables) + ") are set beside the exact values, its figures (" + joined(tc.figures) +
                                         ") are redrawn from the exact solution.  Every number here is computed; the "
                                         "thesis's printed values come from the data files and the errata ledger.")));
  return out;
}

// Sections 1–3: the model and the derivation steps, the thesis's worked trajectories after the parameter table.
doc::Document model_and_derivation(const CaseResult& c) {
  const bool at_motor = c.parameters.measured_at == model::MeasuredAt::Motor;
  doc::Document derivation = symbolic::derivation_document(c.derivation, c.thesis->slots, 2);
  std::vector<Rich> items;
  for (const TrajectoryRun& run : c.runs)
    items.push_back(doc::text(run.label + (run.is_step ? " (at rest in contact, " : " (") ) +
                    doc::math(run.is_step ? "\\theta_o(0) = \\theta_R - " + symbolic::pretty::decimal(run.step, 6)
                                          : "\\theta_o = " + symbolic::pretty::decimal(run.theta_o0, 6) + ",\\ \\dot\\theta_o = " +
                                                symbolic::pretty::decimal(run.dtheta_o0, 6)) +
                    doc::text("): " + run.source));
  const auto table = std::find_if(derivation.begin(), derivation.end(), [](const doc::Block& b) { return b.kind == doc::Block::Kind::Table; });
  const auto at = table == derivation.end() ? derivation.end() : table + 1;
  doc::Document inserted{doc::paragraph(doc::text("The output is measured at the ") + doc::text(at_motor ? "motor" : "load") +
                                        doc::text("; the thesis's worked trajectories:")),
                         doc::list(items)};
  derivation.insert(at, inserted.begin(), inserted.end());
  return derivation;
}

// The case's thesis figures of one kind, redrawn; `caption_tail` follows "Thesis fig. N redrawn: <what>".  Returns how many.
int redrawn_figures(doc::Document& out, const ThesisData& data, const std::string& case_id, const std::string& kind,
                    const std::string& caption_tail) {
  int drawn = 0;
  for (const FigureSpec* f : figures_of(data, case_id))
    if (f->kind == kind) {
      ++drawn;
      out.push_back(doc::figure("figures/" + figure_name(*f),
                                doc::text("Thesis fig. " + std::to_string(f->number) + " redrawn: " + f->what + caption_tail)));
    }
  return drawn;
}

// Section 4's opening: how the dividing lines are computed from the separation line.
doc::Block separation_line_paragraph(const CaseResult& c) {
  Rich r = doc::text("From a point of the separation line, ") +
           doc::math("\\theta_m(0) = \\theta_L(0) = \\theta_R + \\cot\\varphi\\,\\dot\\theta_{m0}") +
           doc::text(" with ") + doc::math("\\cot\\varphi = " + symbolic::pretty::latex(c.derivation.free.cot_phi)) +
           doc::text(", the bodies move freely until the gap ") + doc::math("\\theta_L - \\theta_m") +
           doc::text(" reaches the backlash (the first crossing, found by a certified search on the validated closed forms); "
                     "the dividing lines are the states of motor and load just before that impact and of the recombined "
                     "system just after it (eq. 24).");
  if (c.lines_positive.threshold)
    r = r + doc::text("  No recombination happens for ") +
        doc::math("\\dot\\theta_{m0} < " + symbolic::pretty::decimal(*c.lines_positive.threshold, 7)) +
        doc::text(" (the motor, a closed loop of its own, settles before the load has crossed the backlash).");
  return doc::paragraph(r);
}

// One of the thesis's dividing-line tables beside the exact values; `points` caches the exact point per printed velocity.
void dividing_line_table(doc::Document& out, const CaseResult& c, const ThesisData& data, const std::string& table,
                         std::map<std::string, numeric::DividingLinePoint>& points, Footnotes& notes) {
  std::vector<std::vector<Rich>> rows;
  int agreeing = 0, total = 0;
  for (const DividingLineCell& cell : data.dividing_line_cells) {
    if (cell.case_id != c.spec.id || cell.table != table) continue;
    auto found = points.find(cell.v0);
    if (found == points.end())
      found = points.emplace(cell.v0, c.model->trace_point(printed_number(cell.v0))).first;
    const numeric::DividingLinePoint& q = found->second;
    const std::string quantity = cell.quantity + " at dtheta_m0=" + cell.v0;
    const Erratum* e = find_erratum(data.errata, table, c.spec.id, quantity);
    ++total;
    if (q.status != numeric::RecombinationStatus::Recombination) {
      rows.push_back({doc::text(cell.v0), doc::math(latex_quantity(cell.quantity)), doc::text(cell.printed),
                      doc::text(std::string("no recombination (") + numeric::to_string(q.status) + ")"),
                      e ? notes.cite(*e, table + ", " + quantity) : doc::bold("not in the ledger")});
      continue;
    }
    const double exact = dividing_value(q, cell.quantity);
    const int d = printed_decimals(cell.printed);
    if (agreeing_decimals(exact, cell.printed) == d) ++agreeing;
    rows.push_back({doc::text(cell.v0), doc::math(latex_quantity(cell.quantity)), doc::text(cell.printed), doc::text(fixed(exact, d + 3)),
                    agreement_cell(exact, cell.printed, e, table + ", " + quantity, notes)});
  }
  out.push_back(doc::paragraph(doc::bold("Table " + std::to_string(table_number(table))) +
                               doc::text(": " + std::to_string(agreeing) + " of " + std::to_string(total) +
                                         " printed entries agree with the exact value to their last printed digit.")));
  doc::Block t = doc::table({doc::math("\\dot\\theta_{m0}"), doc::text("quantity"), doc::text("thesis"), doc::text("exact"),
                             doc::text("digit agreement")},
                            rows, "rlrrl");
  t.small = true;
  out.push_back(t);
}

// Section 4: the separation line, the dividing-line tables and the phase portraits with their isoclines.
doc::Document dividing_lines_section(const CaseResult& c, const ThesisData& data, Footnotes& notes) {
  doc::Document out;
  out.push_back(doc::heading(2, doc::text("The dividing lines beside the thesis's tables")));
  out.push_back(separation_line_paragraph(c));
  redrawn_figures(out, data, c.spec.id, "separation", ".");
  std::set<std::string> tables;
  for (const DividingLineCell& cell : data.dividing_line_cells)
    if (cell.case_id == c.spec.id) tables.insert(cell.table);
  std::vector<std::string> ordered(tables.begin(), tables.end());
  std::sort(ordered.begin(), ordered.end(), [](const std::string& a, const std::string& b) { return table_number(a) < table_number(b); });
  std::map<std::string, numeric::DividingLinePoint> points;
  for (const std::string& table : ordered) dividing_line_table(out, c, data, table, points, notes);
  redrawn_figures(out, data, c.spec.id, "phase",
                  ".  Isoclines of the combined system (grey, labelled by their slope η), the separation line (one half per "
                  "face), the recombination loci of both faces (motor, load, and the recombined state after eq. 24), the "
                  "trajectories of the thesis's inputs (the other shaft dotted during separation, in the thesis's convention) "
                  "and the exact limit cycle.");
  return out;
}

// The thesis's printed points of one step input beside the exact simulation at their times.
void step_points_table(doc::Document& out, const CaseResult& c, const ThesisData& data, const TrajectoryRun& run, Footnotes& notes) {
  const numeric::Parameters& p = c.parameters;
  std::vector<std::vector<Rich>> rows;
  std::string table_name;
  for (const StepPoint& sp : data.step_points) {
    if (sp.case_id != c.spec.id || !run.is_step || std::fabs(printed_number(sp.step) - run.step) > 1e-12) continue;
    table_name = sp.table;
    api::SimulationRequest request;
    request.step = run.step;
    request.t_end = printed_number(sp.t);
    const numeric::SimulationResult at = c.model->simulate(request).result;
    double value = at.theta_o_final;
    if (sp.quantity == "theta_m") value = at.final_state.theta_m;
    if (sp.quantity == "theta_L") value = at.final_state.theta_L - at.final_state.face * p.backlash / 2;
    if (sp.quantity == "theta_o - theta_o(0)") value = at.theta_o_final - (p.theta_R - run.step);
    const std::string quantity = sp.quantity + " at t=" + sp.t;
    const Erratum* e = find_erratum(data.errata, sp.table, c.spec.id, quantity);
    const int d = printed_decimals(sp.printed);
    rows.push_back({doc::text(sp.t), doc::math(latex_quantity(sp.quantity)), doc::text(sp.printed), doc::text(fixed(value, d + 3)),
                    agreement_cell(value, sp.printed, e, sp.table + ", " + quantity, notes)});
  }
  if (rows.empty()) return;
  out.push_back(doc::paragraph(doc::text("Beside the thesis's " + readable(table_name) +
                                         " (read off its phase portrait; θL in the thesis's frame, measured from the face "
                                         "left at the separation):")));
  doc::Block t = doc::table({doc::text("t (s)"), doc::text("quantity"), doc::text("thesis"), doc::text("exact"), doc::text("digit agreement")},
                            rows, "rlrrl");
  t.small = true;
  out.push_back(t);
}

// Section 5, first part: each input's simulation, its events and the thesis's points; the step tables' other errata; the figures.
doc::Document step_responses_section(const CaseResult& c, const ThesisData& data, Footnotes& notes) {
  doc::Document out;
  out.push_back(doc::heading(2, doc::text("Step responses and the limit cycle beside the thesis's numbers")));
  for (const TrajectoryRun& run : c.runs) {
    const numeric::SimulationResult& r = run.result;
    out.push_back(doc::paragraph(doc::bold(run.label) + doc::text(" (" + run.source + "): simulated exactly (closed forms, "
                                                                  "certified event times) to t = " + fixed(r.t_final, 3) +
                                                                  " s, status " + numeric::to_string(r.status) + ", " +
                                                                  std::to_string(r.events.size()) + " events:")));
    append(out, events_table(run, 12));
    step_points_table(out, c, data, run, notes);
  }
  // errata of the step tables that are not per time point (separation velocities, the rest error)
  std::vector<Rich> items;
  for (const Erratum& e : data.errata)
    if (e.case_id == c.spec.id && e.file == "step_responses.toml" && e.quantity.find(" at t=") == std::string::npos)
      items.push_back(doc::text(readable(e.where + ", " + e.quantity) + ": printed " + e.printed + ", exact " +
                                (e.exact_decimal.empty() ? e.exact : e.exact_decimal) + " (") +
                      notes.cite(e, e.where + ", " + e.quantity) + doc::text(")"));
  if (!items.empty()) {
    out.push_back(doc::paragraph(doc::text("The thesis's other step-response numbers that differ from the exact ones:")));
    out.push_back(doc::list(items));
  }
  if (redrawn_figures(out, data, c.spec.id, "transient", "; the thesis's printed points overlaid.") == 0)
    out.push_back(doc::figure("figures/case" + c.spec.id + "_step_responses",
                              doc::text("The thesis's step inputs for case " + c.spec.id +
                                        " against time (the thesis has no transient figure for this case).")));
  return out;
}

// The exact limit cycle's numbers beside the thesis's magnitude (section 14).
void limit_cycle_table(doc::Document& out, const CaseResult& c, const ThesisData& data) {
  const ThesisCase& tc = *c.thesis;
  const numeric::LimitCycle& lc = c.cycle;
  const Erratum* magnitude_erratum = find_erratum(data.errata, "Section14", c.spec.id, "magnitude (peak-to-peak of theta_o)");
  std::vector<std::vector<Rich>> rows{
      {doc::text("magnitude: peak-to-peak of θo (section 14)"), doc::text(fixed(lc.peak_to_peak, 9)), doc::text(tc.limit_cycle_printed),
       doc::text(agreeing_decimals(lc.peak_to_peak, tc.limit_cycle_printed) == printed_decimals(tc.limit_cycle_printed)
                     ? "agrees"
                     : "differs by " + sig(100 * (printed_number(tc.limit_cycle_printed) / lc.peak_to_peak - 1), 3) + "%")},
      {doc::text("amplitude max |θo − θR|"), doc::text(fixed(lc.amplitude, 9)), doc::text(""), doc::text("")},
      {doc::text("peak-to-peak of the motor / of the load"), doc::text(fixed(lc.peak_to_peak_motor, 6) + " / " + fixed(lc.peak_to_peak_load, 6)),
       doc::text(""), doc::text("")},
      {doc::text("period (s)"), doc::text(fixed(lc.period, 6)), doc::text(""), doc::text("")},
      {doc::text("velocity at separation θ̇o"), doc::text(fixed(lc.separation_velocity, 9)), doc::text(""), doc::text("")},
      {doc::text("multiplier of the return map"), doc::text(fixed(lc.multiplier, 6) + (lc.stable ? " (stable)" : " (unstable)")),
       doc::text(""), doc::text("")},
      {doc::text("C (eq. 38) at separation / just after recombination"),
       doc::text(fixed(lc.C_separation, 6) + " / " + fixed(lc.C_recombination, 6)), doc::text(""), doc::text("")},
      {doc::text("crossings of θo = θR on the contact arc"), doc::text(std::to_string(lc.contact_arc_crossings_of_theta_R)), doc::text(""),
       doc::text("")}};
  out.push_back(doc::paragraph(doc::text("The fixed point of the half-cycle return map on the separation line (exact hybrid "
                                         "simulation, refined by toms748):")));
  out.push_back(doc::table({doc::text("quantity"), doc::text("exact"), doc::text("thesis"), doc::text("")}, rows, "lrrl"));
  if (magnitude_erratum)
    out.push_back(doc::paragraph(doc::text("Erratum (section 14): ") + doc::text(readable(magnitude_erratum->cause) + ".")));
  if (!lc.other_fixed_points.empty()) {
    std::string list;
    for (double v : lc.other_fixed_points) list += (list.empty() ? "" : ", ") + sig(v, 6);
    out.push_back(doc::paragraph(doc::text("Further fixed points of the return map (separation velocities): " + list + ".")));
  }
  out.push_back(doc::paragraph(doc::text("On the cycle C just after recombination equals C at the next separation unless the "
                                         "contact arc crosses ") +
                               doc::math("\\theta_o = \\theta_R") +
                               doc::text(", where the principal arctan of eq. 38 jumps and C is multiplied by the factor given "
                                         "above: the thesis's comparison of C holds within one half-plane.")));
}

// Why there is no cycle, beside what the thesis prints.
void no_limit_cycle(doc::Document& out, const CaseResult& c) {
  out.push_back(doc::paragraph(doc::text("No limit cycle: " + c.cycle.reason + ".  The thesis (section 14) prints \"" +
                                         c.thesis->limit_cycle_printed + "\".")));
  if (c.parameters.measured_at == model::MeasuredAt::Motor)
    out.push_back(doc::paragraph(
        doc::text("With the output at the motor the backlash is outside the loop: the motor with the load separated is a "
                  "closed, damped loop of its own (eq. 16), so every separated motion ends with the motor at ") +
        doc::math("\\theta_R") +
        doc::text(" and the load drifting to rest inside the backlash; the steady-state error is at most the backlash and "
                  "nothing feeds energy back, so no cycle can persist.")));
}

// The stability constant at the thesis's own points (eqs. 38, 80, 81).
void stability_constants(doc::Document& out, const CaseResult& c, const ThesisData& data) {
  const ThesisCase& tc = *c.thesis;
  for (const Erratum& e : data.errata) {
    if (e.case_id != c.spec.id || e.file != "limit_cycles.toml" || e.where == "Section14") continue;
    const bool separation = e.quantity.find("separation") != std::string::npos;
    const auto slot = tc.slots.find(separation ? "C_separation" : "C_recombination");
    std::string equation = "C_{\\text{" + std::string(separation ? "separation" : "recombination") + "}} = " + e.exact_decimal +
                           "\\quad(\\text{printed } " + e.printed + ")";
    if (slot != tc.slots.end()) equation += " \\tag{" + slot->second + "}";
    out.push_back(doc::paragraph(doc::text("Eq. 38 at the thesis's point (" + readable(e.where + ", " + e.quantity) + "):")));
    out.push_back(doc::equation(equation));
    out.push_back(doc::paragraph(doc::text(readable(e.cause) + ".")));
  }
}

// Section 5, second part: the limit cycle.
doc::Document limit_cycle_section(const CaseResult& c, const ThesisData& data) {
  doc::Document out;
  out.push_back(doc::heading(3, doc::text("The limit cycle")));
  if (c.cycle.status == numeric::CycleStatus::LimitCycle)
    limit_cycle_table(out, c, data);
  else
    no_limit_cycle(out, c);
  stability_constants(out, c, data);
  return out;
}

// The describing function's predicted cycle against the exact one, and the verdict.
void describing_function_comparison(doc::Document& out, const CaseResult& c) {
  const DescribingFunctionPrediction& df = c.describing_function;
  const auto predicted = df.predicted();
  if (predicted && c.cycle.status == numeric::CycleStatus::LimitCycle) {
    const double exact_frequency = 2 * M_PI / c.cycle.period;
    const double ratio = predicted->load_peak_to_peak / c.cycle.peak_to_peak;
    std::vector<std::vector<Rich>> cmp{
        {doc::text("load peak-to-peak (the magnitude)"), doc::text(fixed(predicted->load_peak_to_peak, 6)), doc::text(fixed(c.cycle.peak_to_peak, 6)),
         doc::text(sig(100 * (ratio - 1), 3) + "%")},
        {doc::text("motor peak-to-peak"), doc::text(fixed(predicted->motor_peak_to_peak, 6)), doc::text(fixed(c.cycle.peak_to_peak_motor, 6)),
         doc::text(sig(100 * (predicted->motor_peak_to_peak / c.cycle.peak_to_peak_motor - 1), 3) + "%")},
        {doc::text("frequency ω (rad/s)"), doc::text(fixed(predicted->frequency, 6)), doc::text(fixed(exact_frequency, 6)),
         doc::text(sig(100 * (predicted->frequency / exact_frequency - 1), 3) + "%")}};
    out.push_back(doc::table({doc::text(""), doc::text("describing function"), doc::text("exact"), doc::text("error")}, cmp, "lrrr"));
    std::string verdict = ratio > 1.25 || ratio < 0.8 ? "The describing function misses the magnitude by a factor " + sig(ratio, 3) + "."
                                                        : "The describing function's magnitude is within " +
                                                              sig(std::fabs(100 * (ratio - 1)), 2) + "% of the exact one.";
    std::size_t unstable = 0;
    for (const DescribingFunctionCycle& cycle : df.cycles) unstable += cycle.stable ? 0 : 1;
    if (unstable && c.cycle.other_fixed_points.empty())
      verdict += "  It also predicts " + (unstable == 1 ? std::string("an unstable cycle that does") : std::to_string(unstable) +
                 " unstable cycles that do") + " not exist: the exact return map has no other fixed point in the searched range of "
                 "separation velocities.";
    out.push_back(doc::paragraph(doc::bold("Verdict:") + doc::text(" " + verdict)));
  } else if (predicted) {
    out.push_back(doc::paragraph(doc::bold("Verdict:") +
                                 doc::text(" the describing function predicts a cycle that does not exist (" + c.cycle.reason + ").")));
  } else if (c.cycle.status == numeric::CycleStatus::LimitCycle) {
    out.push_back(doc::paragraph(doc::bold("Verdict:") + doc::text(" the describing function predicts no cycle (" + df.reason +
                                                                   "), but the exact system has one.")));
  } else {
    out.push_back(doc::paragraph(doc::bold("Verdict:") + doc::text(" no cycle either way.")));
  }
}

// Section 5, last part: the classical prediction by the describing function.
doc::Document describing_function_section(const CaseResult& c) {
  doc::Document out;
  out.push_back(doc::heading(3, doc::text("The classical prediction: the describing function")));
  const DescribingFunctionPrediction& df = c.describing_function;
  if (!df.applicable) {
    out.push_back(doc::paragraph(doc::text("Not applicable: " + df.reason + ".")));
    return out;
  }
  out.push_back(doc::paragraph(
      doc::text("The textbook model: one rigid drive ") + doc::math("J = J_m + J_L,\\ F = F_m + F_L") +
      doc::text(" in the loop, the gear a position backlash of width b between the motor and the measured load, ") +
      doc::math("G(s) = \\frac{K}{s(Js + F)}") + doc::text(", and the backlash describing function ") +
      doc::math("N(A) = \\frac{1}{\\pi}\\left[\\frac{\\pi}{2} + \\arcsin\\beta + \\beta\\sqrt{1-\\beta^2}\\right] - "
                "\\frac{\\mathrm{i}}{\\pi}\\left(1 - \\beta^2\\right),\\ \\beta = 1 - \\frac{b}{A}") +
      doc::text("; a cycle is predicted where ") + doc::math("1 + N(A)G(\\mathrm{i}\\omega) = 0") +
      doc::text(", i.e. ") + doc::math("\\operatorname{Re}N = J\\omega^2/K,\\ \\operatorname{Im}N = -F\\omega/K") + doc::text(".")));
  std::vector<std::vector<Rich>> rows;
  for (const DescribingFunctionCycle& cycle : df.cycles)
    rows.push_back({doc::text(fixed(cycle.amplitude, 6)), doc::text(fixed(cycle.frequency, 6)), doc::text(fixed(cycle.period, 4)),
                    doc::text(fixed(cycle.load_peak_to_peak, 6)), doc::text(fixed(cycle.motor_peak_to_peak, 6)),
                    doc::text(cycle.stable ? "stable" : "unstable")});
  if (!rows.empty())
    out.push_back(doc::table({doc::text("A (motor amplitude)"), doc::text("ω (rad/s)"), doc::text("period (s)"),
                              doc::text("load peak-to-peak 2A − b"), doc::text("motor peak-to-peak 2A"), doc::text("")},
                             rows, "rrrrrl"));
  describing_function_comparison(out, c);
  out.push_back(doc::paragraph(doc::text(
      "Why it fails: the describing function sees only J, F, K and b, so it predicts the same cycle for every case that "
      "shares them, whatever the split of inertia and friction between motor and load; and it assumes the load follows a "
      "sinusoidal motor the instant the backlash is taken up.  In the exact motion the load drifts freely across the "
      "backlash, decelerating at its own rate FL/JL, while the motor is driven open loop; the energy exchanged at "
      "recombination (eq. 24) sets the cycle, and that is what the sinusoidal assumption ignores.")));
  return out;
}

// Section 6: the generated evaluator's validation against Boost.Odeint and an excerpt of its code.
doc::Document validation_section(const CaseResult& c) {
  doc::Document out;
  out.push_back(doc::heading(2, doc::text("The generated evaluator and its validation")));
  const numeric::ValidationReport& report = c.validation().report();
  out.push_back(doc::paragraph(doc::text("The header emitted for this case by codegen (exact closed forms, constants rounded "
                                         "once) is checked against Boost.Odeint (dopri5, tolerance " +
                                         sig(numeric::ValidationOptions{}.odeint_tolerance, 2) + ") over the whole segment horizon: free mode to " +
                                         fixed(report.free_horizon, 1) + " s from " + std::to_string(report.free_trajectories) +
                                         " separation points, contact to " + fixed(report.contact_horizon, 1) + " s from " +
                                         std::to_string(report.contact_trajectories) + " initial states; the gate passes at "
                                         "max |error| ≤ " + sig(report.tolerance, 2) + ".  Evaluator: " + report.evaluator +
                                         "; status: " + (report.passed() ? "passed" : "FAILED") + ".")));
  std::vector<std::vector<Rich>> rows;
  for (const numeric::StateError& s : report.states) {
    const std::string where = s.contact ? "θo0 = " + sig(s.at_theta_o0, 4) + ", θ̇o0 = " + sig(s.at_dtheta_o0, 4)
                                        : "θ̇m0 = " + sig(s.at_dtheta_m0, 4);
    // the evaluator's state by its quantity (its name in the JSON is the code's: theta_m, gap, cot_phi)
    const Rich state = s.state == "gap"       ? doc::math("\\theta_L - \\theta_m") + doc::text(" (the gap)")
                       : s.state == "cot_phi" ? doc::math("\\cot\\varphi")
                                              : doc::math(latex_quantity(s.state));
    rows.push_back({state, doc::text(sig(s.max_abs_error, 3)), doc::text(fixed(s.at_t, 3)), doc::text(where),
                    doc::text(std::to_string(s.samples)), doc::text(s.passed ? "pass" : "FAIL")});
  }
  out.push_back(doc::table({doc::text("state"), doc::text("max |error|"), doc::text("at t (s)"), doc::text("from"),
                            doc::text("samples"), doc::text("")},
                           rows, "lrrlrl"));
  const std::string excerpt = code_excerpt(c.generated_header, "theta_m");
  if (!excerpt.empty()) {
    out.push_back(doc::paragraph(doc::text("An excerpt of the generated code (") + doc::code("backlash/generated/case_" + c.spec.id + ".hpp") +
                                 doc::text("; ") + doc::code("backlash codegen " + c.spec.id + " --out DIR") +
                                 doc::text(" writes it):")));
    out.push_back(doc::code_block("cpp", excerpt));
  }
  return out;
}

}  // namespace

doc::Document case_document(const CaseResult& c, const ThesisData& data) {
  doc::Document out = page_header(c);
  append(out, model_and_derivation(c));
  Footnotes notes;  // cited in page order: dividing lines, then step responses
  append(out, dividing_lines_section(c, data, notes));
  append(out, step_responses_section(c, data, notes));
  append(out, limit_cycle_section(c, data));
  append(out, describing_function_section(c));
  append(out, validation_section(c));
  if (!notes.items.empty()) {
    out.push_back(doc::heading(2, doc::text("Errata cited on this page")));
    out.push_back(doc::list(notes.items));
  }
  return out;
}

}  // namespace backlash::reports
