// time_ benchmarks of the hybrid simulation (not timed tests):
//   time_ClosedFormStepResponse/<case>   a 60 s step response on the validated closed forms
//                                        (simulate_step, certified events);
//   time_OdeintStepResponse/<case>       the same on the independent Boost.Odeint simulator
//                                        (simulate_step_with_odeint) at the tolerance that
//                                        gives event times within 1e-10 of the closed form;
//   time_DividingLine1000/<case>         trace_dividing_lines with 1000 θ̇m0 values
//                                        (target ≤ 1 ms);
//   time_ClosedFormPerEvent/<case>/<T>   the same step response to T = 60 s and 60,000 s with
//                                        the events sunk (event_sink, nothing kept): the cost
//                                        per event and whether it grows with the horizon.
// Every closed-form benchmark counts the heap allocations of its timed loop (the replaced global
// allocation functions of tests/support/counting_operator_new.hpp): counters allocs_per_run and,
// per event, allocs_per_event.
// Each case's step is its [experiment] step (the thesis's first worked step input).
// Validation (the gate) happens once, outside the timed loops.
//
// `time_simulation --events [T_END]` prints, instead of timing, one JSON document with each
// case's closed-form and odeint event lists, for bench/compare_simulation.sh to check the
// event accuracy of the baselines in the same run.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/dividing_lines.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/odeint_simulation.hpp"
#include "backlash/numeric/validation.hpp"
#include "counting_operator_new.hpp"  // counts every heap allocation (one TU only)

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <new>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>


namespace {

using namespace backlash;

constexpr double t_end = 60;
// dopri5 abs = rel tolerance of the odeint baseline: the loosest power of ten whose
// event times are within 1e-10 of the closed form on all eight cases over 60 s
// (1e-12 gives up to 6e-10 in case II's long free flights; 1e-13 stays below 1e-10);
// compare_simulation.sh re-checks it in every run.
constexpr double odeint_tolerance = 1e-13;

struct Case {
  std::string id;
  double step;
  const numeric::ValidatedEvaluator* evaluator;
};

const std::vector<Case>& cases() {
  static std::vector<numeric::ValidationResult> keep = [] {
    std::vector<numeric::ValidationResult> v;
    for (const std::string& id : model::thesis_case_ids())
      v.push_back(numeric::validate(numeric::case_evaluator(model::load_case(id))));
    return v;
  }();
  static std::vector<Case> list = [] {
    std::vector<Case> l;
    const auto& ids = model::thesis_case_ids();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const model::CaseSpec spec = model::load_case(ids[i]);
      const double step = spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0;
      l.push_back({ids[i], step, &keep[i].evaluator()});
    }
    return l;
  }();
  return list;
}

numeric::SimulationOptions simulation_options(double end = t_end) {
  numeric::SimulationOptions o;
  o.t_end = end;
  return o;
}

numeric::OdeintSimulationOptions odeint_options() {
  numeric::OdeintSimulationOptions o;
  o.tolerance = odeint_tolerance;
  return o;
}

void time_ClosedFormStepResponse(benchmark::State& state, std::size_t index) {
  const Case& c = cases()[index];
  const auto options = simulation_options();
  std::size_t events = 0;
  const long allocations0 = backlash::testing::heap_allocations.load();
  for (auto _ : state) {
    const numeric::SimulationResult r = numeric::simulate_step(*c.evaluator, c.step, options);
    events = r.events.size();
    benchmark::DoNotOptimize(r.theta_o_final);
  }
  const double per_run = static_cast<double>(backlash::testing::heap_allocations.load() - allocations0) / static_cast<double>(state.iterations());
  state.counters["events"] = static_cast<double>(events);
  state.counters["allocs_per_run"] = per_run;  // the kept event list's growth included
}

// The step response to `end` with the events sunk: the event loop alone.
void time_ClosedFormPerEvent(benchmark::State& state, std::size_t index, double end) {
  const Case& c = cases()[index];
  auto options = simulation_options(end);
  long events = 0;
  options.event_sink = [&events](const numeric::SimulationEvent&) { ++events; };
  long run_events = 0;
  const long allocations0 = backlash::testing::heap_allocations.load();
  for (auto _ : state) {
    events = 0;
    const numeric::SimulationResult r = numeric::simulate_step(*c.evaluator, c.step, options);
    run_events = events;
    benchmark::DoNotOptimize(r.theta_o_final);
  }
  const double per_run = static_cast<double>(backlash::testing::heap_allocations.load() - allocations0) / static_cast<double>(state.iterations());
  state.counters["events"] = static_cast<double>(run_events);
  state.counters["allocs_per_run"] = per_run;
  state.counters["allocs_per_event"] = per_run / static_cast<double>(std::max(1L, run_events));
}

void time_OdeintStepResponse(benchmark::State& state, std::size_t index) {
  const Case& c = cases()[index];
  const auto options = simulation_options();
  const auto oo = odeint_options();
  std::size_t events = 0;
  for (auto _ : state) {
    const numeric::SimulationResult r =
        numeric::simulate_step_with_odeint(c.evaluator->parameters(), c.step, options, oo);
    events = r.events.size();
    benchmark::DoNotOptimize(r.theta_o_final);
  }
  state.counters["events"] = static_cast<double>(events);
}

void time_DividingLine1000(benchmark::State& state, std::size_t index) {
  const Case& c = cases()[index];
  std::vector<double> v0(1000);
  for (std::size_t i = 0; i < v0.size(); ++i) v0[i] = 0.02 + (1.0 - 0.02) * static_cast<double>(i) / 999.0;  // the thesis's range
  std::size_t recombined = 0;
  for (auto _ : state) {
    const numeric::DividingLines lines = numeric::trace_dividing_lines(*c.evaluator, v0);
    recombined = 0;
    for (const auto& p : lines.points) recombined += p.status != numeric::RecombinationStatus::NoRecombination;
    benchmark::DoNotOptimize(lines.points.data());
  }
  state.counters["points"] = static_cast<double>(v0.size());
  state.counters["recombined"] = static_cast<double>(recombined);
}

void print_events_json(double end) {
  const auto options = simulation_options(end);
  const auto oo = odeint_options();
  std::printf("{\"t_end\": %.17g, \"odeint_tolerance\": %.17g, \"cases\": {", end, odeint_tolerance);
  bool first_case = true;
  for (const Case& c : cases()) {
    const numeric::SimulationResult closed = numeric::simulate_step(*c.evaluator, c.step, options);
    const numeric::SimulationResult odeint = numeric::simulate_step_with_odeint(c.evaluator->parameters(), c.step, options, oo);
    std::printf("%s\n  \"%s\": {\"step\": %.17g", first_case ? "" : ",", c.id.c_str(), c.step);
    first_case = false;
    for (const auto& [name, r] : {std::pair<const char*, const numeric::SimulationResult*>{"closed_form", &closed},
                                  std::pair<const char*, const numeric::SimulationResult*>{"odeint", &odeint}}) {
      std::printf(", \"%s\": {\"status\": \"%s\", \"events\": [", name, numeric::to_string(r->status));
      for (std::size_t i = 0; i < r->events.size(); ++i) {
        const auto& e = r->events[i];
        std::printf("%s{\"t\": %.17g, \"kind\": \"%s\", \"bounce\": %s, \"theta_o\": %.17g, \"dtheta_o\": %.17g}",
                    i ? ", " : "", e.t, numeric::to_string(e.kind), e.bounce ? "true" : "false", e.theta_o, e.dtheta_o);
      }
      std::printf("]}");
    }
    std::printf("}");
  }
  std::printf("\n}}\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--events") == 0) {
    print_events_json(argc > 2 ? std::atof(argv[2]) : t_end);
    return 0;
  }
  const auto& list = cases();
  for (std::size_t i = 0; i < list.size(); ++i) {
    benchmark::RegisterBenchmark(("time_ClosedFormStepResponse/" + list[i].id).c_str(), time_ClosedFormStepResponse, i)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("time_OdeintStepResponse/" + list[i].id).c_str(), time_OdeintStepResponse, i)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("time_DividingLine1000/" + list[i].id).c_str(), time_DividingLine1000, i)
        ->Unit(benchmark::kMicrosecond);
    for (const double end : {60.0, 60000.0})
      benchmark::RegisterBenchmark(("time_ClosedFormPerEvent/" + list[i].id + "/" + std::to_string(static_cast<int>(end))).c_str(),
                                   time_ClosedFormPerEvent, i, end)
          ->Unit(benchmark::kMicrosecond);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
