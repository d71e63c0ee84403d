// exam_generated_cases — the generated per-case evaluators (built at compile
// time by backlash_codegen) equal the exact case expressions, evaluated with
// 40 digits by GiNaC/CLN, at sample points; their metadata names the right
// case, branches, parameters and input file.
#include "exact_reference.hpp"

#include "backlash/codegen/emit.hpp"
#include "backlash/generated/cases.hpp"
#include "backlash/model/case_spec.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace {

using backlash::testing::contact_value;
using backlash::testing::free_value;
using backlash::testing::scaled_error;

struct GeneratedCase {
  std::string id;
  std::function<double(double, double)> theta_m, dtheta_m, theta_L, dtheta_L, gap;
  std::function<double(double, double, double)> theta_o, dtheta_o;
  double cot_phi;
  std::function<double(double)> separation_theta;
  std::string contact_branch, free_branch, measured_at, source_file, input_hash;
  std::vector<std::string> parameters_exact;
  std::function<std::vector<double>(double, double)> free_state;
  std::function<std::vector<double>(double, double, double)> contact_state;
};

std::vector<GeneratedCase> generated_cases() {
  std::vector<GeneratedCase> out;
#define BACKLASH_COLLECT(ID)                                                                                     \
  {                                                                                                              \
    namespace g = backlash::generated::case_##ID;                                                               \
    GeneratedCase c;                                                                                             \
    c.id = #ID;                                                                                                  \
    c.theta_m = g::theta_m;                                                                                      \
    c.dtheta_m = g::dtheta_m;                                                                                    \
    c.theta_L = g::theta_L;                                                                                      \
    c.dtheta_L = g::dtheta_L;                                                                                    \
    c.gap = g::gap;                                                                                              \
    c.theta_o = g::theta_o;                                                                                      \
    c.dtheta_o = g::dtheta_o;                                                                                    \
    c.cot_phi = g::cot_phi;                                                                                      \
    c.separation_theta = [](double v) { return g::separation_theta(v); };                                        \
    c.contact_branch = g::metadata::contact_branch;                                                              \
    c.free_branch = g::metadata::free_branch;                                                                    \
    c.measured_at = g::metadata::measured_at;                                                                    \
    c.source_file = g::metadata::source_file;                                                                    \
    c.input_hash = g::metadata::input_hash;                                                                      \
    for (int i = 0; i < g::metadata::parameter_count; ++i) c.parameters_exact.push_back(g::metadata::parameters_exact[i]); \
    c.free_state = [](double t, double v) {                                                                      \
      const auto s = g::free_state(t, v);                                                                        \
      return std::vector<double>{s.theta_m, s.dtheta_m, s.theta_L, s.dtheta_L, s.gap};                           \
    };                                                                                                           \
    c.contact_state = [](double t, double x, double v) {                                                         \
      const auto s = g::contact_state(t, x, v);                                                                  \
      return std::vector<double>{s.theta_o, s.dtheta_o};                                                         \
    };                                                                                                           \
    out.push_back(c);                                                                                            \
  }
  BACKLASH_GENERATED_CASES(BACKLASH_COLLECT)
#undef BACKLASH_COLLECT
  return out;
}

constexpr double tolerance = 1e-12;  // scaled: |error| <= tolerance * max(1, |value|)

class GeneratedCaseTest : public ::testing::TestWithParam<std::string> {
 protected:
  GeneratedCase generated() const {
    for (const GeneratedCase& c : generated_cases())
      if (c.id == GetParam()) return c;
    throw std::runtime_error("case " + GetParam() + " was not generated");
  }
};

TEST_P(GeneratedCaseTest, free_mode_states_equal_the_exact_expressions) {
  const GeneratedCase g = generated();
  const auto exact = backlash::testing::exact_case(backlash::model::load_case(g.id));
  const std::vector<std::pair<const char*, std::pair<const GiNaC::ex*, std::function<double(double, double)>>>> states{
      {"theta_m", {&exact.theta_m, g.theta_m}}, {"dtheta_m", {&exact.dtheta_m, g.dtheta_m}},
      {"theta_L", {&exact.theta_L, g.theta_L}}, {"dtheta_L", {&exact.dtheta_L, g.dtheta_L}},
      {"gap", {&exact.gap, g.gap}}};
  for (double t : {0.0, 1e-6, 0.1, 1.0, 3.7, 10.0, 25.0})
    for (double v0 : {-1.3, -1e-3, 1e-7, 0.42, 2.0}) {
      const std::vector<double> joint = g.free_state(t, v0);
      for (std::size_t k = 0; k < states.size(); ++k) {
        const auto& [name, pair] = states[k];
        const double expected = free_value(*pair.first, t, v0);
        const double actual = pair.second(t, v0);
        EXPECT_LE(scaled_error(actual, expected), tolerance)
            << "case " << g.id << ": " << name << "(t = " << t << ", dtheta_m0 = " << v0 << ") returned " << actual
            << " instead of " << expected;
        EXPECT_LE(scaled_error(joint[k], expected), tolerance)
            << "case " << g.id << ": free_state." << name << "(t = " << t << ", dtheta_m0 = " << v0 << ") returned "
            << joint[k] << " instead of " << expected;
      }
    }
}

TEST_P(GeneratedCaseTest, contact_mode_states_equal_the_exact_expressions) {
  const GeneratedCase g = generated();
  const auto exact = backlash::testing::exact_case(backlash::model::load_case(g.id));
  for (double t : {0.0, 0.05, 1.0, 4.4, 17.0, 40.0})
    for (auto [x0, v0] : std::vector<std::pair<double, double>>{{0.0, 0.0}, {0.38, 0.0}, {1.6, -0.4}, {1.2, 0.8}}) {
      const std::vector<double> joint = g.contact_state(t, x0, v0);
      const double expected[2] = {contact_value(exact.theta_o, t, x0, v0), contact_value(exact.dtheta_o, t, x0, v0)};
      const double actual[2] = {g.theta_o(t, x0, v0), g.dtheta_o(t, x0, v0)};
      const char* names[2] = {"theta_o", "dtheta_o"};
      for (int k = 0; k < 2; ++k) {
        EXPECT_LE(scaled_error(actual[k], expected[k]), tolerance)
            << "case " << g.id << ": " << names[k] << "(t = " << t << ", " << x0 << ", " << v0 << ") returned "
            << actual[k] << " instead of " << expected[k];
        EXPECT_LE(scaled_error(joint[k], expected[k]), tolerance)
            << "case " << g.id << ": contact_state." << names[k] << " returned " << joint[k] << " instead of "
            << expected[k];
      }
    }
}

TEST_P(GeneratedCaseTest, separation_line_equals_the_exact_one) {
  const GeneratedCase g = generated();
  const auto exact = backlash::testing::exact_case(backlash::model::load_case(g.id));
  const double cot = backlash::symbolic::to_double(exact.cot_phi, {});
  EXPECT_EQ(g.cot_phi, cot) << "case " << g.id << ": cot_phi returned " << g.cot_phi << " instead of " << cot;
  const double theta_R = backlash::model::to_double(backlash::model::load_case(g.id).reference);
  for (double v0 : {-1.0, 0.0, 0.3}) {
    const double expected = theta_R + cot * v0;
    EXPECT_NEAR(g.separation_theta(v0), expected, 1e-15)
        << "case " << g.id << ": separation_theta(" << v0 << ") returned " << g.separation_theta(v0) << " instead of "
        << expected;
    // The free mode starts on the separation line.
    EXPECT_NEAR(g.theta_m(0, v0), expected, 1e-12) << "case " << g.id << ": theta_m(0) returned " << g.theta_m(0, v0)
                                                   << " instead of " << expected;
  }
}

TEST_P(GeneratedCaseTest, metadata_names_the_case_its_branches_and_input) {
  const GeneratedCase g = generated();
  const backlash::model::CaseSpec spec = backlash::model::load_case(g.id);
  const auto derivation = backlash::symbolic::derive_case(spec);
  const std::string contact = backlash::symbolic::contact_branch_name(derivation.contact_branch);
  const std::string free = backlash::symbolic::free_branch_name(derivation.free_branch);
  EXPECT_EQ(g.contact_branch, contact) << "metadata contact_branch returned " << g.contact_branch << " instead of " << contact;
  EXPECT_EQ(g.free_branch, free) << "metadata free_branch returned " << g.free_branch << " instead of " << free;
  EXPECT_EQ(g.measured_at, backlash::model::to_string(spec.measured_at));
  const std::vector<std::string> exact{backlash::model::to_string(spec.Jm), backlash::model::to_string(spec.Fm),
                                       backlash::model::to_string(spec.JL), backlash::model::to_string(spec.FL),
                                       backlash::model::to_string(spec.K),  backlash::model::to_string(spec.reference),
                                       backlash::model::to_string(spec.backlash)};
  EXPECT_EQ(g.parameters_exact, exact);
  EXPECT_EQ(g.source_file, "cases/" + g.id + ".toml");
  const std::string expected_hash = backlash::codegen::describe_source(spec).input_hash;
  EXPECT_EQ(g.input_hash, expected_hash) << "metadata input_hash returned " << g.input_hash << " instead of "
                                         << expected_hash << " (is the generated header stale?)";
}

INSTANTIATE_TEST_SUITE_P(ThesisCases, GeneratedCaseTest,
                         ::testing::Values("I", "II", "III", "IV", "V", "VI", "VII", "VIII"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return "case_" + info.param; });

TEST(GeneratedCases, every_thesis_case_is_generated) {
  std::vector<std::string> ids;
  for (const GeneratedCase& c : generated_cases()) ids.push_back(c.id);
  EXPECT_EQ(ids, backlash::model::thesis_case_ids());
}

}  // namespace
