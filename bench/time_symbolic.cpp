// time_ benchmarks of the symbolic engine (issue: ≤ 0.3 s for all eight cases,
// ≥ 300× faster than SymPy on the same inverse transforms; the ratio is printed
// by bench/compare_symbolic_with_sympy.sh, which runs this and the SymPy
// baseline in one go).
#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/case_derivation.hpp"
#include "backlash/symbolic/general_derivation.hpp"
#include "backlash/symbolic/inverse_laplace.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using namespace backlash;

std::vector<model::CaseSpec> thesis_cases() {
  std::vector<model::CaseSpec> specs;
  for (const std::string& id : model::thesis_case_ids()) specs.push_back(model::load_case(id));
  return specs;
}

// Derive and exactly verify every segment of the eight thesis cases.
void time_DeriveAndVerifyEightCases(benchmark::State& state) {
  const auto specs = thesis_cases();
  for (auto _ : state)
    for (const auto& spec : specs) benchmark::DoNotOptimize(symbolic::derive_case(spec));
  state.counters["cases"] = static_cast<double>(specs.size());
}
BENCHMARK(time_DeriveAndVerifyEightCases)->Unit(benchmark::kMillisecond);

// The 40 inverse transforms SymPy is timed on (per case: contact θo, free θm, θ̇m, θL, θ̇L).
void time_FortyInverseTransforms(benchmark::State& state) {
  std::vector<GiNaC::ex> transforms;
  for (const auto& spec : thesis_cases()) {
    const symbolic::CaseDerivation d = symbolic::derive_case(spec);
    for (const symbolic::Segment* s : {&d.contact.position, &d.free.motor_position, &d.free.motor_velocity,
                                       &d.free.load_position, &d.free.load_velocity})
      transforms.push_back(s->laplace);
  }
  for (auto _ : state) {
    for (const GiNaC::ex& F : transforms) {
      symbolic::RadicalList radicals;
      benchmark::DoNotOptimize(symbolic::inverse_laplace(F, symbolic::derivation_symbols().s, radicals));
    }
  }
  state.counters["transforms"] = static_cast<double>(transforms.size());
}
BENCHMARK(time_FortyInverseTransforms)->Unit(benchmark::kMillisecond);

// All 14 general pole-structure branches, derived and verified.
void time_DeriveAndVerifyGeneralBranches(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(symbolic::derive_general_branches());
}
BENCHMARK(time_DeriveAndVerifyGeneralBranches)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
