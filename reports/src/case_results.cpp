// The numbers of one case (derivation, validation, dividing lines, trajectories,
// limit cycle, describing function) and its figures.
#include "report_parts.hpp"

#include "backlash/api/derive.hpp"
#include "backlash/symbolic/pretty.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <regex>
#include <stdexcept>
#include <unordered_map>

namespace backlash::reports {

namespace {
constexpr double nan_value = std::numeric_limits<double>::quiet_NaN();

bool series_has_data(const Series& s) {
  for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k)
    if (std::isfinite(s.x[k]) && std::isfinite(s.y[k])) return true;
  return false;
}
}

std::string fixed(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  std::string s = buffer;
  if (s.rfind("-0.", 0) == 0 && std::strtod(s.c_str(), nullptr) == 0) s.erase(0, 1);
  return s;
}

std::string sig(double v, int significant) { return symbolic::pretty::decimal(v, significant, symbolic::pretty::Style::Text); }

std::string roman_to_anchor(const std::string& id) {
  std::string out = "case-";
  for (char c : id) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string readable(const std::string& text) {
  // One pass of one pattern over the text (the ledger's 600 causes are printed three times:
  // on the case pages, the ledger page and the index), each result kept for the next time.
  static const std::regex identifier(
      R"(\b(d?)theta(?:_([mLoR])(0?)|dot(?:_([mLo]))?)?( dot)?\b|\bomega(?:_([cm]))?\b|\beta([0-9]?)\b|\b(Table|Eq|Section)([0-9]+)\b|\b([A-Za-z0-9]+_[A-Za-z0-9_]+)\.([A-Z][A-Za-z0-9]+)\b)");
  static std::unordered_map<std::string, std::string> done;
  const auto found = done.find(text);
  if (found != done.end()) return found->second;
  std::string out;
  std::size_t from = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), identifier); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    out += text.substr(from, static_cast<std::size_t>(m.position()) - from);
    from = static_cast<std::size_t>(m.position() + m.length());
    if (m[10].matched) {  // a test's name, Suite.Name: split where a line may break
      out += m[10].str() + " / " + m[11].str();
    } else if (m[8].matched) {  // Table20, Eq38, Section14
      out += (m[8].str() == "Table" ? "Table " : m[8].str() == "Eq" ? "eq. " : "section ") + m[9].str();
    } else if (m[7].matched) {  // eta, eta2
      out += "η" + m[7].str();
    } else if (m.str().rfind("omega", 0) == 0) {  // omega, omega_c
      out += "ω" + m[6].str();
    } else {  // theta_m, dtheta_m0, theta_L dot, thetadot, thetadot_o
      const bool dotted = m[1].length() > 0 || m[5].matched || m.str().find("thetadot") != std::string::npos;
      out += std::string(dotted ? "θ̇" : "θ") + m[2].str() + m[3].str() + m[4].str();
    }
  }
  out += text.substr(from);
  return done.emplace(text, out).first->second;
}

const ThesisCase& ThesisData::thesis_case(const std::string& id) const {
  for (const ThesisCase& c : cases)
    if (c.id == id) return c;
  throw std::runtime_error("reports/data/thesis_cases.toml has no case " + id);
}

ThesisData load_thesis_data(const DataPaths& paths) {
  ThesisData d;
  d.errata = load_errata(paths.errata_directory);
  d.cases = load_thesis_cases(paths.data_directory / "thesis_cases.toml");
  d.figures = load_figures(paths.data_directory / "thesis_figures.toml");
  d.step_points = load_step_points(paths.data_directory / "thesis_step_tables.toml");
  d.dividing_line_cells = load_dividing_line_cells(paths.dividing_line_tables);
  return d;
}

std::string figure_name(const FigureSpec& spec) {
  char number[8];
  std::snprintf(number, sizeof number, "%02d", spec.number);
  std::string kind = spec.kind == "phase"        ? "phase_plane"
                     : spec.kind == "separation" ? "separation"
                     : spec.kind == "transient"  ? "transient_response"
                     : spec.sweep == "fig31"     ? "magnitude_vs_friction_ratio"
                                                 : "magnitude_vs_inertia_ratio";
  return std::string("fig") + number + (spec.case_id.empty() ? "" : "_case" + spec.case_id) + "_" + kind;
}

std::vector<const FigureSpec*> figures_of(const ThesisData& data, const std::string& case_id) {
  std::vector<const FigureSpec*> out;
  for (const FigureSpec& f : data.figures)
    if (f.case_id == case_id) out.push_back(&f);
  return out;
}

// ---------------------------------------------------------------- computing a case

namespace {

// The thesis's other inputs of a case (steps, or starts in free flight on the separation line).
TrajectoryRun thesis_run(const api::Model& model, const Trajectory& t, double t_end, const std::string& id) {
  TrajectoryRun run;
  run.source = t.quote;
  if (t.kind == "step") {
    run.step = printed_number(t.step);
    run.label = "step " + sig(run.step, 6);
    api::SimulationRequest request;
    request.step = run.step;
    request.t_end = t_end;
    request.sample_interval = 0.01;
    run.result = model.simulate(request).result;
  } else if (t.kind == "state") {
    run.is_step = false;
    run.theta_o0 = printed_number(t.theta_o);
    run.dtheta_o0 = printed_number(t.dtheta_o);
    run.label = "start (" + sig(run.theta_o0, 6) + ", " + sig(run.dtheta_o0, 6) + ")";
    run.result = model.simulate_from({run.dtheta_o0 > 0 ? -1 : +1, run.theta_o0, run.dtheta_o0}, t_end, 0.01).result;
  } else {
    throw std::runtime_error("thesis_cases.toml: case " + id + ": unknown trajectory kind '" + t.kind + "'");
  }
  return run;
}

// One period of the limit cycle from its separation point, closed.
std::vector<numeric::TrajectorySample> cycle_orbit(const api::Model& model, const numeric::LimitCycle& cycle) {
  const numeric::Parameters& p = model.evaluator().parameters();
  const double v = cycle.separation_velocity;
  std::vector<numeric::TrajectorySample> orbit =
      model.simulate_from({-1, p.theta_R + model.evaluator().cot_phi() * v, v}, cycle.period, cycle.period / 800).result.samples;
  if (!orbit.empty()) orbit.push_back(orbit.front());  // close the orbit
  return orbit;
}

}  // namespace

CaseResult compute_case(const std::string& id, const ThesisData& data) {
  CaseResult c;
  const api::Case source = api::load(id);
  c.model = std::make_shared<const api::Model>(source);  // the validation gates (ValidationFailed)
  const api::Model& model = *c.model;
  c.spec = source.spec();
  c.thesis = &data.thesis_case(id);
  api::ExactCase exact = api::derive_exact(source);
  c.derivation = std::move(exact.derivation);
  c.generated_header = std::move(exact.header);
  c.parameters = model.evaluator().parameters();

  std::vector<double> grid, negative;
  for (int k = 0; k <= 120; ++k) grid.push_back(0.01 * std::pow(150.0, k / 120.0));
  for (double v : grid) negative.push_back(-v);
  c.lines_positive = model.trace(grid).lines;
  c.lines_negative = model.trace(negative).lines;

  double t_end = 60;
  if (c.spec.experiment) {
    if (c.spec.experiment->t_end) t_end = model::to_double(*c.spec.experiment->t_end);
    TrajectoryRun run;
    run.step = model::to_double(c.spec.experiment->step);
    run.label = "step " + sig(run.step, 6);
    run.source = "the case file's [experiment]";
    api::SimulationRequest request;
    request.sample_interval = 0.01;
    run.result = model.simulate(request).result;
    c.runs.push_back(std::move(run));
  }
  for (const Trajectory& t : c.thesis->trajectories) c.runs.push_back(thesis_run(model, t, t_end, id));

  c.cycle = model.limit_cycle().cycle;
  if (c.cycle.status == numeric::CycleStatus::LimitCycle) c.cycle_orbit = cycle_orbit(model, c.cycle);
  c.describing_function = describing_function_prediction(c.parameters);
  return c;
}

// ---------------------------------------------------------------- figures

namespace {

struct Window {
  double x0, x1, y0, y1;
};

void extend(Window& w, double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  w.x0 = std::min(w.x0, x);
  w.x1 = std::max(w.x1, x);
  w.y0 = std::min(w.y0, y);
  w.y1 = std::max(w.y1, y);
}

// The part of the line through (x, y) with direction (dx, dy) inside the window (Liang–Barsky).
bool clip_line(const Window& w, double x, double y, double dx, double dy, double& ax, double& ay, double& bx, double& by) {
  double t0 = -1e300, t1 = 1e300;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x - w.x0, w.x1 - x, y - w.y0, w.y1 - y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0) t0 = std::max(t0, r);
    else t1 = std::min(t1, r);
  }
  if (t0 > t1) return false;
  ax = x + t0 * dx;
  ay = y + t0 * dy;
  bx = x + t1 * dx;
  by = y + t1 * dy;
  return true;
}

const char* color_motor = "#1f5fbf";
const char* color_load = "#2a9d3a";
const char* color_recombined = "#d62728";
const char* trajectory_colors[] = {"#7b3294", "#e66101", "#008b8b", "#8c564b"};

std::string shaft_name(const numeric::Parameters& p, bool measured) {
  const bool motor = (p.measured_at == model::MeasuredAt::Motor) == measured;
  return motor ? "motor" : "load";
}

// θ of the shaft that is not measured, during free flight, in the thesis's convention
// (θm = θL at separation): offset so it starts where θo was at the separation.
Series other_shaft_during_separation(const numeric::SimulationResult& r, const numeric::Parameters& p, const std::string& label,
                                     const std::string& style) {
  Series s{label, {}, {}, style};
  const bool at_motor = p.measured_at == model::MeasuredAt::Motor;
  bool in_run = false;
  double offset = 0;
  for (const numeric::TrajectorySample& x : r.samples) {
    if (x.in_contact) {
      if (in_run) {
        s.x.push_back(nan_value);
        s.y.push_back(nan_value);
      }
      in_run = false;
      continue;
    }
    const double other = at_motor ? x.theta_L : x.theta_m, dother = at_motor ? x.dtheta_L : x.dtheta_m;
    if (!in_run) offset = x.theta_o - other;
    in_run = true;
    s.x.push_back(other + offset);
    s.y.push_back(dother);
  }
  return s;
}

// The runs a phase figure shows: the experiment and/or the second inputs, as the figure's data names them.
std::vector<const TrajectoryRun*> phase_runs(const CaseResult& c, const FigureSpec& spec) {
  std::vector<const TrajectoryRun*> runs;
  for (const std::string& which : spec.trajectories) {
    if (which == "experiment" && !c.runs.empty()) runs.push_back(&c.runs.front());
    if (which == "second")
      for (std::size_t k = 1; k < c.runs.size(); ++k) runs.push_back(&c.runs[k]);
  }
  return runs;
}

// Each trajectory up to its sixth separation (enough to show it approach the cycle).
std::vector<double> cut_at_sixth_separation(const std::vector<const TrajectoryRun*>& runs) {
  std::vector<double> cut;
  for (const TrajectoryRun* r : runs) {
    double t_cut = r->result.t_final;
    int separations = 0;
    for (const numeric::SimulationEvent& e : r->result.events)
      if (e.kind == numeric::EventKind::Separation && ++separations == 6) {
        t_cut = e.t;
        break;
      }
    cut.push_back(t_cut);
  }
  return cut;
}

// The phase window: θR, the shown trajectories and the cycle, with a margin of 8 %.
Window phase_window(const CaseResult& c, const std::vector<const TrajectoryRun*>& runs, const std::vector<double>& cut) {
  const double theta_R = c.parameters.theta_R;
  Window w{theta_R, theta_R, 0, 0};
  for (std::size_t k = 0; k < runs.size(); ++k)
    for (const numeric::TrajectorySample& s : runs[k]->result.samples)
      if (s.t <= cut[k]) extend(w, s.theta_o, s.dtheta_o);
  for (const numeric::TrajectorySample& s : c.cycle_orbit) extend(w, s.theta_o, s.dtheta_o);
  const double dx = std::max(w.x1 - w.x0, 0.2), dy = std::max(w.y1 - w.y0, 0.2);
  w.x0 -= 0.08 * dx;
  w.x1 += 0.08 * dx;
  w.y0 -= 0.08 * dy;
  w.y1 += 0.08 * dy;
  return w;
}

// The label η=… of an isocline whose slope is a round value, at its outer end unless another label is too close.
void label_isocline(Plot& plot, const Window& w, double theta_R, const symbolic::IsoclineRow& row, double ax, double ay, double bx,
                    double by) {
  const double eta = row.is_infinite ? 0 : symbolic::to_double(row.eta, {});
  const bool labelled = row.is_infinite || row.is_vertical ||
                        std::fabs(std::fabs(eta) - 1) < 1e-12 || std::fabs(std::fabs(eta) - 2) < 1e-12 ||
                        std::fabs(std::fabs(eta) - 5) < 1e-12 || std::fabs(eta) < 1e-12 || std::fabs(std::fabs(eta) - 0.5) < 1e-12;
  if (!labelled) return;
  const bool upper = by > ay || (by == ay && bx > ax);
  const double lx = upper ? bx : ax, ly = upper ? by : ay;
  const std::string text = row.is_infinite ? "η=∞" : "η=" + symbolic::pretty::decimal(eta, 4, symbolic::pretty::Style::Text);
  // (left-aligned text: kept clear of the right edge of the frame)
  const double x = std::min(theta_R + 0.9 * (lx - theta_R), w.x1 - 0.06 * (w.x1 - w.x0)), y = 0.9 * ly;
  bool crowded = false;
  for (const Label& other : plot.labels)
    crowded = crowded || (std::fabs(other.x - x) < 0.07 * (w.x1 - w.x0) && std::fabs(other.y - y) < 0.04 * (w.y1 - w.y0));
  if (!crowded) plot.labels.push_back({text, x, y});
}

// The isoclines of the combined system through (θR, 0), clipped to the window and labelled.
void add_isoclines(Plot& plot, const CaseResult& c, const Window& w) {
  const double theta_R = c.parameters.theta_R;
  Series iso{"isoclines of the combined system (η = θ̈_{o}/θ̇_{o})", {}, {}, "lines lw 1 lc rgb '#c8c8c8'"};
  const symbolic::IsoclineTable& table = c.derivation.isoclines.front();
  for (const symbolic::IsoclineRow& row : table.rows) {
    double ax, ay, bx, by;
    const bool ok = row.is_vertical ? clip_line(w, theta_R, 0, 0, 1, ax, ay, bx, by)
                                    : clip_line(w, theta_R, 0, 1, symbolic::to_double(row.tangent, {}), ax, ay, bx, by);
    if (!ok) continue;
    iso.x.insert(iso.x.end(), {ax, bx, nan_value});
    iso.y.insert(iso.y.end(), {ay, by, nan_value});
    label_isocline(plot, w, theta_R, row, ax, ay, bx, by);
  }
  plot.series.push_back(iso);
}

// The separation line (one half per face) and the recombination loci of both faces: motor, load, recombined (eq. 24).
void add_separation_and_loci(Plot& plot, const CaseResult& c, const Window& w) {
  const double theta_R = c.parameters.theta_R;
  const double cot_phi = c.evaluator().cot_phi();
  plot.series.push_back({"separation line, face −b/2 (θ̇_{o} > 0)", {theta_R, theta_R + cot_phi * w.y1}, {0, w.y1},
                         "lines lw 2 dt 2 lc rgb '#000000'"});
  plot.series.push_back({"separation line, face +b/2 (θ̇_{o} < 0)", {theta_R, theta_R + cot_phi * w.y0}, {0, w.y0},
                         "lines lw 2 dt 3 lc rgb '#555555'"});
  Series motor{"motor before recombination (θ_{m}, θ̇_{m}), both faces", {}, {}, std::string("linespoints lw 1 pt 7 ps 0.35 lc rgb '") + color_motor + "'"};
  Series load{"load before recombination (θ_{L}, θ̇_{L}), both faces", {}, {}, std::string("linespoints lw 1 pt 5 ps 0.35 lc rgb '") + color_load + "'"};
  Series recombined{"after the impact (θ_{o}, θ̇_{o}; eq. 24), both faces", {}, {},
                    std::string("linespoints lw 1.5 pt 9 ps 0.45 lc rgb '") + color_recombined + "'"};
  for (const numeric::DividingLines* lines : {&c.lines_positive, &c.lines_negative}) {
    for (const numeric::DividingLinePoint& q : lines->points) {
      if (!numeric::has_impact(q.status)) continue;
      motor.x.push_back(q.theta_m);
      motor.y.push_back(q.dtheta_m);
      load.x.push_back(q.theta_L);
      load.y.push_back(q.dtheta_L);
      recombined.x.push_back(q.theta_o);
      recombined.y.push_back(q.dtheta_o);
    }
    for (Series* s : {&motor, &load, &recombined}) {
      s->x.push_back(nan_value);
      s->y.push_back(nan_value);
    }
  }
  plot.series.push_back(motor);
  plot.series.push_back(load);
  plot.series.push_back(recombined);
}

// The series (θo, θ̇o) of a run's samples.
Series phase_series(const std::string& title, const std::vector<numeric::TrajectorySample>& samples, const std::string& style) {
  Series s{title, {}, {}, style};
  for (const numeric::TrajectorySample& x : samples) {
    s.x.push_back(x.theta_o);
    s.y.push_back(x.dtheta_o);
  }
  return s;
}

// The trajectories up to their cut, the other shaft dotted during separation (the thesis's convention).
void add_trajectories(Plot& plot, const CaseResult& c, const std::vector<const TrajectoryRun*>& runs, const std::vector<double>& cut) {
  const numeric::Parameters& p = c.parameters;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const char* color = trajectory_colors[k % 4];
    numeric::SimulationResult shown = runs[k]->result;
    shown.samples.erase(std::remove_if(shown.samples.begin(), shown.samples.end(),
                                       [&](const numeric::TrajectorySample& x) { return x.t > cut[k]; }),
                        shown.samples.end());
    plot.series.push_back(phase_series(runs[k]->label + ": θ_{o}", shown.samples, std::string("lines lw 1.6 lc rgb '") + color + "'"));
    Series other = other_shaft_during_separation(shown, p, runs[k]->label + ": " + shaft_name(p, false) + " during separation",
                                                 std::string("lines lw 1 dt 4 lc rgb '") + color + "'");
    if (series_has_data(other)) plot.series.push_back(other);
  }
}

Plot phase_plot(const CaseResult& c, const FigureSpec& spec) {
  const numeric::Parameters& p = c.parameters;
  Plot plot;
  plot.name = figure_name(spec);
  plot.title = "Thesis fig. " + std::to_string(spec.number) + ": case " + c.spec.id + ", phase plane θ_{o} vs θ̇_{o}";
  plot.x_label = "θ_{o}, the " + shaft_name(p, true) + " (rad)";
  plot.y_label = "θ̇_{o} (rad/s)";
  plot.width = 1000;
  plot.height = 940;
  plot.key = "outside below center horizontal maxcols 2 samplen 2.5 font ',10'";
  const std::vector<const TrajectoryRun*> runs = phase_runs(c, spec);
  const std::vector<double> cut = cut_at_sixth_separation(runs);
  const Window w = phase_window(c, runs, cut);
  plot.x_range = std::pair{w.x0, w.x1};
  plot.y_range = std::pair{w.y0, w.y1};
  add_isoclines(plot, c, w);
  add_separation_and_loci(plot, c, w);
  add_trajectories(plot, c, runs, cut);
  if (!c.cycle_orbit.empty()) plot.series.push_back(phase_series("limit cycle (exact)", c.cycle_orbit, "lines lw 3.5 lc rgb '#000000'"));
  plot.series.push_back({"θ_{R}", {p.theta_R}, {0}, "points pt 6 ps 1.5 lc rgb '#000000'"});
  return plot;
}

// A legend below the axes, two entries a row.
const char* below_axes_key = "outside below center horizontal maxcols 2 samplen 2.5 font ',10'";

// The vertical range of a divider figure: every divider level and every recombination read
// off, and the two shafts up to the last of those readings, with a margin (later the
// open-loop motor runs far off and would squash the construction the figure is about).
std::pair<double, double> divider_window(const Series& motor, const Series& load, const Series& levels, const Series& hits) {
  double t_last = 0, lo = 0, hi = 0;
  for (double t : hits.x) t_last = std::max(t_last, t);
  for (double y : levels.y)
    if (std::isfinite(y)) hi = std::max(hi, y);
  for (const Series* s : {&motor, &load})
    for (std::size_t k = 0; k < s->x.size(); ++k)
      if (s->x[k] <= t_last) lo = std::min(lo, s->y[k]), hi = std::max(hi, s->y[k]);
  const double margin = 0.12 * (hi - lo);
  return {lo - margin, hi + margin};
}

Plot separation_plot(const CaseResult& c, const FigureSpec& spec) {
  const numeric::Parameters& p = c.parameters;
  const double v = printed_number(spec.dtheta_m0), t_end = printed_number(spec.t_end);
  Plot plot;
  plot.name = figure_name(spec);
  const std::string v_text = sig(v, 6);
  plot.title = "Thesis fig. " + std::to_string(spec.number) + ": case " + c.spec.id + ", θ_{m} and θ_{L} during separation (θ̇_{m0} = " + v_text + ")";
  plot.x_label = "t, time since the separation (s)";
  // the legend below the axes: inside, the curves of one case or another run through it
  plot.key = below_axes_key;
  plot.height = 760;
  plot.y_label = "displacement from θ_{R} (rad)";
  Series m{"θ_{m} − θ_{R}, motor", {}, {}, std::string("lines lw 2 lc rgb '") + color_motor + "'"};
  Series l{"θ_{L} − θ_{R}, load", {}, {}, std::string("lines lw 2 lc rgb '") + color_load + "'"};
  Series gap{"θ_{L} − θ_{m} per unit θ̇_{m0} (the gap)", {}, {}, "lines lw 1.5 dt 2 lc rgb '#444444'"};
  const int n = 600;
  for (int k = 0; k <= n; ++k) {
    const double t = t_end * k / n;
    const numeric::FreeState s = c.evaluator().free_state(t, v);
    m.x.push_back(t);
    m.y.push_back(s.theta_m - p.theta_R);
    l.x.push_back(t);
    l.y.push_back(s.theta_L - p.theta_R);
    gap.x.push_back(t);
    gap.y.push_back(s.gap / v);
  }
  plot.series.push_back(m);
  plot.series.push_back(l);
  plot.x_range = std::pair{0.0, t_end};
  const numeric::DividingLinePoint at = c.model->trace_point(v);
  if (at.status == numeric::RecombinationStatus::Recombination && at.t <= t_end) {
    plot.series.push_back({"recombination (gap = b) at t = " + fixed(at.t, 4), {at.t, at.t}, {at.theta_m - p.theta_R, at.theta_L - p.theta_R},
                           "linespoints lw 1 dt 3 pt 7 ps 1.2 lc rgb '#d62728'"});
  }
  if (!spec.dividers.empty()) {
    plot.series.push_back(gap);
    Series levels{"b/θ̇_{m0}: the divider setting for θ̇_{m0}", {}, {}, "lines lw 1 lc rgb '#999999'"};
    Series hits{"recombination times read off (certified crossings)", {}, {}, "points pt 7 ps 1.2 lc rgb '#d62728'"};
    for (const std::string& d : spec.dividers) {
      const double vd = printed_number(d);
      const double level = p.backlash / vd;
      levels.x.insert(levels.x.end(), {0, t_end, nan_value});
      levels.y.insert(levels.y.end(), {level, level, nan_value});
      plot.labels.push_back({"θ̇_{m0} = " + sig(vd, 4), 0.02 * t_end, level + 0.0});
      const numeric::DividingLinePoint q = c.model->trace_point(vd);
      if (q.status == numeric::RecombinationStatus::Recombination && q.t <= t_end) {
        hits.x.push_back(q.t);
        hits.y.push_back(level);
        plot.labels.push_back({"t = " + fixed(q.t, 3), q.t + 0.02 * t_end, level + 0.0});
      }
    }
    plot.series.push_back(levels);
    if (!hits.x.empty()) plot.series.push_back(hits);
    plot.y_range = divider_window(m, l, levels, hits);
  }
  return plot;
}

// θL in the thesis's frame during free flight (measured from the face left at the last separation).
double thesis_frame_load(const numeric::SimulationResult& r, const numeric::Parameters& p, double t, double theta_L) {
  int face = -1;
  for (const numeric::SimulationEvent& e : r.events) {
    if (e.t > t) break;
    if (e.kind == numeric::EventKind::Separation) face = e.after.face;
  }
  return theta_L - face * p.backlash / 2;
}

Plot transient_plot(const CaseResult& c, const FigureSpec* spec, const ThesisData& data) {
  const numeric::Parameters& p = c.parameters;
  Plot plot;
  if (spec) {
    plot.name = figure_name(*spec);
    plot.title = "Thesis fig. " + std::to_string(spec->number) + ": case " + c.spec.id + ", transient response";
  } else {
    plot.name = "case" + c.spec.id + "_step_responses";
    plot.title = "Case " + c.spec.id + ": the thesis's step inputs (no transient figure in the thesis)";
  }
  plot.x_label = "t (s)";
  plot.y_label = "θ_{o} − θ_{o}(0), displacement from the start (rad)";
  plot.key = below_axes_key;  // inside, the oscillating responses run through it
  plot.height = 760;
  double t_max = 0;
  std::vector<const TrajectoryRun*> runs;
  if (spec) {
    for (const std::string& which : spec->trajectories) {
      if (which == "experiment" && !c.runs.empty()) runs.push_back(&c.runs.front());
      if (which == "second")
        for (std::size_t k = 1; k < c.runs.size(); ++k) runs.push_back(&c.runs[k]);
    }
  } else {
    for (const TrajectoryRun& r : c.runs) runs.push_back(&r);
  }
  // the thesis's printed points (and how far they go)
  std::vector<Series> printed;
  for (const TrajectoryRun* run : runs) {
    if (!run->is_step) continue;
    Series main{"", {}, {}, "points pt 6 ps 1.3 lc rgb '#000000'"}, load{"", {}, {}, "points pt 4 ps 1.3 lc rgb '#2a9d3a'"};
    for (const StepPoint& sp : data.step_points) {
      if (sp.case_id != c.spec.id || std::fabs(printed_number(sp.step) - run->step) > 1e-12) continue;
      main.label = readable(sp.table) + " (printed): θ_{o}, θ_{m}";
      load.label = readable(sp.table) + " (printed): θ_{L}, thesis's frame";
      const double t = printed_number(sp.t), y = printed_number(sp.printed);
      const double start = sp.quantity == "theta_o - theta_o(0)" ? 0.0 : (p.theta_R - run->step);
      t_max = std::max(t_max, t);
      if (sp.quantity == "theta_L") {
        load.x.push_back(t);
        load.y.push_back(y - start);
      } else {
        main.x.push_back(t);
        main.y.push_back(y - start);
      }
    }
    if (!main.x.empty()) printed.push_back(main);
    if (!load.x.empty()) printed.push_back(load);
  }
  const double t_end = t_max > 0 ? std::max(2 * t_max, 10.0) : 40.0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const char* color = trajectory_colors[k % 4];
    const double start = runs[k]->result.samples.empty() ? 0 : runs[k]->result.samples.front().theta_o;
    Series s{runs[k]->label + ": θ_{o} − θ_{o}(0)", {}, {}, std::string("lines lw 2 lc rgb '") + color + "'"};
    Series l{runs[k]->label + ": θ_{L} during separation, thesis's frame", {}, {}, std::string("lines lw 1.2 dt 2 lc rgb '") + color + "'"};
    bool was_free = false;
    for (const numeric::TrajectorySample& x : runs[k]->result.samples) {
      if (x.t > t_end) break;
      s.x.push_back(x.t);
      s.y.push_back(x.theta_o - start);
      if (!x.in_contact && p.measured_at == model::MeasuredAt::Motor) {
        l.x.push_back(x.t);
        l.y.push_back(thesis_frame_load(runs[k]->result, p, x.t, x.theta_L) - start);
        was_free = true;
      } else if (was_free) {
        l.x.push_back(nan_value);
        l.y.push_back(nan_value);
        was_free = false;
      }
    }
    plot.series.push_back(s);
    if (k == 0 && !printed.empty() && series_has_data(l)) plot.series.push_back(l);
  }
  for (Series& s : printed) plot.series.push_back(s);
  plot.x_range = std::pair{0.0, t_end};
  return plot;
}

}  // namespace

std::vector<Plot> case_figures(const CaseResult& c, const ThesisData& data) {
  std::vector<Plot> plots;
  bool has_transient = false;
  for (const FigureSpec* spec : figures_of(data, c.spec.id)) {
    if (spec->kind == "phase") plots.push_back(phase_plot(c, *spec));
    else if (spec->kind == "separation") plots.push_back(separation_plot(c, *spec));
    else if (spec->kind == "transient") {
      plots.push_back(transient_plot(c, spec, data));
      has_transient = true;
    } else {
      throw std::runtime_error("thesis_figures.toml: figure " + std::to_string(spec->number) + ": unknown kind '" + spec->kind + "'");
    }
  }
  if (!has_transient) plots.push_back(transient_plot(c, nullptr, data));
  return plots;
}

// ---------------------------------------------------------------- sweeps

std::vector<SweepResult> compute_sweeps() {
  std::vector<SweepResult> out;
  for (const auto& [name, points] : {std::pair<const char*, long>{"fig31", 101}, {"fig32", 79}}) {
    api::SweepRequest request;
    request.target = name;
    request.points = points;
    out.push_back({name, api::sweep(request).rows});
  }
  return out;
}

namespace {

// A sweep's series name ("FL=0 Fm=.2", "JL=4Jm") in the figures' notation: "F_{L} = 0, F_{m} = .2".
std::string readable_series(const std::string& name) {
  std::string out;
  for (std::size_t k = 0; k < name.size(); ++k) {
    const char c = name[k];
    const char next = k + 1 < name.size() ? name[k + 1] : '\0';
    if ((c == 'J' || c == 'F') && (next == 'L' || next == 'm')) {
      out += std::string(1, c) + "_{" + next + "}";
      ++k;
    } else if (c == '=') {
      out += " = ";
    } else if (c == ' ') {
      out += ", ";
    } else {
      out += c;
    }
  }
  return out;
}

bool same_parameters(const numeric::Parameters& a, const numeric::Parameters& b) {
  const auto close = [](double x, double y) { return std::fabs(x - y) <= 1e-9 * std::max(1.0, std::fabs(y)); };
  return a.measured_at == b.measured_at && close(a.Jm, b.Jm) && close(a.Fm, b.Fm) && close(a.JL, b.JL) && close(a.FL, b.FL) &&
         close(a.K, b.K) && close(a.theta_R, b.theta_R) && close(a.backlash, b.backlash);
}

}  // namespace

std::vector<Plot> sweep_figures(const std::vector<SweepResult>& sweeps, const std::vector<CaseResult>& cases,
                                const ThesisData& data) {
  std::vector<Plot> plots;
  for (const SweepResult& sweep : sweeps) {
    const FigureSpec* spec = nullptr;
    for (const FigureSpec& f : data.figures)
      if (f.kind == "sweep" && f.sweep == sweep.name) spec = &f;
    if (!spec) throw std::runtime_error("thesis_figures.toml has no figure for sweep " + sweep.name);
    Plot plot;
    plot.name = figure_name(*spec);
    plot.title = "Thesis fig. " + std::to_string(spec->number) + ": limit-cycle magnitude (peak-to-peak of θ_{o}) vs " +
                 (sweep.name == "fig31" ? "F_{L}/F" : "J_{L}/J_{m}");
    plot.x_label = sweep.name == "fig31" ? "F_{L}/F, load friction over total friction F = F_{m} + F_{L} (ratio)"
                                         : "J_{L}/J_{m}, load inertia over motor inertia (ratio)";
    plot.y_label = "magnitude: peak-to-peak of θ_{o} on the cycle (rad)";
    plot.width = 1000;
    plot.key = "inside right top font ',10'";
    std::vector<std::string> order;
    std::map<std::string, Series> series;
    for (const numeric::SweepRow& row : sweep.rows) {
      if (!series.count(row.point.series)) {
        order.push_back(row.point.series);
        series[row.point.series] = Series{"exact, " + readable_series(row.point.series), {}, {}, ""};
      }
      Series& s = series[row.point.series];
      s.x.push_back(row.point.x);
      s.y.push_back(row.status == numeric::SweepStatus::LimitCycle ? row.cycle.peak_to_peak : nan_value);
    }
    for (std::size_t k = 0; k < order.size(); ++k) {
      Series s = series[order[k]];
      s.style = std::string("lines lw 2 lc rgb '") + trajectory_colors[k % 4] + "'";
      plot.series.push_back(s);
    }
    Series thesis{"the thesis's magnitudes (section 14) at its cases", {}, {}, "points pt 7 ps 1.8 lc rgb '#d62728'"};
    Series exact{"exact magnitudes at those cases", {}, {}, "points pt 6 ps 2.2 lw 2 lc rgb '#000000'"};
    for (const CaseResult& c : cases) {
      if (c.thesis->limit_cycle_printed == "none") continue;
      for (const numeric::SweepRow& row : sweep.rows) {
        if (!same_parameters(row.point.parameters, c.parameters)) continue;
        thesis.x.push_back(row.point.x);
        thesis.y.push_back(printed_number(c.thesis->limit_cycle_printed));
        exact.x.push_back(row.point.x);
        exact.y.push_back(c.cycle.peak_to_peak);
        plot.labels.push_back({"  case " + c.spec.id, row.point.x + 0.01 * (sweep.rows.back().point.x - sweep.rows.front().point.x),
                               printed_number(c.thesis->limit_cycle_printed)});
        break;
      }
    }
    if (!thesis.x.empty()) {
      plot.series.push_back(thesis);
      plot.series.push_back(exact);
    }
    // room on the right for the case labels of the points at the end of the sweep
    const double x0 = sweep.rows.front().point.x, x1 = sweep.rows.back().point.x;
    plot.x_range = std::pair{std::min(0.0, x0), x1 + 0.1 * (x1 - std::min(0.0, x0))};
    // and above and below every curve and point, so no case label sits on the frame
    double lo = INFINITY, hi = -INFINITY;
    for (const Series& s : plot.series)
      for (double y : s.y)
        if (std::isfinite(y)) lo = std::min(lo, y), hi = std::max(hi, y);
    if (lo < hi) plot.y_range = std::pair{lo - 0.06 * (hi - lo), hi + 0.06 * (hi - lo)};
    plots.push_back(plot);
  }
  return plots;
}

}  // namespace backlash::reports
