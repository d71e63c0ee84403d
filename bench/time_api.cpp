// time_api — the facade's calls from C++, the baseline of bench/compare_python.sh (the same
// calls from Python): case V's limit cycle on a validated model, and the whole route
// (load, validation gates, limit cycle).
#include "backlash/api/backlash.hpp"

#include <benchmark/benchmark.h>

namespace {

void LimitCycleV(benchmark::State& state) {
  const backlash::api::Model v(backlash::api::load("V"));
  for (auto _ : state) benchmark::DoNotOptimize(v.limit_cycle());
}
BENCHMARK(LimitCycleV)->Unit(benchmark::kMicrosecond);

void LoadValidateLimitCycleV(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(backlash::api::Model(backlash::api::load("V")).limit_cycle());
}
BENCHMARK(LoadValidateLimitCycleV)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
