// explorer_core.cpp — the explorer page's numeric core (explorer/README.md): the facade
// (backlash/api/backlash.hpp) compiled to WebAssembly, behind a few functions that take and
// return JSON text.  No physics here: every number the page draws comes from the same C++ as
// the CLI — the validated model (Model), its step response and runs from a state
// (simulate_from_state, `simulate --from`), the limit cycle, the dividing lines (trace); the
// JSON documents are the CLI's own (Simulation::json, Cycle::json, Trace::json).  The only
// formula here is the isoclines' slope table (eq. 25 solved for θ̇o at slope η), a drawing aid.
//
// Errors come back as {"ok": false, "field": NAME, "message": TEXT}: the facade's BadInput
// names its argument, a case file's error its key; the page shows the message beside the field.
#include "backlash/api/backlash.hpp"
#include "backlash/model/effect_table.hpp"

#include <emscripten/bind.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace backlash::explorer {

using nlohmann::json;

namespace {

/// The model the page shows, and the parameter texts it was made from (for slices).
struct Current {
  std::unique_ptr<api::Model> model;
  std::vector<std::pair<std::string, std::string>> texts;
};
Current& current() {
  static Current c;
  return c;
}

/// An exact rational as the text a field shows: a terminating decimal exactly ("0.3"), else "p/q".
std::string field_text(const model::Rational& r) {
  using boost::multiprecision::cpp_int;
  model::Rational x = r;
  int k = 0;
  while (denominator(x) != 1 && k < 40) x *= 10, ++k;
  if (denominator(x) != 1) return numerator(r).str() + "/" + denominator(r).str();
  const cpp_int n = numerator(x);
  std::string digits = (n < 0 ? cpp_int(-n) : n).str();
  if (k > 0) {
    if (static_cast<int>(digits.size()) <= k) digits.insert(0, static_cast<std::size_t>(k + 1) - digits.size(), '0');
    digits.insert(digits.size() - static_cast<std::size_t>(k), ".");
  }
  return (n < 0 ? "-" : "") + digits;
}

/// What the page shows of an error: the field it concerns and the one-line message.
std::string error_json(const std::string& field, const std::string& message) {
  return json{{"ok", false}, {"field", field}, {"message", message}}.dump();
}

template <class Work>
std::string guarded(Work&& work) {
  try {
    return work();
  } catch (const api::BadInput& e) {
    return error_json(e.argument(), e.what());
  } catch (const model::CaseFileError& e) {
    return error_json(e.key(), e.what());
  } catch (const std::exception& e) {
    return error_json("", e.what());
  }
}

/// The parameters of a case as the texts of the page's fields (Case::from_texts's names).
json case_fields(const api::Case& c) {
  const model::CaseSpec& s = c.spec();
  json f{{"name", s.name}, {"measured_at", s.measured_at == model::MeasuredAt::Motor ? "motor" : "load"},
         {"Jm", field_text(s.Jm)}, {"Fm", field_text(s.Fm)}, {"JL", field_text(s.JL)}, {"FL", field_text(s.FL)}, {"K", field_text(s.K)}, {"backlash", field_text(s.backlash)},
         {"reference", field_text(s.reference)}};
  if (s.experiment && s.experiment->kind == model::ExperimentKind::Step) {
    f["step"] = field_text(s.experiment->step);
    if (s.experiment->t_end) f["t_end"] = field_text(*s.experiment->t_end);
  }
#define BACKLASH_EXPLORER_EFFECT(FIELD, EFFECT, KEY, NAME, ...) \
  if (s.effects.FIELD) f[NAME] = field_text(*s.effects.FIELD);
  BACKLASH_EFFECT_PARAMETERS(BACKLASH_EXPLORER_EFFECT)
#undef BACKLASH_EXPLORER_EFFECT
  return f;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// The samples of the last runs, by name ("run": the last trajectory or step response,
/// "orbit": the limit cycle's), as five columns one after the other — t, θo, θ̇o, θm, θL, each
/// `count` long — that the page reads as typed arrays straight from the module's memory
/// (samples(NAME)), not as JSON text: a frame draws several runs of ~800 samples each.
std::vector<double>& sample_buffer(const std::string& name) {
  static std::vector<double> run, orbit;
  return name == "orbit" ? orbit : run;
}
void keep_samples(const std::string& name, const std::vector<numeric::TrajectorySample>& samples) {
  std::vector<double>& out = sample_buffer(name);
  const std::size_t n = samples.size();
  out.resize(5 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const numeric::TrajectorySample& s = samples[i];
    out[i] = s.t, out[n + i] = s.theta_o, out[2 * n + i] = s.dtheta_o, out[3 * n + i] = s.theta_m, out[4 * n + i] = s.theta_L;
  }
}

/// A run as the page needs it: the CLI's JSON document (spliced in as text: no parse and
/// dump again), the time it took; its samples kept as "run".
std::string run_json(const api::Simulation& run, double ms) {
  keep_samples("run", run.result.samples);
  json head{{"ok", true}, {"ms", ms}, {"count", run.result.samples.size()}};
  if (run.stopped_early()) head["stop_message"] = run.stop_message();
  std::string out = head.dump();
  out.pop_back();  // the closing brace: the simulation document follows
  return out + ",\"simulation\":" + run.json() + "}";
}

const api::Model& model() {
  if (!current().model) throw api::BadInput("case", "no case loaded");
  return *current().model;
}

}  // namespace

/// A case file's text (a thesis case's, embedded in the page) → its fields, without loading it.
std::string fields_of_case(const std::string& toml, const std::string& id) {
  return guarded([&] {
    return json{{"ok", true}, {"fields", case_fields(api::Case::from_text(toml, id + ".toml", id))}}.dump();
  });
}

/// The page's fields (a JSON array of [name, text] pairs, Case::from_texts's names) → the
/// validated model, kept as the current one; its summary: parameters, the separation line's
/// cot φ, the isoclines' slopes, the case file the CLI reads.
std::string load_case(const std::string& pairs_json) {
  return guarded([&] {
    const auto t0 = std::chrono::steady_clock::now();
    const auto texts = json::parse(pairs_json).get<std::vector<std::pair<std::string, std::string>>>();
    auto loaded = std::make_unique<api::Model>(api::Case::from_texts(texts));
    current().model = std::move(loaded);
    current().texts = texts;
    const api::Model& m = model();
    const numeric::Parameters& p = m.evaluator().parameters();
    json isoclines = json::array();  // contact mode: θ̈o = η θ̇o on θ̇o = K(θR − θo)/(J η + F)
    for (const double eta : {-3.0, -2.0, -1.5, -1.0, -0.75, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0, 2.0}) {
      const double denominator = (p.Jm + p.JL) * eta + p.Fm + p.FL;
      if (denominator != 0) isoclines.push_back({{"eta", eta}, {"slope", p.K / denominator}});
    }
    return json{{"ok", true},
                {"parameters", {{"Jm", p.Jm}, {"Fm", p.Fm}, {"JL", p.JL}, {"FL", p.FL}, {"K", p.K},
                                {"backlash", p.backlash}, {"theta_R", p.theta_R},
                                {"measured_at", p.measured_at == model::MeasuredAt::Motor ? "motor" : "load"}}},
                {"cot_phi", m.evaluator().cot_phi()},
                {"effects", m.effect_model().effects().describe()},
                {"isoclines", isoclines},
                {"case_file", m.source().case_file()},
                {"ms", milliseconds_since(t0)}}
        .dump();
  });
}

/// The θ̇m0 of the dividing lines of both faces, as the report draws them (reports/src/
/// case_results.cpp): the default grid (numeric::default_dividing_line_grid, θ̇m0 > 0: the
/// separation from the face x = −b/2) and its negatives (from x = +b/2).
const std::vector<double>& both_faces() {
  static const std::vector<double> grid = [] {
    std::vector<double> v = numeric::default_dividing_line_grid();
    const std::size_t n = v.size();
    for (std::size_t i = 0; i < n; ++i) v.push_back(-v[i]);
    return v;
  }();
  return grid;
}

/// The limit cycle (the CLI's `limit-cycle --json`) and one period of its orbit from its
/// separation point (as the report draws it); the dividing lines of both faces (`trace --json`
/// at both_faces()).
std::string portrait() {
  return guarded([&] {
    const auto t0 = std::chrono::steady_clock::now();
    const api::Model& m = model();
    const api::Cycle cycle = m.limit_cycle();
    json head{{"ok", true}, {"orbit", 0}};
    if (cycle.found() && std::isfinite(cycle.cycle.period) && cycle.cycle.period > 0) {
      const double v = cycle.cycle.separation_velocity;
      const numeric::Parameters& p = m.evaluator().parameters();
      const api::Simulation orbit =
          m.simulate_from({-1, p.theta_R + m.evaluator().cot_phi() * v, v}, cycle.cycle.period, cycle.cycle.period / 800);
      keep_samples("orbit", orbit.result.samples);
      head["orbit"] = orbit.result.samples.size();
    }
    head["cycle_ms"] = milliseconds_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    const std::string trace = m.trace(both_faces()).json();
    head["trace_ms"] = milliseconds_since(t1);
    head["ms"] = milliseconds_since(t0);
    std::string out = head.dump();
    out.pop_back();  // the CLI's documents follow as text
    return out + ",\"cycle\":" + cycle.json() + ",\"trace\":" + trace + "}";
  });
}

/// The run from (θo, θ̇o) — contact on the face driving toward θR, or (flight) free flight
/// leaving the face contact would leave: `simulate --from θo,θ̇o [--flight] --t-end T`.
std::string trajectory(double theta_o, double dtheta_o, bool flight, double t_end, double sample_interval) {
  return guarded([&] {
    const api::Model& m = model();
    const auto t0 = std::chrono::steady_clock::now();
    const api::StartState start = api::start_state(m.evaluator().parameters(), {theta_o, dtheta_o}, !flight);
    const api::Simulation run = m.simulate_from_state(start, {.t_end = t_end, .sample_interval = sample_interval});
    return run_json(run, milliseconds_since(t0));
  });
}

/// The step response of the case's experiment (`simulate CASE --json`), sampled.
std::string step_response(double sample_interval) {
  return guarded([&] {
    const api::Model& m = model();
    const auto t0 = std::chrono::steady_clock::now();
    const api::Simulation run = m.simulate({.sample_interval = sample_interval});
    return run_json(run, milliseconds_since(t0));
  });
}

/// The CSV of the run from (θo, θ̇o) as trajectory() computes it: `simulate --from θo,θ̇o
/// [--flight] --t-end T --dt S --csv`, byte for byte (Simulation::csv, docs/design.md).
std::string trajectory_csv(double theta_o, double dtheta_o, bool flight, double t_end, double sample_interval) {
  return guarded([&] {
    const api::Model& m = model();
    const api::StartState start = api::start_state(m.evaluator().parameters(), {theta_o, dtheta_o}, !flight);
    return m.simulate_from_state(start, {.t_end = t_end, .sample_interval = sample_interval}).csv();
  });
}

/// The CSV of the step response: `simulate CASE --dt S --csv`, byte for byte.
std::string step_csv(double sample_interval) {
  return guarded([&] { return model().simulate({.sample_interval = sample_interval}).csv(); });
}

/// The columns kept by the last run (NAME "run") or limit cycle ("orbit"): a Float64Array
/// view of the module's memory (valid until the next call into the module; the page copies it).
emscripten::val samples(const std::string& name) {
  const std::vector<double>& b = sample_buffer(name);
  return emscripten::val(emscripten::typed_memory_view(b.size(), b.data()));
}

/// The limit cycle's peak-to-peak at `points` values of one parameter (its name in the
/// fields) from `from` to `to`, the others as loaded: a live slice of the design map.
std::string slice(const std::string& name, double from, double to, int points) {
  return guarded([&] {
    const auto t0 = std::chrono::steady_clock::now();
    json rows = json::array();
    for (int i = 0; i < points && i < 200; ++i) {
      const double x = points > 1 ? from + (to - from) * i / (points - 1) : from;
      auto texts = current().texts;
      for (auto& [key, value] : texts)
        if (key == name) value = json(x).dump();
      json row{{"x", x}};
      try {
        const api::Cycle c = api::Model(api::Case::from_texts(texts)).limit_cycle();
        row["status"] = c.status();
        if (c.found()) row["peak_to_peak"] = c.cycle.peak_to_peak;
      } catch (const std::exception& e) {
        row["status"] = "refused";
        row["reason"] = e.what();
      }
      rows.push_back(row);
    }
    return json{{"ok", true}, {"rows", rows}, {"ms", milliseconds_since(t0)}}.dump();
  });
}

/// The effect parameters of the table of effects (model/effect_table.hpp) for the page's fields.
std::string effect_table() {
  json out = json::array();
  for (const model::EffectParameterInfo& p : model::effect_parameters)
    out.push_back({{"name", std::string(p.name)}, {"effect", std::string(p.effect)},
                   {"description", std::string(p.description)}, {"unit", std::string(p.unit)}});
  return out.dump();
}

}  // namespace backlash::explorer

EMSCRIPTEN_BINDINGS(backlash_explorer) {
  using namespace backlash::explorer;
  emscripten::function("fields_of_case", &fields_of_case);
  emscripten::function("load_case", &load_case);
  emscripten::function("portrait", &portrait);
  emscripten::function("trajectory", &trajectory);
  emscripten::function("step_response", &step_response);
  emscripten::function("trajectory_csv", &trajectory_csv);
  emscripten::function("step_csv", &step_csv);
  emscripten::function("samples", &samples);
  emscripten::function("slice", &slice);
  emscripten::function("effect_table", &effect_table);
}
