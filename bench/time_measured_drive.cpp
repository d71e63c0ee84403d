// time_ benchmarks of the measured-drive simulator (discrepancy/measured_drive_simulation.hpp; not timed tests):
//   time_MeasuredDrive/<τ in µs>   one run over an EMPS-sized record: 24 841 samples at 1 kHz
//                                  (t = 0 … 24.84 s), a synthetic controller output of EMPS's
//                                  range (±4.3 V, gain 35.15 N/V) and the published EMPS rigid
//                                  model (M = 95.11 kg, Fv = 203.5 N·s/m, Fc = 20.39 N,
//                                  offset −3.16 N).  τ = 0 gives one hold piece per sample,
//                                  τ = 500 µs two (the shifted samples fall between outputs).
// The counter "per_piece" is the CPU time per hold piece.
#include "backlash/discrepancy/measured_drive_simulation.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace {

using namespace backlash;

constexpr std::size_t samples = 24841;

struct Record {
  std::vector<double> t, drive;
};

// A trapezoid-like back-and-forth trajectory's control effort: slow swings, faster
// corrections and a deterministic ripple — sign changes and sticking as in the real record.
const Record& record() {
  static const Record r = [] {
    Record out;
    out.t.resize(samples);
    out.drive.resize(samples);
    for (std::size_t k = 0; k < samples; ++k) {
      const double t = 1e-3 * static_cast<double>(k);
      out.t[k] = t;
      out.drive[k] = 2.5 * std::sin(2 * M_PI * t / 6.2) + 1.2 * std::sin(2 * M_PI * t / 0.9) +
                     0.4 * std::sin(2 * M_PI * t / 0.037) + 0.2 * std::sin(1e3 * t * t);
    }
    return out;
  }();
  return r;
}

void time_MeasuredDrive(benchmark::State& state) {
  const Record& r = record();
  discrepancy::RigidDrive m;
  m.J = 95.1089;
  m.F = 203.5034;
  m.coulomb = 20.3935;
  m.offset = -3.1648;
  m.gain = 35.150651882485469;
  m.delay = 1e-6 * static_cast<double>(state.range(0));
  std::size_t events = 0;
  for (auto _ : state) {
    const discrepancy::MeasuredDriveRun run = discrepancy::simulate_measured_drive(m, r.t, r.drive, 0, samples - 1, 0.0, 0.0);
    events = run.event_count;
    benchmark::DoNotOptimize(run.x.data());
  }
  const double pieces = static_cast<double>(samples - 1) * (state.range(0) % 1000 == 0 ? 1 : 2);
  state.counters["events"] = static_cast<double>(events);
  state.counters["per_piece"] = benchmark::Counter(pieces * static_cast<double>(state.iterations()),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(time_MeasuredDrive)->Arg(0)->Arg(500)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
