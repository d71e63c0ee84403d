// time_ benchmarks of limit cycles and sweeps (issue targets: one limit cycle
// ≤ 50 µs; 1e5 sweep points ≤ 5 s on 2 cores).  "Cold" searches the whole
// range of separation velocities; "warm" starts from a neighbouring cycle, as
// every point but the first of a sweep does (continuation).
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace backlash;

const numeric::ValidationResult& case_V() {
  static const numeric::ValidationResult r = numeric::validate(numeric::case_evaluator(model::load_case("V")));
  return r;
}

void time_LimitCycleCold(benchmark::State& state) {
  const auto& e = case_V().evaluator();
  for (auto _ : state) benchmark::DoNotOptimize(numeric::find_limit_cycle(e));
}
BENCHMARK(time_LimitCycleCold)->Unit(benchmark::kMicrosecond);

void time_LimitCycleWarm(benchmark::State& state) {
  const auto& e = case_V().evaluator();
  numeric::LimitCycleOptions options;
  options.guess = 0.19;  // the neighbour's cycle in a sweep (v* = 0.19220…)
  for (auto _ : state) benchmark::DoNotOptimize(numeric::find_limit_cycle(e, options));
}
BENCHMARK(time_LimitCycleWarm)->Unit(benchmark::kMicrosecond);

void time_HalfCycle(benchmark::State& state) {
  const auto& e = case_V().evaluator();
  for (auto _ : state) benchmark::DoNotOptimize(numeric::half_cycle(e, 0.19));
}
BENCHMARK(time_HalfCycle)->Unit(benchmark::kMicrosecond);

// Figure 32 with 33,334 points per series (100,002 points) on 2 threads.
void time_Sweep100kPointsTwoThreads(benchmark::State& state) {
  const auto points = numeric::figure32_points(33334);
  numeric::SweepOptions options;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(numeric::run_sweep(points, options));
  state.counters["points"] = static_cast<double>(points.size());
}
BENCHMARK(time_Sweep100kPointsTwoThreads)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
