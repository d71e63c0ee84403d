// backlash._core — the facade (backlash/api/backlash.hpp) for Python (docs/design.md,
// "Library and package").  The user-facing names and their documentation are in
// python/backlash/__init__.py; this file only binds.  str() of a result is the CLI's
// text output, repr() a one-line summary.  Every numeric call runs with the GIL released
// (sweeps and the discrepancy workflow use their own threads); errors become exceptions
// carrying the facade's one-line message:
//   BadInput, CaseFileError, MeasuredDataError   (subclasses of ValueError)
//   ValidationFailed                              (a subclass of RuntimeError)
#include "backlash/api/backlash.hpp"
#include "backlash/api/discrepancy_pages.hpp"
#include "backlash/api/map.hpp"
#include "backlash/model/data_dir.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdio>
#include <memory>
#include <mutex>

namespace py = pybind11;
using namespace backlash;

namespace {

using Release = py::call_guard<py::gil_scoped_release>;

py::array_t<double> array(const std::vector<double>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

template <class Item, class Field>
py::array_t<double> column(const std::vector<Item>& items, Field field) {
  py::array_t<double> out(static_cast<py::ssize_t>(items.size()));
  double* data = out.mutable_data();
  for (std::size_t i = 0; i < items.size(); ++i) data[i] = field(items[i]);
  return out;
}

/// str(result): what the CLI prints (its text output) without the final newline.
std::string printed(std::string text) {
  if (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

std::string shortest(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

py::object optional_array(const std::optional<std::vector<double>>& values) {
  return values ? py::object(array(*values)) : py::object(py::none());
}

/// A case and, once asked for, its validated model (the gates run once per case).
class PyCase {
 public:
  explicit PyCase(api::Case c) : case_(std::move(c)), slot_(std::make_shared<Slot>()) {}
  const api::Case& get() const { return case_; }
  /// Runs the gates on first use (the GIL is released by the caller).
  const api::Model& model() const {
    const std::lock_guard<std::mutex> lock(slot_->mutex);
    if (!slot_->model) slot_->model.emplace(case_);
    return *slot_->model;
  }

 private:
  struct Slot {
    std::mutex mutex;
    std::optional<api::Model> model;
  };
  api::Case case_;
  std::shared_ptr<Slot> slot_;
};

py::dict parameters_dict(const model::CaseSpec& s) {
  py::dict d;
  d["Jm"] = model::to_string(s.Jm);
  d["Fm"] = model::to_string(s.Fm);
  d["JL"] = model::to_string(s.JL);
  d["FL"] = model::to_string(s.FL);
  d["K"] = model::to_string(s.K);
  d["backlash"] = model::to_string(s.backlash);
  d["reference"] = model::to_string(s.reference);
  d["measured_at"] = model::to_string(s.measured_at);
  if (s.experiment) {
    if (s.experiment->kind == model::ExperimentKind::Step)
      d["step"] = model::to_string(s.experiment->step);
    else
      d["drive_gain"] = model::to_string(s.experiment->drive_gain);
    if (s.experiment->t_end) d["t_end"] = model::to_string(*s.experiment->t_end);
  }
  for (const model::EffectInfo& effect : model::effects_table) {  // every parameter of the effects present
    if (!s.effects.has(effect)) continue;
    for (std::size_t i = effect.first; i < effect.first + effect.count; ++i)
      if (const auto& v = model::field(s.effects, model::effect_parameters[i].id))
        d[py::str(std::string(model::effect_parameters[i].name))] = model::to_string(*v);
  }
  return d;
}

py::list events_list(const std::vector<numeric::SimulationEvent>& events) {
  py::list out;
  for (const numeric::SimulationEvent& e : events) {
    py::dict event;
    event["t"] = e.t;
    event["kind"] = numeric::to_string(e.kind);
    event["theta_o"] = e.theta_o;
    event["dtheta_o"] = e.dtheta_o;
    event["theta_m"] = e.after.theta_m;
    event["theta_L"] = e.after.theta_L;
    event["bounce"] = e.bounce;
    if (e.body != numeric::Body::None) event["body"] = numeric::to_string(e.body);
    if (e.accumulation) event["accumulation"] = true;
    out.append(event);
  }
  return out;
}

/// Case.simulate: the step response sampled every `dt` [s] (None: events only, as the CLI's
/// `simulate` without --csv), through the facade's checks of the CLI's --dt
/// (api::check_sample_interval, the sample count in Model::simulate), named "dt" here.
api::Simulation simulate_sampled(const PyCase& c, api::SimulationRequest request, std::optional<double> dt) {
  try {
    if (dt) api::check_sample_interval(*dt);
    request.sample_interval = dt.value_or(0);
    return c.model().simulate(request);
  } catch (const api::BadInput& bad) {
    if (bad.argument() != "sample_interval") throw;
    throw api::BadInput("dt", bad.problem());
  }
}

/// Case.simulate_from: the run from a state (api::start_state: θm, θ̇m, θL, θ̇L or θo, θ̇o), as
/// `simulate --from`, sampled every `dt` [s] (None: events only).
api::Simulation simulate_from_sampled(const PyCase& c, const std::vector<double>& from, bool in_contact,
                                      std::optional<double> gap, std::optional<double> other_velocity,
                                      std::optional<double> t_end, std::optional<double> dt) {
  const api::Model& model = c.model();
  const api::StartState start = api::start_state(model.evaluator().parameters(), from, in_contact, gap, other_velocity);
  try {
    if (dt) api::check_sample_interval(*dt);
    return model.simulate_from_state(start, {.t_end = t_end, .sample_interval = dt.value_or(0)});
  } catch (const api::BadInput& bad) {
    if (bad.argument() != "sample_interval") throw;
    throw api::BadInput("dt", bad.problem());
  }
}

py::dict candidate_dict(const discrepancy::Candidate& c) {
  py::dict parameters, uncertainty;
  for (const discrepancy::Parameter& p : c.parameters) {
    parameters[py::str(p.name)] = p.value;
    uncertainty[py::str(p.name)] = p.uncertainty;
  }
  py::dict d;
  d["effect"] = c.effect;
  d["parameters"] = parameters;
  d["uncertainty"] = uncertainty;
  d["rms"] = c.rms;
  d["delta_bic"] = c.delta_bic;
  d["decisive"] = c.decisive;
  return d;
}

// ---------------------------------------------------------------------- the bindings, by result

// cases
void bind_cases(py::module_& m) {
  py::class_<PyCase>(m, "Case")
      .def_property_readonly("id", [](const PyCase& c) { return c.get().id(); })
      .def_property_readonly("name", [](const PyCase& c) { return c.get().spec().name; })
      .def_property_readonly("source", [](const PyCase& c) { return c.get().spec().source.string(); })
      .def_property_readonly("measured_at", [](const PyCase& c) { return std::string(model::to_string(c.get().spec().measured_at)); })
      .def_property_readonly("parameters", [](const PyCase& c) { return parameters_dict(c.get().spec()); })
      .def_property_readonly("has_effects", [](const PyCase& c) { return c.get().spec().effects.any(); })
      .def_property_readonly("effects", [](const PyCase& c) { return c.get().effects().describe(); })
      .def_property_readonly("measured_drive", [](const PyCase& c) {
        const auto& x = c.get().spec().experiment;
        return x && x->kind == model::ExperimentKind::Drive;
      })
      .def("case_file", [](const PyCase& c) { return c.get().case_file(); })
      .def("validated", [](const PyCase& c) { (void)c.model(); }, Release())
      .def(
          "simulate",
          [](const PyCase& c, std::optional<double> step, std::optional<double> t_end, std::optional<double> dt) {
            return simulate_sampled(c, {.step = step, .t_end = t_end}, dt);
          },
          py::arg("step") = py::none(), py::arg("t_end") = py::none(), py::arg("dt") = 0.01, Release())
      .def(
          "simulate_from",
          [](const PyCase& c, const std::vector<double>& from, bool flight, std::optional<double> gap,
             std::optional<double> other_velocity, std::optional<double> t_end, std::optional<double> dt) {
            return simulate_from_sampled(c, from, !flight, gap, other_velocity, t_end, dt);
          },
          py::arg("from_"), py::arg("flight") = false, py::arg("gap") = py::none(), py::arg("other_velocity") = py::none(),
          py::arg("t_end") = py::none(), py::arg("dt") = 0.01, Release())
      .def(
          "trace",
          [](const PyCase& c, std::optional<std::vector<double>> v0) {
            return v0 ? c.model().trace(*v0) : c.model().trace();
          },
          py::arg("v0") = py::none(), Release())
      .def("limit_cycle", [](const PyCase& c) { return c.model().limit_cycle(); }, Release())
      .def(
          "validate", [](const PyCase& c, double tolerance) { return api::validate(c.get(), false, tolerance); },
          py::arg("tolerance") = 1e-9, Release())
      .def("__repr__", [](const PyCase& c) { return "<backlash.Case " + c.get().id() + ": " + c.get().spec().name + ">"; });

  m.def("load_case", [](const std::string& name) { return PyCase(api::Case::load(name)); }, py::arg("case"), Release());
  m.def(
      "load_parameters",
      [](const std::vector<std::pair<std::string, std::string>>& texts) { return PyCase(api::Case::from_texts(texts)); },
      py::arg("parameters"));
  m.def(
      "load_text", [](const std::string& text, const std::string& name) { return PyCase(api::Case::from_text(text, name)); },
      py::arg("text"), py::arg("name"));
}

// simulate
void bind_simulation(py::module_& m) {
  py::class_<api::Simulation>(m, "Simulation")
      .def_readonly("case", &api::Simulation::case_id)
      .def_readonly("step", &api::Simulation::step)
      .def_readonly("t_end", &api::Simulation::t_end)
      .def_property_readonly("status", [](const api::Simulation& s) { return std::string(numeric::to_string(s.result.status)); })
      .def_property_readonly("stopped_early", &api::Simulation::stopped_early)
      .def_property_readonly("stop_reason", [](const api::Simulation& s) { return s.result.stop_reason; })
      .def_property_readonly("events", [](const api::Simulation& s) { return events_list(s.result.events); })
      .def_property_readonly("final", [](const api::Simulation& s) {
        const numeric::HybridState& f = s.result.final_state;
        py::dict d;
        d["t"] = s.result.t_final;
        d["theta_o"] = s.result.theta_o_final;
        d["error"] = s.final_error();
        d["theta_m"] = f.theta_m;
        d["theta_L"] = f.theta_L;
        d["dtheta_m"] = f.dtheta_m;
        d["dtheta_L"] = f.dtheta_L;
        d["in_contact"] = f.in_contact;
        d["motor_stuck"] = f.motor_stuck;
        d["load_stuck"] = f.load_stuck;
        return d;
      })
      .def_property_readonly("t", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.t; }); })
      .def_property_readonly("theta_o", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.theta_o; }); })
      .def_property_readonly("dtheta_o", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.dtheta_o; }); })
      .def_property_readonly("theta_m", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.theta_m; }); })
      .def_property_readonly("dtheta_m", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.dtheta_m; }); })
      .def_property_readonly("theta_L", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.theta_L; }); })
      .def_property_readonly("dtheta_L", [](const api::Simulation& s) { return column(s.result.samples, [](auto& x) { return x.dtheta_L; }); })
      .def_property_readonly("in_contact", [](const api::Simulation& s) {
        py::array_t<bool> out(static_cast<py::ssize_t>(s.result.samples.size()));
        for (std::size_t i = 0; i < s.result.samples.size(); ++i) out.mutable_data()[i] = s.result.samples[i].in_contact;
        return out;
      })
      .def("json", &api::Simulation::json)
      .def("csv", &api::Simulation::csv)
      .def("text", &api::Simulation::text)
      .def("__str__", [](const api::Simulation& s) { return printed(s.text()); })
      .def("__repr__", [](const api::Simulation& s) {
        return "<backlash.Simulation " + s.case_id + ": step " + shortest(s.step) + " over " + shortest(s.t_end) + " s, " +
               numeric::to_string(s.result.status) + ", " + std::to_string(s.result.events.size()) + " events, " +
               std::to_string(s.result.samples.size()) + " samples>";
      });
}

// trace
void bind_trace(py::module_& m) {
  using Point = numeric::DividingLinePoint;
  auto when_recombined = [](double Point::*field) {
    return [field](const api::Trace& r) {
      return column(r.lines.points, [field](const Point& p) {
        return numeric::has_impact(p.status) ? p.*field : NAN;
      });
    };
  };
  py::class_<api::Trace>(m, "Trace")
      .def_readonly("case", &api::Trace::case_id)
      .def_readonly("evaluator", &api::Trace::evaluator)
      .def_property_readonly("cot_phi", [](const api::Trace& r) { return r.lines.cot_phi; })
      .def_property_readonly("threshold", [](const api::Trace& r) { return r.lines.threshold; })
      .def_property_readonly("horizon", [](const api::Trace& r) { return r.lines.horizon; })
      .def_property_readonly("v0", [](const api::Trace& r) { return column(r.lines.points, [](const Point& p) { return p.dtheta_m0; }); })
      .def_property_readonly("status", [](const api::Trace& r) {
        std::vector<std::string> out;
        for (const Point& p : r.lines.points) out.emplace_back(numeric::to_string(p.status));
        return out;
      })
      .def_property_readonly("t", when_recombined(&Point::t))
      .def_property_readonly("theta_m", when_recombined(&Point::theta_m))
      .def_property_readonly("dtheta_m", when_recombined(&Point::dtheta_m))
      .def_property_readonly("theta_L", when_recombined(&Point::theta_L))
      .def_property_readonly("dtheta_L", when_recombined(&Point::dtheta_L))
      .def_property_readonly("theta_o", when_recombined(&Point::theta_o))
      .def_property_readonly("dtheta_o", when_recombined(&Point::dtheta_o))
      .def("json", &api::Trace::json)
      .def("csv", &api::Trace::csv)
      .def("text", &api::Trace::text)
      .def("__str__", [](const api::Trace& r) { return printed(r.text()); })
      .def("__repr__", [](const api::Trace& r) {
        return "<backlash.Trace " + r.case_id + ": " + std::to_string(r.lines.points.size()) + " points, cot_phi " +
               shortest(r.lines.cot_phi) + ">";
      });
}

// limit cycle
void bind_cycle(py::module_& m) {
  auto cycle_value = [](double numeric::LimitCycle::*field) {
    return [field](const api::Cycle& c) { return c.found() ? c.cycle.*field : NAN; };
  };
  py::class_<api::Cycle>(m, "Cycle")
      .def_readonly("case", &api::Cycle::case_id)
      .def_property_readonly("status", &api::Cycle::status)
      .def_property_readonly("found", &api::Cycle::found)
      .def_property_readonly("reason", [](const api::Cycle& c) { return c.cycle.reason; })
      .def_property_readonly("amplitude", cycle_value(&numeric::LimitCycle::amplitude))
      .def_property_readonly("peak_to_peak", cycle_value(&numeric::LimitCycle::peak_to_peak))
      .def_property_readonly("peak_to_peak_motor", cycle_value(&numeric::LimitCycle::peak_to_peak_motor))
      .def_property_readonly("peak_to_peak_load", cycle_value(&numeric::LimitCycle::peak_to_peak_load))
      .def_property_readonly("period", cycle_value(&numeric::LimitCycle::period))
      // k of a period-k cycle (crossings of the return map's section per period); 0 without a cycle.
      .def_property_readonly("period_count", [](const api::Cycle& c) { return c.found() ? c.cycle.period_count : 0; })
      .def_property_readonly("separation_velocity", cycle_value(&numeric::LimitCycle::separation_velocity))
      .def_property_readonly("multiplier", cycle_value(&numeric::LimitCycle::multiplier))
      .def_property_readonly("half_map_derivative", cycle_value(&numeric::LimitCycle::half_map_derivative))
      .def_property_readonly("C_separation", cycle_value(&numeric::LimitCycle::C_separation))
      .def_property_readonly("C_recombination", cycle_value(&numeric::LimitCycle::C_recombination))
      .def_property_readonly("stable", [](const api::Cycle& c) { return c.found() && c.cycle.stable; })
      .def_property_readonly("method", [](const api::Cycle& c) { return c.cycle.method; })
      .def_property_readonly("other_fixed_points", [](const api::Cycle& c) { return c.cycle.other_fixed_points; })
      .def("json", &api::Cycle::json)
      .def("text", &api::Cycle::text)
      .def("__str__", [](const api::Cycle& c) { return printed(c.text()); })
      .def("__repr__", [](const api::Cycle& c) {
        if (!c.found()) return "<backlash.Cycle " + c.case_id + ": " + c.status() + " (" + c.cycle.reason + ")>";
        return "<backlash.Cycle " + c.case_id + ": limit_cycle, peak_to_peak " + shortest(c.cycle.peak_to_peak) +
               " rad, period " + shortest(c.cycle.period) + " s>";
      });
}

// sweep
void bind_sweep(py::module_& m) {
  using Row = numeric::SweepRow;
  auto sweep_value = [](double numeric::LimitCycle::*field) {
    return [field](const api::Sweep& s) {
      return column(s.rows, [field](const Row& r) { return r.status == numeric::SweepStatus::LimitCycle ? r.cycle.*field : NAN; });
    };
  };
  py::class_<api::Sweep>(m, "Sweep")
      .def_property_readonly("x", [](const api::Sweep& s) { return column(s.rows, [](const Row& r) { return r.point.x; }); })
      .def_property_readonly("series", [](const api::Sweep& s) {
        std::vector<std::string> out;
        for (const Row& r : s.rows) out.push_back(r.point.series);
        return out;
      })
      .def_property_readonly("status", [](const api::Sweep& s) {
        std::vector<std::string> out;
        for (const Row& r : s.rows) out.push_back(api::status_of(r));
        return out;
      })
      .def_property_readonly("branches", [](const api::Sweep& s) {
        std::vector<std::string> out;
        for (const Row& r : s.rows) out.push_back(r.branches);
        return out;
      })
      .def_property_readonly("peak_to_peak", sweep_value(&numeric::LimitCycle::peak_to_peak))
      .def_property_readonly("amplitude", sweep_value(&numeric::LimitCycle::amplitude))
      .def_property_readonly("period", sweep_value(&numeric::LimitCycle::period))
      .def_property_readonly("separation_velocity", sweep_value(&numeric::LimitCycle::separation_velocity))
      .def_property_readonly("multiplier", sweep_value(&numeric::LimitCycle::multiplier))
      .def("__len__", [](const api::Sweep& s) { return s.rows.size(); })
      .def("csv", &api::Sweep::csv)
      .def("summary_line", &api::Sweep::summary_line)
      .def("__repr__", [](const api::Sweep& s) {
        return "<backlash.Sweep " + std::to_string(s.rows.size()) + " points on " + std::to_string(s.threads) + " threads>";
      });
  m.def(
      "sweep",
      [](const std::string& target, const std::string& vary, double from, double to, int points, int threads) {
        api::SweepRequest request;
        request.target = target;
        request.vary = vary;
        request.from = from;
        request.to = to;
        request.points = points;
        request.threads = threads;
        return api::sweep(request);
      },
      py::arg("target"), py::arg("vary"), py::arg("start"), py::arg("stop"), py::arg("points"), py::arg("threads"),
      Release());
}

// design-space maps (backlash/api/map.hpp)
void bind_map(py::module_& m) {
  auto request_of = [](const std::string& target, const std::vector<std::string>& vary, const std::string& sample,
                       long points, int threads, std::optional<double> step) {
    api::MapRequest r;
    r.target = target;
    for (const std::string& v : vary) r.vary.push_back(api::parse_vary(v));
    r.sample = sample;
    r.points = points;
    r.threads = threads;
    r.step = step;
    return r;
  };
  m.def(
      "map_rows",
      [request_of](const std::string& target, const std::vector<std::string>& vary, const std::string& sample,
                   long points, int threads, std::optional<double> step) {
        const api::MapRequest r = request_of(target, vary, sample, points, threads, step);
        std::vector<double> x, peak_to_peak, period, multiplier, settle;
        std::vector<std::string> status;
        {
          py::gil_scoped_release release;
          api::run_map(r, [&](const api::MapRow& row) {
            x.insert(x.end(), row.x.begin(), row.x.end());
            status.push_back(api::status_of(row.row));
            const bool cycle = status.back() == "limit_cycle";
            peak_to_peak.push_back(cycle ? row.row.cycle.peak_to_peak : NAN);
            period.push_back(cycle ? row.row.cycle.period : NAN);
            multiplier.push_back(cycle ? row.row.cycle.multiplier : NAN);
            settle.push_back(row.row.settle.time);
          });
        }
        py::array_t<double> xs = array(x);
        xs.resize({static_cast<py::ssize_t>(status.size()), static_cast<py::ssize_t>(r.vary.size())});
        py::dict out;
        out["x"] = xs;
        out["status"] = status;
        out["peak_to_peak"] = array(peak_to_peak);
        out["period"] = array(period);
        out["multiplier"] = array(multiplier);
        out["settle_time"] = array(settle);
        return out;
      },
      py::arg("target"), py::arg("vary"), py::arg("sample"), py::arg("points"), py::arg("threads"), py::arg("step"));
  m.def(
      "map_write",
      [request_of](const std::string& target, const std::vector<std::string>& vary, const std::string& sample,
                   long points, int threads, std::optional<double> step, const std::filesystem::path& out, bool resume) {
        api::MapOutput o;
        o.out = out;
        o.resume = resume;
        const api::MapRequest r = request_of(target, vary, sample, points, threads, step);
        api::MapSummary s;
        {
          py::gil_scoped_release release;
          s = api::write_map(r, o);
        }
        py::dict d;
        d["points"] = s.points;
        d["resumed_from"] = s.resumed_from;
        d["boundary_points"] = s.boundary_points;
        d["figures_note"] = s.figures_note;
        return d;
      },
      py::arg("target"), py::arg("vary"), py::arg("sample"), py::arg("points"), py::arg("threads"), py::arg("step"),
      py::arg("out"), py::arg("resume"));
}

// records, discrepancy
void bind_records_and_discrepancy(py::module_& m) {
  py::class_<measurements::MeasuredRecord>(m, "Record")
      .def_property_readonly("t", [](const measurements::MeasuredRecord& r) { return array(r.t); })
      .def_property_readonly("theta_out", [](const measurements::MeasuredRecord& r) { return array(r.theta_out); })
      .def_property_readonly("theta_motor", [](const measurements::MeasuredRecord& r) { return optional_array(r.theta_motor); })
      .def_property_readonly("theta_load", [](const measurements::MeasuredRecord& r) { return optional_array(r.theta_load); })
      .def_property_readonly("drive", [](const measurements::MeasuredRecord& r) { return optional_array(r.drive); })
      .def_property_readonly("source", [](const measurements::MeasuredRecord& r) { return r.source.string(); })
      .def("__len__", &measurements::MeasuredRecord::size)
      .def("csv", [](const measurements::MeasuredRecord& r) { return measurements::format_measured_csv(r); });
  m.def("read_record", [](const std::filesystem::path& file) { return api::read_record(file); }, py::arg("file"), Release());
  m.def(
      "make_record",
      [](std::vector<double> t, std::vector<double> theta_out, std::optional<std::vector<double>> theta_motor,
         std::optional<std::vector<double>> theta_load, std::optional<std::vector<double>> drive, const std::string& name) {
        return api::make_record(std::move(t), std::move(theta_out), std::move(theta_motor), std::move(theta_load),
                                std::move(drive), name);
      },
      py::arg("t"), py::arg("theta_out"), py::arg("theta_motor"), py::arg("theta_load"), py::arg("drive"), py::arg("name"));

  py::class_<api::Discrepancy>(m, "Discrepancy")
      .def_property_readonly("status", [](const api::Discrepancy& d) { return std::string(discrepancy::to_string(d.status())); })
      .def_property_readonly("measured_drive", &api::Discrepancy::measured_drive)
      .def_property_readonly("effects", [](const api::Discrepancy& d) {
        py::list out;
        const auto& named = d.step_result() ? d.step_result()->effects : d.drive_result()->effects;
        for (const discrepancy::Candidate& c : named) out.append(candidate_dict(c));
        return out;
      })
      .def_property_readonly("parameter_corrections", [](const api::Discrepancy& d) {
        py::list out;  // a step record's corrected nominal parameters (docs/discrepancy.md)
        if (d.step_result())
          for (const discrepancy::ParameterCorrection& c : d.step_result()->parameter_corrections) {
            py::dict x;
            x["key"] = c.key, x["nominal"] = c.nominal, x["fitted"] = c.fitted, x["sigma"] = c.uncertainty;
            x["ratio"] = c.ratio, x["given_free"] = c.given_free;
            out.append(x);
          }
        return out;
      })
      .def_property_readonly("rms_before", [](const api::Discrepancy& d) {
        return d.step_result() ? d.step_result()->rms_before : d.drive_result()->rms_before;
      })
      .def_property_readonly("rms_after", [](const api::Discrepancy& d) {
        return d.step_result() ? d.step_result()->rms_after : d.drive_result()->rms_after;
      })
      .def_property_readonly("noise", [](const api::Discrepancy& d) {
        return d.step_result() ? d.step_result()->noise : d.drive_result()->noise;
      })
      .def("json", [](const api::Discrepancy& d) { return api::discrepancy_json(d); })
      .def("text", &api::Discrepancy::text, py::arg("data"), py::arg("validation") = "")
      .def("files", &api::discrepancy_files, py::arg("data_name"), py::arg("validation_name") = "")
      .def("corrected_case_file", [](const api::Discrepancy& d) { return api::corrected_case_file(d); });
  m.def(
      "discrepancy",
      [](const PyCase& c, const measurements::MeasuredRecord& data, std::optional<double> step, int threads,
         std::optional<double> cutoff, std::optional<double> window,
         std::optional<measurements::MeasuredRecord> validation) {
        api::DiscrepancyRequest request;
        request.step = step;
        request.threads = threads;
        request.cutoff = cutoff;
        request.window = window;
        request.validation = std::move(validation);
        return api::discrepancy(c.get(), data, request);
      },
      py::arg("model"), py::arg("data"), py::arg("step"), py::arg("threads"), py::arg("cutoff"), py::arg("window"),
      py::arg("validation"), Release());
}

// validation reports
void bind_validation(py::module_& m) {
  py::class_<api::Validation>(m, "Validation")
      .def_property_readonly("passed", &api::Validation::passed)
      .def_readonly("failures", &api::Validation::failures)
      .def("json", &api::Validation::json)
      .def("text", &api::Validation::text);
  m.def(
      "validate_branches", [](double tolerance) { return api::validate(std::nullopt, true, tolerance); },
      py::arg("tolerance") = 1e-9, Release());

  m.def("data_dir", [] { return model::data_dir().string(); });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "backlash's numeric core (the facade backlash/api/backlash.hpp); use the package `backlash`.";

  py::register_exception<api::BadInput>(m, "BadInput", PyExc_ValueError);
  py::register_exception<model::CaseFileError>(m, "CaseFileError", PyExc_ValueError);
  py::register_exception<measurements::MeasuredDataError>(m, "MeasuredDataError", PyExc_ValueError);
  py::register_exception<numeric::ValidationFailed>(m, "ValidationFailed", PyExc_RuntimeError);

  bind_cases(m);
  bind_simulation(m);
  bind_trace(m);
  bind_cycle(m);
  bind_sweep(m);
  bind_map(m);
  bind_records_and_discrepancy(m);
  bind_validation(m);
}
