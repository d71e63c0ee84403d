// time_ benchmarks of limit cycles and sweeps (issue 19's targets: case V cold ≤ 1.5 × warm,
// warm ≤ 25 µs; issue 13's: 1e5 sweep points ≤ 5 s on 2 cores).  "Cold" starts Newton's method
// from the describing function's guess; "warm" from a neighbouring cycle, as every point but the
// first of a sweep's block does (continuation); "survey" is the grid survey the cold search falls
// back to (and the cold search before issue 19).  The end of the run prints the ratios, measured
// in this one run, and met/missed per target.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

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

void time_LimitCycleSurvey(benchmark::State& state) {
  const auto& e = case_V().evaluator();
  numeric::LimitCycleOptions options;
  options.survey_only = true;
  for (auto _ : state) benchmark::DoNotOptimize(numeric::find_limit_cycle(e, options));
}
BENCHMARK(time_LimitCycleSurvey)->Unit(benchmark::kMicrosecond);

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

// The console's lines, and the CPU time per iteration [µs] of each benchmark kept for the ratios.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> cpu_us;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration && r.iterations > 0)
        cpu_us[r.benchmark_name()] = r.GetAdjustedCPUTime() * 1e6 / benchmark::GetTimeUnitMultiplier(r.time_unit);
    ConsoleReporter::ReportRuns(runs);
  }
};

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto& t = reporter.cpu_us;
  const auto cold = t.find("time_LimitCycleCold"), warm = t.find("time_LimitCycleWarm");
  if (cold == t.end() || warm == t.end()) return 0;
  const double ratio = cold->second / warm->second;
  std::printf("case V, CPU time: cold %.1f us, warm %.1f us, cold/warm %.2f (target <= 1.5: %s), warm (target <= 25 us: %s)\n",
              cold->second, warm->second, ratio, ratio <= 1.5 ? "met" : "missed", warm->second <= 25 ? "met" : "missed");
  if (const auto survey = t.find("time_LimitCycleSurvey"); survey != t.end())
    std::printf("the grid survey the cold search falls back to: %.1f us (%.1f x cold)\n", survey->second,
                survey->second / cold->second);
  return 0;
}
