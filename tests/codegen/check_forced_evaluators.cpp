// check_forced_evaluators — the generated forced-mode evaluators (namespace
// backlash::generated::case_<ID>::forced, emitted by codegen/src/emit_forced.cpp)
// against three independent references, for every thesis case:
//
//  1. the exact symbolic solution (symbolic::derive_forced_modes) evaluated by
//     CLN at 40 digits with the arguments taken exactly, at many (t, argument)
//     points: |generated − exact| ≤ 1e-13·S, where S = Σ |c_i·m_i(args)·t^k e^{rt}
//     cos/sin| is the size of the terms the closed form sums (partial fractions
//     cancel where a displacement is small: near t = 0 and where it changes sign,
//     so the error is measured against the terms, as it can only be); where the
//     sum is well conditioned (S ≤ 10·|exact|) also plainly |error| ≤ 1e-13·|exact|;
//  2. the numeric layer's own closed forms (numeric::ModeFlow::local on the mode
//     the forced solution describes, built from Effects, Mode and a start state):
//     |generated − ModeFlow| ≤ 1e-12·S;
//  3. Boost.Odeint integrating each forced ODE written as z' = A z + c
//     (numeric::reference_linear_trajectory, abs = rel tolerance 1e-12, the inputs
//     scaled to size 1 — the ODE is linear in them):
//     |generated − odeint| ≤ 1e-9·max(S, the component's size along the trajectory).
// Each test prints the largest error it measured.
#include "exact_reference.hpp"

#include "backlash/generated/cases.hpp"
#include "backlash/model/case_spec.hpp"
#include "effects/effect_modes.hpp"
#include "backlash/numeric/reference.hpp"
#include "backlash/symbolic/forced_modes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

// ------------------------------------------------------------------ the generated functions

namespace forced_fallback {
// At global scope, so that unqualified lookup in the collecting lambdas meets it
// together with the generated namespace (both nominated into the global scope).
// Chosen only when a case has no such function (motor_closed: output at the load;
// coupled: output at the motor): a generated function is a better match.
struct absent {};
template <class... A>
absent motor_closed(A...) { return {}; }
template <class... A>
absent coupled(A...) { return {}; }
}  // namespace forced_fallback

namespace {

using GiNaC::ex;
using GiNaC::numeric;
using Values = std::vector<double>;
using Args = std::vector<double>;
using Evaluator = std::function<Values(double, const Args&)>;

template <class F>
Evaluator motor_closed_adapter(F f) {
  if constexpr (std::is_same_v<std::invoke_result_t<F, double, double, double>, forced_fallback::absent>) {
    return {};
  } else {
    return [f](double t, const Args& a) {
      const auto s = f(t, a[0], a[1]);
      return Values{s.y, s.velocity, s.displacement};
    };
  }
}

template <class F>
Evaluator coupled_adapter(F f) {
  if constexpr (std::is_same_v<std::invoke_result_t<F, double, double, double, double, double, double>, forced_fallback::absent>) {
    return {};
  } else {
    return [f](double t, const Args& a) {
      const auto s = f(t, a[0], a[1], a[2], a[3], a[4]);
      return Values{s.motor_displacement, s.motor_velocity, s.load_displacement, s.load_velocity};
    };
  }
}

struct GeneratedForced {
  std::string id;
  std::map<std::string, Evaluator> modes;  // absent modes are not in the map
};

std::vector<GeneratedForced> generated_forced() {
  std::vector<GeneratedForced> out;
#define BACKLASH_COLLECT_FORCED(ID)                                                                              \
  {                                                                                                              \
    namespace f = backlash::generated::case_##ID::forced;                                                       \
    GeneratedForced c;                                                                                           \
    c.id = #ID;                                                                                                  \
    c.modes["contact_constant"] = [](double t, const Args& a) {                                                  \
      const auto s = f::contact_constant(t, a[0], a[1]);                                                         \
      return Values{s.displacement, s.velocity};                                                                 \
    };                                                                                                           \
    c.modes["load_constant"] = [](double t, const Args& a) {                                                     \
      const auto s = f::load_constant(t, a[0], a[1]);                                                            \
      return Values{s.displacement, s.velocity};                                                                 \
    };                                                                                                           \
    c.modes["motor_constant"] = [](double t, const Args& a) {                                                    \
      const auto s = f::motor_constant(t, a[0], a[1]);                                                           \
      return Values{s.displacement, s.velocity};                                                                 \
    };                                                                                                           \
    Evaluator closed = motor_closed_adapter([](double t, double y0, double v0) {                                 \
      using namespace backlash::generated::case_##ID::forced;                                                    \
      using namespace forced_fallback;                                                                                  \
      return motor_closed(t, y0, v0);                                                                            \
    });                                                                                                          \
    if (closed) c.modes["motor_closed"] = closed;                                                                \
    Evaluator coupled_flight =                                                                                   \
        coupled_adapter([](double t, double vm0, double yL0, double vL0, double um, double uL) {                 \
          using namespace backlash::generated::case_##ID::forced;                                                \
          using namespace forced_fallback;                                                                              \
          return coupled(t, vm0, yL0, vL0, um, uL);                                                              \
        });                                                                                                      \
    if (coupled_flight) c.modes["coupled"] = coupled_flight;                                                     \
    out.push_back(c);                                                                                            \
  }
  BACKLASH_GENERATED_CASES(BACKLASH_COLLECT_FORCED)
#undef BACKLASH_COLLECT_FORCED
  return out;
}

const GeneratedForced& generated(const std::string& id) {
  static const std::vector<GeneratedForced> all = generated_forced();
  for (const GeneratedForced& g : all)
    if (g.id == id) return g;
  throw std::runtime_error("case " + id + " was not generated");
}

// The output order of the generated result structs (checked against the symbolic solutions).
const std::map<std::string, std::vector<std::string>>& output_names() {
  static const std::map<std::string, std::vector<std::string>> names{
      {"contact_constant", {"displacement", "velocity"}},
      {"load_constant", {"displacement", "velocity"}},
      {"motor_constant", {"displacement", "velocity"}},
      {"motor_closed", {"y", "velocity", "displacement"}},
      {"coupled", {"motor_displacement", "motor_velocity", "load_displacement", "load_velocity"}}};
  return names;
}

// ------------------------------------------------------------------ the exact reference

// One output as exponential-polynomial terms with 40-digit coefficients per monomial of
// the arguments: value and term size S at (t, args), arguments taken exactly.
class ExactOutput {
 public:
  ExactOutput(const backlash::symbolic::TimeFunction& f, const backlash::symbolic::RadicalList& radicals,
              const std::vector<ex>& arguments) {
    const DigitsGuard guard;
    const backlash::symbolic::TimeFunction combined = f.combined(radicals);
    for (const backlash::symbolic::ExpTerm& term : combined.terms()) {
      Term t;
      t.t_power = term.t_power;
      t.rate = to_numeric(term.rate, radicals);
      t.oscillation = term.oscillation;
      t.frequency = term.oscillation == backlash::symbolic::Oscillation::None ? numeric(0) : to_numeric(term.frequency, radicals);
      std::vector<unsigned> powers(arguments.size(), 0);
      split(backlash::symbolic::with_explicit_radicals(term.coefficient, radicals).expand(), arguments, 0, powers,
            t.monomials);
      terms_.push_back(t);
    }
  }

  struct Value {
    double value = 0, size = 0;
  };
  Value at(double t_double, const Args& args) const {
    const DigitsGuard guard;
    const numeric t = backlash::testing::exact_numeric(t_double);
    std::vector<numeric> a;
    for (double x : args) a.push_back(backlash::testing::exact_numeric(x));
    numeric value = 0, size = 0;
    for (const Term& term : terms_) {
      numeric factor = integer_power(t, term.t_power);
      if (!term.rate.is_zero()) factor *= GiNaC::exp(term.rate * t);
      if (term.oscillation == backlash::symbolic::Oscillation::Cos) factor *= GiNaC::cos(term.frequency * t);
      if (term.oscillation == backlash::symbolic::Oscillation::Sin) factor *= GiNaC::sin(term.frequency * t);
      for (const auto& [c, powers] : term.monomials) {
        numeric m = c * factor;
        for (std::size_t i = 0; i < a.size(); ++i) m *= integer_power(a[i], powers[i]);
        value += m;
        size += GiNaC::abs(m);
      }
    }
    return {value.to_double(), size.to_double()};
  }

 private:
  struct DigitsGuard {
    long saved = GiNaC::Digits;
    DigitsGuard() { GiNaC::Digits = 40; }
    ~DigitsGuard() { GiNaC::Digits = saved; }
  };
  struct Term {
    std::vector<std::pair<numeric, std::vector<unsigned>>> monomials;
    unsigned t_power = 0;
    numeric rate, frequency;
    backlash::symbolic::Oscillation oscillation = backlash::symbolic::Oscillation::None;
  };
  static numeric integer_power(const numeric& x, unsigned k) {  // x^0 = 1, also for x = 0
    numeric out = 1;
    for (unsigned i = 0; i < k; ++i) out *= x;
    return out;
  }
  static numeric to_numeric(const ex& e, const backlash::symbolic::RadicalList& radicals) {
    const ex value = GiNaC::evalf(backlash::symbolic::with_explicit_radicals(e, radicals));
    if (!GiNaC::is_a<numeric>(value)) throw std::runtime_error("exact reference: not a number");
    return GiNaC::ex_to<numeric>(value);
  }
  static void split(const ex& c, const std::vector<ex>& arguments, std::size_t level, std::vector<unsigned>& powers,
                    std::vector<std::pair<numeric, std::vector<unsigned>>>& out) {
    if (level == arguments.size()) {
      if (c.is_zero()) return;
      out.push_back({to_numeric(c, {}), powers});
      return;
    }
    const ex& s = arguments[level];
    for (int k = 0; k <= c.degree(s); ++k) {
      powers[level] = static_cast<unsigned>(k);
      split(c.coeff(s, k), arguments, level + 1, powers, out);
    }
    powers[level] = 0;
  }
  std::vector<Term> terms_;
};

struct ExactMode {
  std::vector<std::string> outputs;
  std::vector<ExactOutput> values;
};

// Every forced mode of a case, exact (derived once per case).
const std::map<std::string, ExactMode>& exact_modes(const std::string& id) {
  static std::map<std::string, std::map<std::string, ExactMode>> cache;
  auto found = cache.find(id);
  if (found != cache.end()) return found->second;
  const backlash::symbolic::ForcedModes m = backlash::symbolic::derive_forced_modes(backlash::model::load_case(id));
  std::map<std::string, ExactMode> modes;
  for (const backlash::symbolic::ForcedSolution* s : m.solutions()) {
    ExactMode mode;
    for (const backlash::symbolic::ForcedOutput& o : s->outputs) {
      mode.outputs.push_back(o.segment.name);
      mode.values.emplace_back(o.segment.solution, m.radicals, s->arguments);
    }
    modes[s->name] = std::move(mode);
  }
  return cache[id] = std::move(modes);
}

// ------------------------------------------------------------------ sample points

const std::vector<double> sample_times{0.0, 1e-3, 0.05, 0.7, 2.5, 9.0, 30.0};

const std::map<std::string, std::vector<Args>>& sample_arguments() {
  static const std::map<std::string, std::vector<Args>> args{
      {"contact_constant", {{0.5, 0.1}, {-1.3, 0.02}, {2.0, -0.7}, {1e-3, 0.3}, {0.0, -1e-3}, {0.8, 0.0}}},
      {"load_constant", {{0.5, 0.1}, {-1.3, 0.02}, {2.0, -0.7}, {1e-3, 0.3}, {0.0, -1e-3}, {0.8, 0.0}}},
      {"motor_constant", {{0.5, 0.1}, {-1.3, 0.02}, {2.0, -0.7}, {1e-3, 0.3}, {0.0, -1e-3}, {0.8, 0.0}}},
      {"motor_closed", {{0.3, -0.5}, {-1.1, 0.2}, {0.0, 1.0}, {1e-4, 0.0}, {2.0, 2.0}, {-0.05, -0.7}}},
      {"coupled",
       {{0.5, 0.1, 0.4, 0.05, -0.02},
        {-1.2, 0.3, -0.8, -0.1, 0.01},
        {0.0, -0.2, 0.6, 0.3, 0.0},
        {1e-3, 1e-3, 2e-3, -1e-3, 5e-4},
        {2.0, -1.5, 1.0, 0.7, -0.3},
        {0.3, 0.0, 0.0, 0.0, 0.0}}}};
  return args;
}

std::string describe(const std::string& id, const std::string& mode, const std::string& output, double t, const Args& a) {
  std::ostringstream out;
  out.precision(17);
  out << "case " << id << ": forced::" << mode << "(t = " << t;
  for (double x : a) out << ", " << x;
  out << ")." << output;
  return out.str();
}

class ForcedEvaluatorTest : public ::testing::TestWithParam<std::string> {};

// ------------------------------------------------------------------ 1. exact

TEST_P(ForcedEvaluatorTest, check_generated_forced_modes_equal_the_exact_solutions) {
  const std::string id = GetParam();
  const GeneratedForced& g = generated(id);
  const std::map<std::string, ExactMode>& exact = exact_modes(id);
  std::vector<std::string> generated_names, exact_names;
  for (const auto& [name, f] : g.modes) generated_names.push_back(name);
  for (const auto& [name, m] : exact) exact_names.push_back(name);
  ASSERT_EQ(generated_names, exact_names) << "case " << id << ": the generated forced modes differ from the derived ones";
  double worst_scaled = 0, worst_plain = 0;
  long points = 0;
  for (const auto& [name, mode] : exact) {
    ASSERT_EQ(mode.outputs, output_names().at(name)) << "case " << id << ": " << name << " outputs";
    for (const Args& a : sample_arguments().at(name))
      for (double t : sample_times) {
        const Values got = g.modes.at(name)(t, a);
        for (std::size_t k = 0; k < mode.values.size(); ++k, ++points) {
          const ExactOutput::Value e = mode.values[k].at(t, a);
          const double error = std::fabs(got[k] - e.value);
          worst_scaled = std::max(worst_scaled, e.size > 0 ? error / e.size : error);
          EXPECT_LE(error, 1e-13 * e.size) << describe(id, name, mode.outputs[k], t, a) << " returned " << got[k]
                                           << " instead of " << e.value << " (terms of size " << e.size << ")";
          if (e.size <= 10 * std::fabs(e.value) && e.value != 0) {
            worst_plain = std::max(worst_plain, error / std::fabs(e.value));
            EXPECT_LE(error, 1e-13 * std::fabs(e.value))
                << describe(id, name, mode.outputs[k], t, a) << " returned " << got[k] << " instead of " << e.value;
          }
        }
      }
  }
  std::cout << "case " << id << ": " << points << " values; max |error|/S = " << worst_scaled
            << ", max relative error where S <= 10|exact| = " << worst_plain << "\n";
}

// ------------------------------------------------------------------ 2. the numeric layer's closed forms

struct FlowScenario {
  std::string mode;            // forced mode
  backlash::numeric::Mode m;   // the numeric mode it describes
  backlash::numeric::HybridState start;
};

TEST_P(ForcedEvaluatorTest, check_generated_forced_modes_equal_the_numeric_closed_forms) {
  namespace nm = backlash::numeric;
  const std::string id = GetParam();
  const backlash::model::CaseSpec spec = backlash::model::load_case(id);
  const nm::Parameters p = nm::parameters_of(spec);
  const bool at_motor = spec.measured_at == backlash::model::MeasuredAt::Motor;
  nm::Effects e;
  e.coulomb_motor = 0.03;
  e.coulomb_load = 0.02;
  e.saturation = 0.4;
  e.torque_offset = 0.05;
  const GeneratedForced& g = generated(id);
  const std::map<std::string, ExactMode>& exact = exact_modes(id);
  auto state = [&](double theta_m, double dtheta_m, double theta_L, double dtheta_L) {
    nm::HybridState s;
    s.theta_m = theta_m;
    s.dtheta_m = dtheta_m;
    s.theta_L = theta_L;
    s.dtheta_L = dtheta_L;
    s.in_contact = false;
    return s;
  };
  std::vector<FlowScenario> scenarios;
  for (int regime : {1, -1})
    for (int slip : {1, -1}) {
      nm::HybridState contact = state(0.6, 0.7 * slip, 0.6 + p.backlash / 2, 0.7 * slip);
      contact.in_contact = true;
      scenarios.push_back({"contact_constant", {nm::ModeKind::Contact, -1, regime, slip, slip}, contact});
      scenarios.push_back({"motor_constant", {nm::ModeKind::Free, -1, regime, slip, 1}, state(0.4, -0.9 * slip, 0.5, 0.3)});
      scenarios.push_back({"load_constant", {nm::ModeKind::Free, 1, regime, 1, slip}, state(0.4, 0.2, 0.45, 1.1 * slip)});
    }
  for (int sm : {1, -1})
    for (int sl : {1, -1})
      scenarios.push_back({at_motor ? "motor_closed" : "coupled", {nm::ModeKind::Free, -1, 0, sm, sl},
                           state(0.35, 0.8 * sm, 0.35 + p.backlash, -0.6 * sl)});
  double worst = 0;
  for (const FlowScenario& sc : scenarios) {
    const nm::ModeFlow flow(p, e, sc.m, sc.start);
    // The forced mode's arguments for this start, formed as the numeric layer forms them.
    Args a;
    std::vector<int> rows;  // flow.local() row of each generated output (−1: not compared)
    const double T = e.coulomb_motor + e.coulomb_load;
    if (sc.mode == "contact_constant") {
      a = {sc.start.dtheta_m, sc.m.regime * e.saturation + e.torque_offset - T * sc.m.slip_motor};
      rows = {0, 1};
    } else if (sc.mode == "motor_constant") {
      a = {sc.start.dtheta_m, sc.m.regime * e.saturation + e.torque_offset - e.coulomb_motor * sc.m.slip_motor};
      rows = {0, 1};
    } else if (sc.mode == "load_constant") {
      a = {sc.start.dtheta_L, -e.coulomb_load * sc.m.slip_load};
      rows = {2, 3};
    } else if (sc.mode == "motor_closed") {
      const double y_star = (e.torque_offset - e.coulomb_motor * sc.m.slip_motor) / p.K;
      a = {sc.start.theta_m - p.theta_R - y_star, sc.start.dtheta_m};
      rows = {-1, 1, 0};
    } else {
      a = {sc.start.dtheta_m, sc.start.theta_L - p.theta_R, sc.start.dtheta_L,
           e.torque_offset - e.coulomb_motor * sc.m.slip_motor, -e.coulomb_load * sc.m.slip_load};
      rows = {0, 1, 2, 3};
    }
    const ExactMode& mode = exact.at(sc.mode);
    for (double t : {0.01, 0.3, 1.7, 6.0, 20.0}) {
      const nm::SmallVector z = flow.local(t);
      const Values got = g.modes.at(sc.mode)(t, a);
      for (std::size_t k = 0; k < rows.size(); ++k) {
        if (rows[k] < 0) continue;
        const double size = mode.values[k].at(t, a).size;
        const double error = std::fabs(got[k] - z(rows[k]));
        worst = std::max(worst, error / size);
        EXPECT_LE(error, 1e-12 * size) << describe(id, sc.mode, mode.outputs[k], t, a) << " returned " << got[k]
                                       << " instead of " << z(rows[k]) << " (numeric::ModeFlow, "
                                       << sc.m.describe() << "; terms of size " << size << ")";
      }
    }
  }
  std::cout << "case " << id << ": " << scenarios.size() << " modes; max |generated - ModeFlow|/S = " << worst << "\n";
}

// ------------------------------------------------------------------ 3. odeint

TEST_P(ForcedEvaluatorTest, check_generated_forced_modes_follow_their_ode_under_odeint) {
  namespace nm = backlash::numeric;
  const std::string id = GetParam();
  const nm::Parameters p = nm::parameters_of(backlash::model::load_case(id));
  const GeneratedForced& g = generated(id);
  const std::map<std::string, ExactMode>& exact = exact_modes(id);
  const std::vector<double> times{0.25, 1.0, 3.0, 8.0, 20.0};
  double worst = 0;
  for (const auto& [name, mode] : exact) {
    for (const Args& a : sample_arguments().at(name)) {
      // The forced ODE as z' = A z + c, written from its equation (not from the numeric layer).
      const int n = name == "coupled" ? 4 : 2;
      nm::LinearSegment segment{nm::SmallMatrix::Zero(n, n), nm::SmallVector::Zero(n)};
      nm::SmallVector z0 = nm::SmallVector::Zero(n);
      std::vector<std::pair<int, int>> compare;  // (generated output, z row)
      segment.A(0, 1) = 1;
      if (name == "coupled") {  // z = (Δm, θ̇m, ΔL, θ̇L)
        segment.A(1, 1) = -p.Fm / p.Jm;
        segment.A(1, 2) = -p.K / p.Jm;
        segment.A(2, 3) = 1;
        segment.A(3, 3) = -p.FL / p.JL;
        segment.c(1) = (a[3] - p.K * a[1]) / p.Jm;
        segment.c(3) = a[4] / p.JL;
        z0 << 0, a[0], 0, a[2];
        compare = {{0, 0}, {1, 1}, {2, 2}, {3, 3}};
      } else if (name == "motor_closed") {  // z = (y, y')
        segment.A(1, 0) = -p.K / p.Jm;
        segment.A(1, 1) = -p.Fm / p.Jm;
        z0 << a[0], a[1];
        compare = {{0, 0}, {1, 1}};
      } else {  // z = (Δ, Δ'): J Δ'' + F Δ' = g
        const double J = name == "contact_constant" ? p.Jm + p.JL : (name == "load_constant" ? p.JL : p.Jm);
        const double F = name == "contact_constant" ? p.Fm + p.FL : (name == "load_constant" ? p.FL : p.Fm);
        segment.A(1, 1) = -F / J;
        segment.c(1) = a[1] / J;
        z0 << 0, a[0];
        compare = {{0, 0}, {1, 1}};
      }
      // The ODE is linear in (z0, c): integrate it scaled to inputs of size 1 (odeint's
      // absolute tolerance then means relative to the inputs) and scale back.
      const double input = std::max(z0.cwiseAbs().maxCoeff(), segment.c.cwiseAbs().maxCoeff());
      const double unit = input > 0 ? input : 1.0;
      nm::LinearSegment scaled = segment;
      scaled.c /= unit;
      std::vector<nm::SmallVector> reference = nm::reference_linear_trajectory(scaled, z0 / unit, times);
      for (nm::SmallVector& z : reference) z *= unit;
      // odeint controls its error against the size of the state it integrates (abs = rel =
      // 1e-12 per step), so a component is compared on the scale of that component along
      // the sampled trajectory (its start included), or of the closed form's terms if larger.
      nm::SmallVector magnitude = z0.cwiseAbs();
      for (const nm::SmallVector& z : reference) magnitude = magnitude.cwiseMax(z.cwiseAbs());
      for (std::size_t i = 0; i < times.size(); ++i) {
        const Values got = g.modes.at(name)(times[i], a);
        for (const auto& [k, row] : compare) {
          const double scale = std::max(mode.values[k].at(times[i], a).size, magnitude(row));
          const double error = std::fabs(got[k] - reference[i](row));
          worst = std::max(worst, error / scale);
          EXPECT_LE(error, 1e-9 * scale) << describe(id, name, mode.outputs[k], times[i], a) << " returned " << got[k]
                                         << " instead of " << reference[i](row) << " (odeint; scale " << scale << ")";
        }
        if (name == "motor_closed") {  // displacement = y − y0
          const double scale = std::max(mode.values[2].at(times[i], a).size, magnitude(0));
          const double error = std::fabs(got[2] - (reference[i](0) - a[0]));
          worst = std::max(worst, error / scale);
          EXPECT_LE(error, 1e-9 * scale) << describe(id, name, "displacement", times[i], a) << " returned " << got[2]
                                         << " instead of " << reference[i](0) - a[0] << " (odeint; scale " << scale << ")";
        }
      }
    }
  }
  std::cout << "case " << id << ": max |generated - odeint|/scale = " << worst << "\n";
}

INSTANTIATE_TEST_SUITE_P(ThesisCases, ForcedEvaluatorTest,
                         ::testing::Values("I", "II", "III", "IV", "V", "VI", "VII", "VIII"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return "case_" + info.param; });

}  // namespace
