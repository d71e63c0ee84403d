// time_evaluators — ns per call of the segment evaluators against Boost.Odeint.
//
//   generated   the per-case headers (backlash/generated/case_<ID>.hpp): each
//               state alone, and free_state/contact_state computing all at once
//   parametric  the stable layer (numeric/parametric.hpp: StableSegments), any parameters
//   direct      the generated per-branch partial fractions
//   odeint      runge_kutta_dopri5 with dense output at abs = rel = 1e-12
//               integrating the same segment from 0 to the same t
//
// Times t cycle over 64 values in (0, 10].  After the Google Benchmark table a
// summary prints ns per state and the odeint/evaluator ratio per point (one
// point = the four free-mode states θm, θ̇m, θL, θ̇L at one t).
// Targets (issue): ≤ 15 ns per state per case, ≤ 50 ns per state parametric,
// odeint ≥ 500× slower per point.
#include "backlash/generated/cases.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/direct_branches.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/reference.hpp"

#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <map>
#include <string>

namespace {

using namespace backlash;

const std::array<double, 64>& times() {
  static const std::array<double, 64> t = [] {
    std::array<double, 64> out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = 10.0 * (static_cast<double>(i) + 1) / out.size();
    return out;
  }();
  return t;
}

constexpr double v0 = 0.37, theta_o0 = 0.2, dtheta_o0 = 0.1;

template <class F>
void run(benchmark::State& state, F&& f) {
  const auto& t = times();
  std::size_t i = 0;
  double sink = 0;
  for (auto _ : state) {
    sink += f(t[i]);
    i = (i + 1) & 63;
  }
  benchmark::DoNotOptimize(sink);
}

// ---------------------------------------------------------------- generated, state by state
#define BACKLASH_STATE_BENCHMARKS(ID)                                                                            \
  void BM_case_##ID##_theta_m(benchmark::State& s) { run(s, [](double t) { return generated::case_##ID::theta_m(t, v0); }); } \
  void BM_case_##ID##_dtheta_m(benchmark::State& s) { run(s, [](double t) { return generated::case_##ID::dtheta_m(t, v0); }); } \
  void BM_case_##ID##_theta_L(benchmark::State& s) { run(s, [](double t) { return generated::case_##ID::theta_L(t, v0); }); } \
  void BM_case_##ID##_dtheta_L(benchmark::State& s) { run(s, [](double t) { return generated::case_##ID::dtheta_L(t, v0); }); } \
  void BM_case_##ID##_gap(benchmark::State& s) { run(s, [](double t) { return generated::case_##ID::gap(t, v0); }); }   \
  void BM_case_##ID##_theta_o(benchmark::State& s) {                                                              \
    run(s, [](double t) { return generated::case_##ID::theta_o(t, theta_o0, dtheta_o0); });                       \
  }                                                                                                              \
  void BM_case_##ID##_dtheta_o(benchmark::State& s) {                                                             \
    run(s, [](double t) { return generated::case_##ID::dtheta_o(t, theta_o0, dtheta_o0); });                      \
  }                                                                                                              \
  void BM_case_##ID##_free_state(benchmark::State& s) {                                                           \
    run(s, [](double t) {                                                                                        \
      const auto x = generated::case_##ID::free_state(t, v0);                                                    \
      return x.theta_m + x.dtheta_m + x.theta_L + x.dtheta_L;                                                    \
    });                                                                                                          \
  }                                                                                                              \
  void BM_case_##ID##_contact_state(benchmark::State& s) {                                                        \
    run(s, [](double t) {                                                                                        \
      const auto x = generated::case_##ID::contact_state(t, theta_o0, dtheta_o0);                                \
      return x.theta_o + x.dtheta_o;                                                                             \
    });                                                                                                          \
  }                                                                                                              \
  BENCHMARK(BM_case_##ID##_theta_m);                                                                             \
  BENCHMARK(BM_case_##ID##_dtheta_m);                                                                            \
  BENCHMARK(BM_case_##ID##_theta_L);                                                                             \
  BENCHMARK(BM_case_##ID##_dtheta_L);                                                                            \
  BENCHMARK(BM_case_##ID##_gap);                                                                                 \
  BENCHMARK(BM_case_##ID##_theta_o);                                                                             \
  BENCHMARK(BM_case_##ID##_dtheta_o);                                                                            \
  BENCHMARK(BM_case_##ID##_free_state);                                                                          \
  BENCHMARK(BM_case_##ID##_contact_state);
BACKLASH_GENERATED_CASES(BACKLASH_STATE_BENCHMARKS)
#undef BACKLASH_STATE_BENCHMARKS

// ---------------------------------------------------------------- parametric and direct
numeric::Parameters case_parameters(const char* id) { return numeric::parameters_of(model::load_case(id)); }

void BM_parametric_free_state(benchmark::State& s, const char* id) {
  const numeric::StableSegments p(case_parameters(id));
  run(s, [&](double t) {
    const auto x = p.free_state(t, v0);
    return x.theta_m + x.dtheta_m + x.theta_L + x.dtheta_L;
  });
}
void BM_parametric_contact_state(benchmark::State& s, const char* id) {
  const numeric::StableSegments p(case_parameters(id));
  run(s, [&](double t) {
    const auto x = p.contact_state(t, theta_o0, dtheta_o0);
    return x.theta_o + x.dtheta_o;
  });
}
void BM_parametric_free_state_near_equal_rates(benchmark::State& s) {
  numeric::Parameters p = case_parameters("V");
  p.FL = p.JL * (p.Fm / p.Jm) * (1 + 1e-9);  // merging poles: the recurrence path
  const numeric::StableSegments segments(p);
  run(s, [&](double t) {
    const auto x = segments.free_state(t, v0);
    return x.theta_m + x.dtheta_m + x.theta_L + x.dtheta_L;
  });
}
void BM_direct_free_state(benchmark::State& s, const char* id) {
  const numeric::Parameters p = case_parameters(id);
  const numeric::Branch branch = numeric::select_branches(p).free;
  run(s, [&](double t) {
    const auto x = numeric::direct_free_state(branch, p, t, v0);
    return x.theta_m + x.dtheta_m + x.theta_L + x.dtheta_L;
  });
}
void BM_odeint_free_state(benchmark::State& s, const char* id) {
  const numeric::Parameters p = case_parameters(id);
  run(s, [&](double t) {
    const auto x = numeric::reference_free_state(p, v0, t, 1e-12);
    return x.theta_m + x.dtheta_m + x.theta_L + x.dtheta_L;
  });
}
void BM_odeint_contact_state(benchmark::State& s, const char* id) {
  const numeric::Parameters p = case_parameters(id);
  run(s, [&](double t) {
    const auto x = numeric::reference_contact_state(p, theta_o0, dtheta_o0, t, 1e-12);
    return x.theta_o + x.dtheta_o;
  });
}

BENCHMARK_CAPTURE(BM_parametric_free_state, case_V, "V");
BENCHMARK_CAPTURE(BM_parametric_free_state, case_III, "III");
BENCHMARK_CAPTURE(BM_parametric_free_state, case_I, "I");
BENCHMARK(BM_parametric_free_state_near_equal_rates);
BENCHMARK_CAPTURE(BM_parametric_contact_state, case_V, "V");
BENCHMARK_CAPTURE(BM_direct_free_state, case_V, "V");
BENCHMARK_CAPTURE(BM_direct_free_state, case_I, "I");
BENCHMARK_CAPTURE(BM_odeint_free_state, case_V, "V");
BENCHMARK_CAPTURE(BM_odeint_free_state, case_I, "I");
BENCHMARK_CAPTURE(BM_odeint_contact_state, case_V, "V");

// ---------------------------------------------------------------- summary
class Recorder : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs)
      if (run.run_type == Run::RT_Iteration && !run.error_occurred)
        ns[run.benchmark_name()] = run.GetAdjustedCPUTime();  // ns, CPU time (robust to a busy machine)
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> ns;
};

double get(const Recorder& r, const std::string& name) {
  const auto it = r.ns.find(name);
  return it == r.ns.end() ? 0.0 : it->second;
}

void summary(const Recorder& r) {
  std::printf("\nSummary (ns; a point = theta_m, dtheta_m, theta_L, dtheta_L at one t)\n");
  std::printf("%-6s %16s %16s %18s %18s\n", "case", "free max/state", "free joint/state", "contact max/state",
              "contact joint/state");
  double worst_free = 0, worst_contact = 0, worst_joint = 0;
  for (const char* id : {"I", "II", "III", "IV", "V", "VI", "VII", "VIII"}) {
    const std::string base = std::string("BM_case_") + id + "_";
    double free_max = 0, contact_max = 0;
    for (const char* s : {"theta_m", "dtheta_m", "theta_L", "dtheta_L", "gap"}) free_max = std::max(free_max, get(r, base + s));
    for (const char* s : {"theta_o", "dtheta_o"}) contact_max = std::max(contact_max, get(r, base + s));
    const double joint = get(r, base + "free_state") / 4, contact = get(r, base + "contact_state") / 2;
    worst_free = std::max(worst_free, free_max);
    worst_contact = std::max(worst_contact, contact_max);
    worst_joint = std::max({worst_joint, joint, contact});
    std::printf("%-6s %16.1f %16.1f %18.1f %18.1f\n", id, free_max, joint, contact_max, contact);
  }
  const double param_V = get(r, "BM_parametric_free_state/case_V") / 4;
  const double param_I = get(r, "BM_parametric_free_state/case_I") / 4;
  const double param_III = get(r, "BM_parametric_free_state/case_III") / 4;
  const double param_close = get(r, "BM_parametric_free_state_near_equal_rates") / 4;
  const double param_contact = get(r, "BM_parametric_contact_state/case_V") / 2;
  const double ode_V = get(r, "BM_odeint_free_state/case_V"), ode_I = get(r, "BM_odeint_free_state/case_I");
  const double ode_contact = get(r, "BM_odeint_contact_state/case_V");
  std::printf("parametric per state: case V %.1f, case III %.1f, case I %.1f, near equal rates %.1f, contact %.1f\n",
              param_V, param_III, param_I, param_close, param_contact);
  std::printf("direct per state: case V %.1f, case I %.1f\n", get(r, "BM_direct_free_state/case_V") / 4,
              get(r, "BM_direct_free_state/case_I") / 4);
  std::printf("odeint per point: free case V %.0f, free case I %.0f, contact case V %.0f\n", ode_V, ode_I, ode_contact);
  const double gen_point_V = get(r, "BM_case_V_free_state"), gen_point_I = get(r, "BM_case_I_free_state");
  std::printf("ratio odeint/generated per point: case V %.0fx, case I %.0fx; odeint/parametric: case V %.0fx, case I %.0fx\n",
              ode_V / gen_point_V, ode_I / gen_point_I, ode_V / (4 * param_V), ode_I / (4 * param_I));
  std::printf("targets: per-case <= 15 ns/state (single free state worst %.1f, single contact state worst %.1f "
              "[exp + sincos], joint evaluation worst %.1f), parametric <= 50 ns/state (worst %.1f), "
              "odeint >= 500x per point\n",
              worst_free, worst_contact, worst_joint, std::max({param_V, param_I, param_III, param_close, param_contact}));
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  Recorder recorder;
  benchmark::RunSpecifiedBenchmarks(&recorder);
  summary(recorder);
  benchmark::Shutdown();
  return 0;
}
