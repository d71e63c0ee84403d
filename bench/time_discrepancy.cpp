// time_ benchmarks of the discrepancy workflow (not timed tests):
//   time_StepWorkflow       examples/case_V_with_hidden_friction.csv (case V, 60 s at 100 Hz,
//                           Coulomb friction hidden): the whole workflow, 8 candidates, 2 rounds;
//   time_DriveWorkflow      the EMPS estimation record (24 841 samples at 1 kHz) with the
//                           validation record: the whole measured-drive workflow.
// Counters: simulations (least-squares solves for the drive) per run, and per candidate.
#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/discrepancy/measured_drive.hpp"
#include "backlash/measurements/emps.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"

#include <benchmark/benchmark.h>

#include <string>

namespace {

using namespace backlash;

const std::string source = BACKLASH_SOURCE_DIR;

void time_StepWorkflow(benchmark::State& state) {
  const model::CaseSpec spec = model::load_case("V");
  const measurements::MeasuredRecord data = measurements::read_measured_csv(source + "/examples/case_V_with_hidden_friction.csv");
  discrepancy::DiscrepancyResult r;
  for (auto _ : state) r = discrepancy::find_discrepancy(spec, data, 0.62, {});
  int candidates = 0;
  for (const auto& round : r.rounds) candidates += static_cast<int>(round.size());
  state.counters["simulations"] = r.simulations;
  state.counters["candidates"] = candidates;
  state.counters["sims_per_candidate"] = candidates ? static_cast<double>(r.simulations) / candidates : 0.0;
  state.SetLabel(r.effects.empty() ? "nothing named" : r.effects.front().effect);
}
BENCHMARK(time_StepWorkflow)->Unit(benchmark::kMillisecond)->Iterations(3);

void time_DriveWorkflow(benchmark::State& state) {
  const model::CaseSpec spec = model::load_case(source + "/examples/emps.toml");
  const auto estimation = measurements::to_measured_record(measurements::read_emps(source + "/tests/data/emps/DATA_EMPS.mat"));
  const auto validation =
      measurements::to_measured_record(measurements::read_emps(source + "/tests/data/emps/DATA_EMPS_PULSES.mat"));
  discrepancy::DriveDiscrepancyResult r;
  for (auto _ : state) r = discrepancy::find_drive_discrepancy(spec, estimation, {}, &validation);
  int candidates = 0;
  for (const auto& round : r.rounds) candidates += static_cast<int>(round.size());
  state.counters["least_squares"] = r.least_squares;
  state.counters["candidates"] = candidates;
  state.SetLabel(std::to_string(r.effects.size()) + " effects named");
}
BENCHMARK(time_DriveWorkflow)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
