// The effects engine's witness constants built once per mode matrix and guard (issue 19, the effects
// engine per event; effects_engine.hpp, detail::witness_mode):
//   item_effects_witness_mode_as_rebuilt    a kept WitnessMode given a new forcing c is, member for
//                                           member and bit for bit, WitnessMode(A, c, e) built afresh
//                                           — for the engine's own modes (rigid contact, free flight,
//                                           the mesh) and random matrices, balanced or not;
//   item_effects_event_times_as_odeint      the closed-form engine's events, with each closed-form
//                                           effect, are the independent odeint effects simulator's:
//                                           the same kinds in the same order, times within the
//                                           cross-check's 1e-8 s (odeint at 1e-13).
#include "effects/effects_engine.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/odeint_effects_simulation.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace backlash;
using numeric::SmallMatrix;
using numeric::SmallRow;
using numeric::SmallVector;
using numeric::WitnessMode;

// Bit for bit (NaN payloads included): the same double.
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <class M>
bool same_bits(const M& a, const M& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!same_bits(a.data()[i], b.data()[i])) return false;
  return true;
}

void expect_same(const WitnessMode& a, const WitnessMode& b, const std::string& what) {
  EXPECT_TRUE(same_bits(a.A, b.A) && same_bits(a.c, b.c) && same_bits(a.e, b.e)) << what;
  EXPECT_TRUE(same_bits(a.eA, b.eA) && same_bits(a.eA2, b.eA2) && same_bits(a.eA3, b.eA3)) << what;
  EXPECT_TRUE(same_bits(a.scale, b.scale)) << what;
  for (const auto member : {&WitnessMode::ec, &WitnessMode::eAc, &WitnessMode::eA2c, &WitnessMode::mu_A, &WitnessMode::norm_e,
                            &WitnessMode::norm_eA2, &WitnessMode::norm_eA3, &WitnessMode::norm_e_plain, &WitnessMode::norm_eA,
                            &WitnessMode::norm_A, &WitnessMode::inverse_scale, &WitnessMode::time_unit})
    EXPECT_TRUE(same_bits(a.*member, b.*member)) << what << ": " << a.*member << " vs " << b.*member;
}

}  // namespace

TEST(EffectsEngineCost, item_effects_witness_mode_as_rebuilt) {
  std::mt19937 random(19);
  std::uniform_real_distribution<double> entry(-3, 3), log_size(-6, 6);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = trial % 2 == 0 ? 2 : 4;
    SmallMatrix A(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = entry(random) * std::pow(10.0, trial % 3 == 0 ? log_size(random) : 0.0);
    SmallVector c1(n), c2(n);
    SmallRow e(n);
    for (int i = 0; i < n; ++i) c1(i) = entry(random), c2(i) = entry(random) * 1e3, e(i) = entry(random);
    const std::string what = "trial " + std::to_string(trial);
    expect_same(numeric::detail::witness_mode(A, c1, e), WitnessMode(A, c1, e), what + " (first)");
    expect_same(numeric::detail::witness_mode(A, c2, e), WitnessMode(A, c2, e), what + " (kept, new c)");
    expect_same(numeric::detail::witness_mode(A, c1, e), WitnessMode(A, c1, e), what + " (kept, first c)");
  }
}

TEST(EffectsEngineCost, item_effects_event_times_as_odeint) {
  const model::CaseSpec spec = model::load_case("V");
  const numeric::ValidationResult nominal = numeric::validate(numeric::case_evaluator(spec));
  ASSERT_TRUE(nominal.passed());
  const numeric::Parameters p = numeric::parameters_of(spec);
  std::vector<std::pair<std::string, numeric::Effects>> list;
  auto add = [&list](const std::string& name, auto&& set) {
    numeric::Effects e;
    set(e);
    list.push_back({name, e});
  };
  add("coulomb_load", [](numeric::Effects& e) { e.coulomb_load = 0.03; });
  add("coulomb_motor", [](numeric::Effects& e) { e.coulomb_motor = 0.02; });
  add("restitution", [](numeric::Effects& e) { e.restitution = 0.4; });
  add("saturation", [](numeric::Effects& e) { e.saturation = 0.1; });
  add("compliance", [](numeric::Effects& e) { e.mesh_stiffness = 400, e.mesh_damping = 4; });
  add("torque_offset", [](numeric::Effects& e) { e.torque_offset = 0.02; });
  numeric::SimulationOptions o;
  o.t_end = 20;
  for (const auto& [name, effects] : list) {
    const numeric::EffectValidationResult gate = numeric::validate_effects(nominal.evaluator(), effects);
    ASSERT_TRUE(gate.passed()) << name;
    const numeric::SimulationResult closed = numeric::simulate_effects_step(gate.model(), 0.62, o, {.general_engine = true});
    numeric::OdeintSimulationOptions odeint;
    odeint.tolerance = 1e-13;
    const numeric::SimulationResult reference = numeric::simulate_effects_step_with_odeint(p, effects, 0.62, o, odeint);
    ASSERT_EQ(closed.events.size(), reference.events.size()) << name;
    for (std::size_t i = 0; i < closed.events.size(); ++i) {
      EXPECT_EQ(closed.events[i].kind, reference.events[i].kind) << name << ", event " << i;
      EXPECT_NEAR(closed.events[i].t, reference.events[i].t, 1e-8) << name << ", event " << i;
    }
  }
}
