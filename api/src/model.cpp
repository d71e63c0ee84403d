// model.cpp — the validated model and its results: step response, dividing lines, limit
// cycle, each written as the CLI prints it (the JSON keys are docs/design.md's contract).
#include "backlash/api/backlash.hpp"

#include "format.hpp"

#include "backlash/numeric/effects_limit_cycle.hpp"
#include "backlash/numeric/scales.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>

namespace backlash::api {

using detail::appendf;

namespace {

numeric::ValidationResult validated_nominal(const Case& c) {
  detail::check_parameter_scales(c.spec());
  numeric::ValidationOptions options;
  options.error_coordinates = true;  // the copy the simulators run (in_error_coordinates): θR costs no digits
  numeric::ValidationResult result = numeric::validate(numeric::case_evaluator(c.spec()), options);
  if (!result.passed()) {
    std::string failing;
    for (const numeric::StateError& s : result.report().states)
      if (!s.passed) failing += (failing.empty() ? "" : ", ") + s.state;
    throw numeric::ValidationFailed("case " + c.id() + ": the evaluator failed validation against odeint (" + failing +
                                    "); refusing to use it");
  }
  return result;
}

// The engaged mesh's closed forms (an eigen-decomposition) lose accuracy with the mesh's phase:
// where they miss the gate, the stiffness and damping are refused as input (exit 2) with the
// error found; any other mode missing it is a failure of ours (ValidationFailed, exit 1).
void refuse_unresolved_mesh(const numeric::EffectValidationReport& report, const Case& c) {
  std::string failing;
  for (const numeric::ModeValidation& m : report.modes) {
    if (m.passed) continue;
    if (m.mode.kind != numeric::ModeKind::Mesh) return;
    if (failing.empty())
      appendf(failing, "max |error| %.3g > %.3g at %.3g s", m.max_abs_error, report.tolerance, m.at_tau);
  }
  const numeric::Effects& e = c.effects();
  const numeric::Parameters p = c.parameters();
  const double zeta = e.mesh_damping / (2 * std::sqrt(e.mesh_stiffness * p.Jm * p.JL / (p.Jm + p.JL)));
  throw model::CaseFileError(c.spec().source, 0, "compliance",
                             "cannot be computed: the closed forms of the engaged mesh (stiffness " +
                                 detail::number_text(e.mesh_stiffness) + ", damping ratio " + detail::number_text(zeta) +
                                 ") miss the odeint gate (" + failing +
                                 "): the rounding of their eigen-decomposition grows with the mesh's phase over the "
                                 "gate's horizon of 400 mesh radians");
}

numeric::EffectValidationResult validated_effects(const numeric::ValidationResult& nominal, const Case& c) {
  numeric::EffectValidationResult effects = numeric::validate_effects(nominal.evaluator(), c.effects());
  if (!effects.passed()) {
    refuse_unresolved_mesh(effects.report(), c);
    (void)effects.model();  // throws ValidationFailed, naming the failing modes
  }
  return effects;
}

/// The step A: the request's, else the case's [experiment] step.
double requested_step(const model::CaseSpec& spec, const std::optional<double>& given) {
  if (given) {
    if (!std::isfinite(*given)) throw BadInput("step", "not finite, got " + detail::number_text(*given));
    return *given;
  }
  if (!spec.experiment) throw BadInput("step", "required (the case has no [experiment] step)");
  if (spec.experiment->kind != model::ExperimentKind::Step)
    throw BadInput("step", "required (the case's experiment is a measured drive, which needs its record: use the "
                           "discrepancy workflow)");
  return model::to_double(spec.experiment->step);
}

/// The end time: the request's, else the case's t_end, else 60 s.
double requested_t_end(const model::CaseSpec& spec, const std::optional<double>& given) {
  if (given) {
    if (!std::isfinite(*given) || *given <= 0) throw BadInput("t_end", "must be > 0, got " + detail::number_text(*given));
    return *given;
  }
  return spec.experiment && spec.experiment->t_end ? model::to_double(*spec.experiment->t_end) : 60.0;
}

/// `simulate --csv`'s header and rows (shared by the whole CSV and the streamed one).
constexpr const char* csv_header = "t,theta_o,dtheta_o,theta_m,dtheta_m,theta_L,dtheta_L,mode\n";

void append_sample(std::string& out, const numeric::TrajectorySample& s, const char* contact_mode) {
  // One formatting pass per row (a streamed CSV has millions): 7 numbers of at most 24
  // characters and the mode always fit the buffer.
  char row[256];
  const int n = std::snprintf(row, sizeof row, "%.10g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s\n", s.t, s.theta_o,
                              s.dtheta_o, s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, s.in_contact ? contact_mode : "free");
  out.append(row, static_cast<std::size_t>(std::min(n, static_cast<int>(sizeof row) - 1)));
}

/// The CSV's last line after an early stop (nothing otherwise).
std::string csv_end(const Simulation& run) {
  std::string out;
  if (run.stopped_early())
    appendf(out, "# stopped early at t = %.10g: %s: %s\n", run.result.t_final, numeric::to_string(run.result.status),
            run.result.stop_reason.c_str());
  return out;
}

}  // namespace

// ---------------------------------------------------------------------- the model

Model::Model(Case source)
    : case_(std::move(source)), validation_(validated_nominal(case_)), effects_(validated_effects(validation_, case_)) {}

namespace {

/// A sample interval >= 0 (0: events only) giving at most largest_sample_count samples to t_end.
void check_sampling(double sample_interval, double t_end) {
  if (!std::isfinite(sample_interval) || sample_interval < 0)
    throw BadInput("sample_interval", "must be >= 0, got " + detail::number_text(sample_interval));
  if (sample_interval > 0 && t_end / sample_interval + 1 > largest_sample_count) {
    std::string problem;
    appendf(problem, "%g s over t_end = %g s gives %.3g samples; at most %g are recorded (use a larger interval or a "
                     "shorter t_end)", sample_interval, t_end, std::floor(t_end / sample_interval) + 1, largest_sample_count);
    throw BadInput("sample_interval", problem);
  }
}

/// A simulation of `m` to `t_end`, its sampling checked, with the model's case, parameters and
/// effects; its start and its result are still to come.
Simulation simulation_of(const Model& m, double t_end, double sample_interval) {
  check_sampling(sample_interval, t_end);
  Simulation out;
  out.t_end = t_end;
  out.case_id = m.id();
  out.parameters = m.evaluator().parameters();
  out.effects = m.effect_model().effects();
  return out;
}

/// A simulation's request checked and its options made; the result is still to be computed.
Simulation prepared(const Model& m, const SimulationRequest& request, numeric::SimulationOptions& options) {
  const model::CaseSpec& spec = m.source().spec();
  const double step = requested_step(spec, request.step);
  Simulation out = simulation_of(m, requested_t_end(spec, request.t_end), request.sample_interval);
  out.step = step;
  // A step whose motion double precision cannot resolve against the backlash is refused
  // before any work (numeric/scales.hpp): an answer there would be rounding noise.
  const std::string what = request.step ? "the step " + detail::number_text(out.step) : "the step of the case file";
  if (const auto problem = numeric::resolution_problem(out.parameters, std::fabs(out.step), what))
    throw BadInput("step", *problem);
  if (const auto problem = numeric::time_resolution_problem(out.parameters, out.effects, out.t_end))
    throw BadInput("t_end", *problem);
  options.t_end = out.t_end;
  options.sample_interval = request.sample_interval;
  return out;
}

}  // namespace

Simulation Model::simulate(const SimulationRequest& request) const {
  numeric::SimulationOptions options;
  Simulation out = prepared(*this, request, options);
  out.result = numeric::simulate_effects_step(effect_model(), out.step, options);
  return out;
}

void check_sample_interval(double sample_interval) {
  if (!std::isfinite(sample_interval) || !(sample_interval > 0))
    throw BadInput("sample_interval", "must be > 0, got " + detail::number_text(sample_interval));
}

namespace {

/// Runs `out` (its options prepared) with its CSV handed to `csv` as it is computed:
/// the header, each sample, the early-stop line (simulate_csv, simulate_from_state_csv).
void stream_csv(Simulation& out, numeric::SimulationOptions& options, const TextSink& csv,
                const std::function<numeric::SimulationResult(const numeric::SimulationOptions&)>& run) {
  const char* contact_mode = out.effects.compliant() ? "mesh" : "contact";
  csv(csv_header);
  std::string line;
  options.event_sink = [](const numeric::SimulationEvent&) {};  // the CSV prints samples only: events not kept
  options.sample_sink = [&](const numeric::TrajectorySample& s) {
    line.clear();
    append_sample(line, s, contact_mode);
    csv(line);
  };
  out.result = run(options);
  if (const std::string end = csv_end(out); !end.empty()) csv(end);
}

}  // namespace

Simulation Model::simulate_csv(const SimulationRequest& request, const TextSink& csv) const {
  check_sample_interval(request.sample_interval);
  numeric::SimulationOptions options;
  Simulation out = prepared(*this, request, options);
  stream_csv(out, options, csv, [&](const numeric::SimulationOptions& o) {
    return numeric::simulate_effects_step(effect_model(), out.step, o);
  });
  return out;
}

// ---------------------------------------------------------------------- a run from any state

StartState start_state(const numeric::Parameters& p, const std::vector<double>& from, bool in_contact,
                       std::optional<double> gap, std::optional<double> other_velocity) {
  if (from.size() == 4) {
    if (gap) throw BadInput("gap", "only with the measured shaft's two values (from = theta_o, dtheta_o)");
    if (other_velocity) throw BadInput("other_velocity", "only with the measured shaft's two values (from = theta_o, dtheta_o)");
    return {from[0], from[1], from[2], from[3], in_contact};
  }
  if (from.size() != 2)
    throw BadInput("from", "expected theta_m,dtheta_m,theta_L,dtheta_L or theta_o,dtheta_o, got " +
                               std::to_string(from.size()) + " values");
  const double theta_o = from[0], dtheta_o = from[1];
  // In contact: the face driving toward θR; in flight: the face contact would leave at this state (eq. 25's Tc).
  const int face = in_contact ? (theta_o <= p.theta_R ? -1 : +1) : (numeric::transmitted_torque_at(p, theta_o, dtheta_o) > 0 ? +1 : -1);
  const double x = gap.value_or(face * p.backlash / 2);  // θL − θm
  const double other = other_velocity.value_or(dtheta_o);
  if (p.measured_at == model::MeasuredAt::Motor) return {theta_o, dtheta_o, theta_o + x, other, in_contact};
  return {theta_o - x, other, theta_o, dtheta_o, in_contact};
}

namespace {

/// A free start on a face σ must open the gap: not move into the face, and — both shafts at
/// one velocity, the nominal model — not be a state where contact on σ holds (−σ·Tc > 0: the
/// drive presses the shafts together; the flight would end at once).
void refuse_closing_flight(const numeric::Parameters& p, const numeric::Effects& e, const numeric::HybridState& h) {
  const double dx = h.dtheta_L - h.dtheta_m;
  const std::string where = "in free flight on the face x = " + std::string(h.face > 0 ? "+" : "-") + "b/2";
  if (h.face * dx > 0)
    throw BadInput("from", where + " the gap would close beyond the face (dtheta_L - dtheta_m = " +
                               detail::number_text(dx) + "): start in contact");
  if (dx != 0 || e.any()) return;
  const double torque = numeric::transmitted_torque_at(p, numeric::measured(p, h), numeric::measured_velocity(p, h));
  if (-h.face * torque > 0)
    throw BadInput("from", where + " the drive presses the shafts together (transmitted torque " +
                               detail::number_text(torque) + " holds contact on this face): start in contact, or "
                               "in flight from the other face");
}

/// The start state checked for admissibility (StartState's rules; BadInput "from" naming the
/// coordinate and the rule), made exact on its face: the measured shaft kept, the other one at
/// x = ±b/2 from it, so that a typed decimal state lies on the face.
numeric::HybridState admitted_start(const numeric::Parameters& p, const numeric::Effects& e, const StartState& s) {
  const std::pair<const char*, double> values[] = {
      {"theta_m", s.theta_m}, {"dtheta_m", s.dtheta_m}, {"theta_L", s.theta_L}, {"dtheta_L", s.dtheta_L}};
  for (const auto& [name, v] : values)
    if (!std::isfinite(v)) throw BadInput("from", std::string(name) + " is not finite, got " + detail::number_text(v));
  const double half = p.backlash / 2, x = s.theta_L - s.theta_m;
  const double slack = 1e-12 * std::max({half, std::fabs(s.theta_m), std::fabs(s.theta_L)});  // the rounding of x
  const bool at_face = std::fabs(std::fabs(x) - half) <= slack;
  const std::string gap = "the gap theta_L - theta_m = " + detail::number_text(x);
  const std::string faces = " (the faces are at +-b/2 = +-" + detail::number_text(half) + ")";
  numeric::HybridState h{s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, s.in_contact, x > 0 ? +1 : -1};
  if (!s.in_contact) {
    if (p.backlash <= 0) throw BadInput("from", "a rigid drive (backlash 0) has no free flight: start in contact");
    if (std::fabs(x) > half + slack) throw BadInput("from", gap + " is outside the backlash" + faces);
    // Strictly inside (numeric::inside_backlash, the same rounding rule): any velocities, the face
    // σ the nearer one (x > 0: +b/2, else −b/2); on a face: a flight leaving it.
    if (at_face) refuse_closing_flight(p, e, h);
  } else if (e.compliant()) {
    if (std::fabs(x) < half - slack)
      throw BadInput("from", gap + " is inside the backlash: the mesh is engaged only at or beyond a face" + faces +
                                 "; start in free flight instead");
  } else {
    if (!at_face) throw BadInput("from", gap + " is not on a face" + faces + ": in contact the gap is +-b/2; start in "
                                           "free flight for a gap inside");
    if (std::fabs(s.dtheta_m - s.dtheta_L) > 1e-12 * std::max(std::fabs(s.dtheta_m), std::fabs(s.dtheta_L)))
      throw BadInput("from", "in contact both shafts move at one velocity: dtheta_m = " + detail::number_text(s.dtheta_m) +
                                 ", dtheta_L = " + detail::number_text(s.dtheta_L));
  }
  if (at_face && !(s.in_contact && e.compliant())) {  // exactly on the face, the measured shaft kept
    const double theta_o = numeric::measured(p, h);
    (p.measured_at == model::MeasuredAt::Motor ? h.theta_L : h.theta_m) =
        theta_o + (p.measured_at == model::MeasuredAt::Motor ? 1 : -1) * h.face * half;
  }
  if (s.in_contact && !e.compliant()) h.dtheta_m = h.dtheta_L = numeric::measured_velocity(p, h);
  h.drive_regime = numeric::drive_regime(p, e, numeric::measured(p, h));
  return h;
}

/// A run from a state: its request checked and its options made; the result is still to be computed.
Simulation prepared_from(const Model& m, const StartState& start, const SimulationRequest& request,
                         numeric::SimulationOptions& options) {
  if (request.step) throw BadInput("step", "not with a start state (--from): the run starts from that state");
  Simulation out = simulation_of(m, requested_t_end(m.source().spec(), request.t_end), request.sample_interval);
  out.start = admitted_start(out.parameters, out.effects, start);
  if (const auto problem = numeric::time_resolution_problem(out.parameters, out.effects, out.t_end))
    throw BadInput("t_end", *problem);
  options.t_end = out.t_end;
  options.sample_interval = request.sample_interval;
  return out;
}

}  // namespace

Simulation Model::simulate_from_state(const StartState& start, const SimulationRequest& request) const {
  numeric::SimulationOptions options;
  Simulation out = prepared_from(*this, start, request, options);
  out.result = numeric::simulate_effects(effect_model(), *out.start, options);
  return out;
}

Simulation Model::simulate_from_state_csv(const StartState& start, const SimulationRequest& request,
                                          const TextSink& csv) const {
  check_sample_interval(request.sample_interval);
  numeric::SimulationOptions options;
  Simulation out = prepared_from(*this, start, request, options);
  stream_csv(out, options, csv, [&](const numeric::SimulationOptions& o) {
    return numeric::simulate_effects(effect_model(), *out.start, o);
  });
  return out;
}

void detail::check_parameter_scales(const model::CaseSpec& spec) {
  numeric::Parameters p = numeric::parameters_of(spec);
  p.theta_R = 0;  // the numerics run in error coordinates: θR plays no part
  if (const std::optional<std::string> problem = numeric::parameter_scale_problem(p))
    throw model::CaseFileError(spec.source, 0, "", "cannot be computed in double precision: " + *problem);
  if (const std::optional<std::string> problem = numeric::effect_scale_problem(p, numeric::effects_of(spec)))
    throw model::CaseFileError(spec.source, 0, "", "cannot be computed: " + *problem);
}

Trace Model::trace(const std::vector<double>& v0) const {
  if (v0.empty()) throw BadInput("v0", "empty list");
  for (const double v : v0)
    if (!std::isfinite(v)) throw BadInput("v0", "not finite, got " + detail::number_text(v));
  Trace out;
  out.case_id = case_.id();
  out.evaluator = evaluator().evaluator().name();
  out.lines = numeric::trace_dividing_lines(evaluator(), v0);
  return out;
}

numeric::DividingLinePoint Model::trace_point(double v0) const {
  if (!std::isfinite(v0)) throw BadInput("v0", "not finite, got " + detail::number_text(v0));
  return numeric::dividing_line_point(evaluator(), v0);
}

Simulation Model::simulate_from(const FreeFlightStart& start, double t_end, double sample_interval) const {
  if (start.face != -1 && start.face != +1) throw BadInput("face", "expected -1 or +1, got " + std::to_string(start.face));
  if (!std::isfinite(start.theta_o)) throw BadInput("theta_o", "not finite, got " + detail::number_text(start.theta_o));
  if (!std::isfinite(start.dtheta_o)) throw BadInput("dtheta_o", "not finite, got " + detail::number_text(start.dtheta_o));
  if (!std::isfinite(t_end) || t_end <= 0) throw BadInput("t_end", "must be > 0, got " + detail::number_text(t_end));
  Simulation out = simulation_of(*this, t_end, sample_interval);
  if (const auto problem = numeric::time_resolution_problem(out.parameters, out.effects, t_end))
    throw BadInput("t_end", *problem);
  numeric::HybridState state = numeric::state_on_face(out.parameters, start.face, start.theta_o, start.dtheta_o, false);
  state.drive_regime = numeric::drive_regime(out.parameters, out.effects, start.theta_o);
  numeric::SimulationOptions options;
  options.t_end = t_end;
  options.sample_interval = sample_interval;
  out.result = numeric::simulate_effects(effect_model(), state, options);
  return out;
}

Cycle Model::limit_cycle() const {
  const model::CaseSpec& spec = case_.spec();
  numeric::EffectLimitCycleOptions options;
  if (spec.experiment && spec.experiment->kind == model::ExperimentKind::Step)
    options.step = model::to_double(spec.experiment->step);
  Cycle out;
  out.case_id = case_.id();
  out.parameters = evaluator().parameters();
  out.effects = effect_model().effects();
  if (out.effects.any()) {
    out.cycle = numeric::find_limit_cycle(effect_model(), options);
  } else {  // the single answer lists every further cycle (the survey runs after Newton too)
    numeric::LimitCycleOptions nominal;
    nominal.list_other_fixed_points = true;
    out.cycle = numeric::find_limit_cycle(effect_model().nominal(), nominal);
  }
  return out;
}

// ---------------------------------------------------------------------- simulate

bool Simulation::stopped_early() const { return numeric::stopped_early(result.status); }

std::string Simulation::stop_message() const {
  std::string out;
  if (stopped_early())
    appendf(out, "stopped early at t = %.10g (%s): %s", result.t_final, numeric::to_string(result.status),
            result.stop_reason.c_str());
  return out;
}

namespace {

nlohmann::json events_json(const std::vector<numeric::SimulationEvent>& events) {
  nlohmann::json out = nlohmann::json::array();
  for (const numeric::SimulationEvent& e : events) {
    nlohmann::json event{{"t", e.t},
                         {"kind", numeric::to_string(e.kind)},
                         {"theta_o", e.theta_o},
                         {"dtheta_o", e.dtheta_o},
                         {"theta_m", e.after.theta_m},
                         {"theta_L", e.after.theta_L},
                         {"bounce", e.bounce}};
    if (e.body != numeric::Body::None) event["body"] = numeric::to_string(e.body);
    if (e.accumulation) event["accumulation"] = true;
    out.push_back(event);
  }
  return out;
}

}  // namespace

std::string Simulation::json() const {
  const numeric::HybridState& f = result.final_state;
  nlohmann::json out{{"case", case_id},
                     {"step", step},
                     {"t_end", t_end},
                     {"effects", detail::effects_json(effects)},
                     {"status", numeric::to_string(result.status)},
                     {"events", events_json(result.events)},
                     {"final",
                      {{"t", result.t_final},
                       {"theta_o", result.theta_o_final},
                       {"error", final_error()},
                       {"theta_m", f.theta_m},
                       {"theta_L", f.theta_L},
                       {"dtheta_m", f.dtheta_m},
                       {"dtheta_L", f.dtheta_L},
                       {"in_contact", f.in_contact},
                       {"motor_stuck", f.motor_stuck},
                       {"load_stuck", f.load_stuck}}}};
  if (start)
    out["from"] = {{"theta_m", start->theta_m}, {"dtheta_m", start->dtheta_m}, {"theta_L", start->theta_L},
                   {"dtheta_L", start->dtheta_L}, {"in_contact", start->in_contact}, {"face", start->face}};
  if (stopped_early()) out["stop_reason"] = result.stop_reason;
  return detail::document(out);
}

std::string Simulation::csv() const {
  std::string out = csv_header;
  const char* contact_mode = effects.compliant() ? "mesh" : "contact";
  for (const numeric::TrajectorySample& s : result.samples) append_sample(out, s, contact_mode);
  return out + csv_end(*this);
}

std::string Simulation::text() const {
  std::string out;
  if (start)
    appendf(out, "%s, from theta_m = %.10g, dtheta_m = %.10g, theta_L = %.10g, dtheta_L = %.10g (%s) over %g s: %s, %zu "
                 "events (effects: %s)\n", case_id.c_str(), start->theta_m, start->dtheta_m, start->theta_L, start->dtheta_L,
            start->in_contact ? "contact" : "free flight", t_end, numeric::to_string(result.status), result.events.size(),
            effects.describe().c_str());
  else
    appendf(out, "%s, step %g over %g s: %s, %zu events (effects: %s)\n", case_id.c_str(), step, t_end,
            numeric::to_string(result.status), result.events.size(), effects.describe().c_str());
  for (const numeric::SimulationEvent& e : result.events)
    appendf(out, "  t = %14.10f  %-13s theta_o = %12.8f  dtheta_o = %12.8f%s%s%s\n", e.t, numeric::to_string(e.kind),
            e.theta_o, e.dtheta_o, e.bounce ? "  (bounce)" : "", e.accumulation ? "  (end of a bounce series)" : "",
            e.body != numeric::Body::None ? (std::string("  ") + numeric::to_string(e.body)).c_str() : "");
  appendf(out, "final: t = %g  theta_o = %.10f  theta_m = %.10f  theta_L = %.10f  error theta_o - theta_R = %.10f\n",
          result.t_final, result.theta_o_final, result.final_state.theta_m, result.final_state.theta_L, final_error());
  if (stopped_early()) out += stop_message() + "\n";
  return out;
}

// ---------------------------------------------------------------------- trace

namespace {
nlohmann::json maybe(bool present, double value) { return present ? nlohmann::json(value) : nlohmann::json(nullptr); }
}  // namespace

std::string Trace::json() const {
  nlohmann::json points = nlohmann::json::array();
  for (const numeric::DividingLinePoint& p : lines.points) {
    const bool ok = numeric::has_impact(p.status);
    points.push_back({{"v0", p.dtheta_m0},
                      {"status", numeric::to_string(p.status)},
                      {"grazing", p.grazing},
                      {"t", maybe(ok, p.t)},
                      {"theta_m", maybe(ok, p.theta_m)},
                      {"dtheta_m", maybe(ok, p.dtheta_m)},
                      {"theta_L", maybe(ok, p.theta_L)},
                      {"dtheta_L", maybe(ok, p.dtheta_L)},
                      {"theta_o", maybe(ok, p.theta_o)},
                      {"dtheta_o", maybe(ok, p.dtheta_o)}});
  }
  nlohmann::json out{
      {"case", case_id},
      {"cot_phi", lines.cot_phi},
      {"threshold", lines.threshold ? nlohmann::json(*lines.threshold) : nlohmann::json(nullptr)},
      {"horizon", lines.horizon},
      {"evaluator", evaluator},
      {"convention", "theta_m(0) = theta_L(0) = theta_R + cot_phi*v0; m, L before the impact, o after it (eq. 24)"},
      {"points", points}};
  if (!lines.work_limit.empty()) out["work_limit"] = lines.work_limit;  // only when a point is unresolved
  return detail::document(out);
}

std::string Trace::csv() const {
  std::string out = "v0,status,grazing,t,theta_m,dtheta_m,theta_L,dtheta_L,theta_o,dtheta_o\n";
  for (const numeric::DividingLinePoint& p : lines.points) {
    appendf(out, "%.17g,%s,%s", p.dtheta_m0, numeric::to_string(p.status), p.grazing ? "true" : "false");
    if (!numeric::has_impact(p.status))
      out += ",,,,,,,\n";
    else
      appendf(out, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", p.t, p.theta_m, p.dtheta_m, p.theta_L, p.dtheta_L,
              p.theta_o, p.dtheta_o);
  }
  return out;
}

std::string Trace::text() const {
  std::string out;
  appendf(out, "%s: separation line theta_o = theta_R %+.10g*dtheta_o", case_id.c_str(), lines.cot_phi);
  if (lines.threshold) appendf(out, "; no recombination for |dtheta_m0| < %.10g", *lines.threshold);
  appendf(out, "\n%10s %-13s %14s %12s %12s %12s %12s %12s %12s\n", "dtheta_m0", "status", "t", "theta_m", "dtheta_m",
          "theta_L", "dtheta_L", "theta_o", "dtheta_o+");
  for (const numeric::DividingLinePoint& p : lines.points) {
    if (!numeric::has_impact(p.status)) {
      appendf(out, "%10.6g %-13s\n", p.dtheta_m0, numeric::to_string(p.status));
      continue;
    }
    appendf(out, "%10.6g %-13s %14.10f %12.8f %12.8f %12.8f %12.8f %12.8f %12.8f\n", p.dtheta_m0,
            numeric::to_string(p.status), p.t, p.theta_m, p.dtheta_m, p.theta_L, p.dtheta_L, p.theta_o, p.dtheta_o);
  }
  if (!lines.work_limit.empty()) appendf(out, "work_limit: %s\n", lines.work_limit.c_str());
  return out;
}

// ---------------------------------------------------------------------- limit cycle

std::string Cycle::status() const { return detail::status_text(cycle.status); }

std::string Cycle::json() const {
  const bool ok = found();
  const bool with_effects = effects.any();
  auto value = [&](double v) { return ok && std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json out{{"case", case_id},
                     {"status", status()},
                     {"amplitude", value(cycle.amplitude)},
                     {"peak_to_peak", value(cycle.peak_to_peak)},
                     {"period", value(cycle.period)},
                     {"separation_velocity", value(cycle.separation_velocity)},
                     {"multiplier", value(cycle.multiplier)},
                     {"half_map_derivative", value(cycle.half_map_derivative)},
                     {"stable", ok && cycle.stable},
                     {"peak_to_peak_motor", value(cycle.peak_to_peak_motor)},
                     {"peak_to_peak_load", value(cycle.peak_to_peak_load)},
                     {"bounce", ok && cycle.bounced},
                     {"other_fixed_points", cycle.other_fixed_points},
                     {"effects", detail::effects_json(effects)},
                     {"method", cycle.method}};
  // A cycle that crosses the return map's section k > 1 times per period (docs/design.md).
  if (ok && cycle.period_count > 1) out["period_count"] = cycle.period_count;
  if (with_effects) {
    out["iterations"] = cycle.iterations;
    out["residual"] = value(cycle.residual);
  } else {
    out["survey_fallback"] = cycle.survey_fallback;  // Newton from the first guess did not settle
    out["stability_constant"] = {{"C_separation", value(cycle.C_separation)},
                                 {"C_recombination", value(cycle.C_recombination)},
                                 {"contact_arc_crossings_of_theta_R", cycle.contact_arc_crossings_of_theta_R},
                                 {"jump_factor_across_theta_R", numeric::stability_constant_jump(parameters)}};
  }
  if (!ok) out["reason"] = cycle.reason;
  if (!ok && cycle.rest_error != 0) out["rest_error"] = cycle.rest_error;
  return detail::document(out);
}

std::string Cycle::text() const {
  std::string out;
  if (!found()) {
    appendf(out, "%s: %s: %s\n", case_id.c_str(),
            cycle.status == numeric::CycleStatus::Unresolved ? "limit cycle unresolved" : "no limit cycle",
            cycle.reason.c_str());
    return out;
  }
  const std::string kind = cycle.period_count > 1 ? "period-" + std::to_string(cycle.period_count) + " cycle" : "limit cycle";
  appendf(out, "%s: %s %s (%s; effects: %s)\n", case_id.c_str(), cycle.stable ? "stable" : "unstable", kind.c_str(),
          cycle.method.c_str(), effects.describe().c_str());
  if (std::isfinite(cycle.separation_velocity))
    appendf(out, "  separation velocity  %.12f\n", cycle.separation_velocity);
  else  // the bodies part only at impacts (restitution), never at a separation event
    appendf(out, "  separation velocity  none (the bodies part only by bouncing at impacts)\n");
  appendf(out, "  multiplier (P')      %.9f\n  period               %.9f\n", cycle.multiplier, cycle.period);
  appendf(out, "  amplitude |θo−θR|    %.9f\n  peak-to-peak θo      %.9f\n  peak-to-peak θm, θL  %.9f, %.9f\n",
          cycle.amplitude, cycle.peak_to_peak, cycle.peak_to_peak_motor, cycle.peak_to_peak_load);
  if (!effects.any())
    appendf(out, "  eq. 38: C at separation %.9f, after recombination %.9f (contact arc crosses θR %d×)\n",
            cycle.C_separation, cycle.C_recombination, cycle.contact_arc_crossings_of_theta_R);
  return out;
}

}  // namespace backlash::api
