// time_ benchmarks of the effects (not timed tests): case V's step of 0.62 over 60 s,
//   time_NominalClosedForm              the thesis's model on the closed forms (simulate_step);
//   time_EffectsClosedForm/<effect>     with one effect, on the closed-form engine
//                                       (simulate_effects_step; the delay by the method of steps;
//                                       Stribeck friction integrated where its drop has not saturated);
//   time_EffectsOdeint/<effect>         the same on the independent Boost.Odeint simulator at the
//                                       tolerance the cross-check uses (1e-13: event times within
//                                       ~4e-10 s of the closed form).
// After the table (one run, CPU time: other work on the machine does not count): per effect its cost against the nominal model per 60 s run and per
// event (issue 19's target: within 2x per event), and odeint / closed form.
// Validation (the gate) happens once per effect, outside the timed loops.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/validation.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace backlash;

constexpr double step = 0.62, t_end = 60;

struct Effect {
  std::string name;
  numeric::Effects effects;
};

const std::vector<Effect>& effects() {
  static const std::vector<Effect> list = [] {
    std::vector<Effect> l;
    auto add = [&](const std::string& name, auto&& set) {
      numeric::Effects e;
      set(e);
      l.push_back({name, e});
    };
    add("coulomb_load=0.03", [](numeric::Effects& e) { e.coulomb_load = 0.03; });
    add("coulomb_motor=0.02", [](numeric::Effects& e) { e.coulomb_motor = 0.02; });
    add("restitution=0.4", [](numeric::Effects& e) { e.restitution = 0.4; });
    add("saturation=0.1", [](numeric::Effects& e) { e.saturation = 0.1; });
    add("compliance=400/4", [](numeric::Effects& e) { e.mesh_stiffness = 400, e.mesh_damping = 4; });
    add("delay=0.05", [](numeric::Effects& e) { e.delay = 0.05; });
    add("torque_offset=0.02", [](numeric::Effects& e) { e.torque_offset = 0.02; });
    add("stribeck+mesh=1e5", [](numeric::Effects& e) {  // check_effects_boundaries' stiff pair
      e.stribeck_motor_static = 0.186, e.stribeck_motor_velocity = 0.0031, e.mesh_stiffness = 1e5;
    });
    return l;
  }();
  return list;
}

const numeric::ValidationResult& nominal() {
  static const numeric::ValidationResult v = numeric::validate(numeric::case_evaluator(model::load_case("V")));
  return v;
}

const numeric::ValidatedEffectModel& validated(const numeric::Effects& e) {
  static std::map<std::string, std::unique_ptr<numeric::EffectValidationResult>> cache;
  std::unique_ptr<numeric::EffectValidationResult>& slot = cache[e.describe()];
  if (!slot) slot = std::make_unique<numeric::EffectValidationResult>(numeric::validate_effects(nominal().evaluator(), e));
  return slot->model();
}

numeric::SimulationOptions options() {
  numeric::SimulationOptions o;
  o.t_end = t_end;
  return o;
}

std::map<std::string, double> closed_ns, odeint_ns, closed_events;

void time_NominalClosedForm(benchmark::State& state) {
  numeric::SimulationOptions o;
  o.t_end = t_end;
  std::size_t events = 0;
  for (auto _ : state) {
    const numeric::SimulationResult r = numeric::simulate_step(nominal().evaluator(), step, o);
    events = r.events.size();
    benchmark::DoNotOptimize(r);
  }
  state.counters["events"] = static_cast<double>(events);
}
BENCHMARK(time_NominalClosedForm)->Unit(benchmark::kMicrosecond);

void time_EffectsClosedForm(benchmark::State& state) {
  const Effect& e = effects()[static_cast<std::size_t>(state.range(0))];
  state.SetLabel(e.name);
  const numeric::ValidatedEffectModel& model = validated(e.effects);
  const numeric::SimulationOptions o = options();
  std::size_t events = 0;
  for (auto _ : state) {
    const numeric::SimulationResult r = numeric::simulate_effects_step(model, step, o, {.general_engine = true});
    events = r.events.size();
    benchmark::DoNotOptimize(r);
  }
  state.counters["events"] = static_cast<double>(events);
}
BENCHMARK(time_EffectsClosedForm)->DenseRange(0, 7)->Unit(benchmark::kMicrosecond);

void time_EffectsOdeint(benchmark::State& state) {
  const Effect& e = effects()[static_cast<std::size_t>(state.range(0))];
  state.SetLabel(e.name);
  const numeric::Parameters p = numeric::parameters_of(model::load_case("V"));
  const numeric::SimulationOptions o = options();
  numeric::OdeintSimulationOptions odeint;
  odeint.tolerance = 1e-13;
  for (auto _ : state) benchmark::DoNotOptimize(numeric::simulate_effects_step_with_odeint(p, e.effects, step, o, odeint));
}
BENCHMARK(time_EffectsOdeint)->DenseRange(0, 7)->Unit(benchmark::kMicrosecond);

// Collects the per-effect times for the ratio table.
class Ratios : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      const std::string name = run.benchmark_name();
      const double ns = run.GetAdjustedCPUTime() * (run.time_unit == benchmark::kMicrosecond ? 1e3 : 1);
      const double events = run.counters.count("events") ? static_cast<double>(run.counters.at("events")) : 0.0;
      if (name.rfind("time_EffectsClosedForm", 0) == 0) closed_ns[run.report_label] = ns, closed_events[run.report_label] = events;
      if (name.rfind("time_EffectsOdeint", 0) == 0) odeint_ns[run.report_label] = ns;
      if (name.rfind("time_NominalClosedForm", 0) == 0) nominal_ns = ns, nominal_events = events;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  double nominal_ns = 0, nominal_events = 0;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  Ratios reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\ncase V, step 0.62, 60 s (one run): closed form with the effect, its cost against the nominal model, "
              "and odeint's time against it\n");
  // Per event (issue 19: the effects engine within 2x of the nominal closed form per event).
  const double nominal_per_event = reporter.nominal_events > 0 ? reporter.nominal_ns / reporter.nominal_events : 0.0;
  std::printf("nominal: %.1f us, %.0f events, %.2f us per event\n", reporter.nominal_ns / 1e3, reporter.nominal_events,
              nominal_per_event / 1e3);
  std::printf("%-20s %12s %12s %8s %12s %12s %10s\n", "effect", "closed [us]", "/ nominal", "events", "us/event",
              "/ nominal/ev", "odeint/cf");
  for (const auto& [label, ns] : closed_ns) {
    const double o = odeint_ns.count(label) ? odeint_ns[label] : 0, events = closed_events[label];
    const double per_event = events > 0 ? ns / events : 0.0;
    std::printf("%-20s %12.1f %12.2f %8.0f %12.2f %12.2f %10.1f\n", label.c_str(), ns / 1e3,
                reporter.nominal_ns > 0 ? ns / reporter.nominal_ns : 0.0, events, per_event / 1e3,
                nominal_per_event > 0 ? per_event / nominal_per_event : 0.0, o > 0 ? o / ns : 0.0);
  }
  benchmark::Shutdown();
}
