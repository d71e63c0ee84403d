// check_parametric_accuracy — the stable parametric evaluator
// (numeric/parametric.hpp) is accurate everywhere: relative error
// ≤ 1e-10 (|error| ≤ 1e-10·max(1, |value|)) against the exact case
// expression (GiNaC/CLN, 80 digits — the partial fractions of the reference
// cancel up to ~1e28 at the finest grid points) on grids approaching every
// pole-structure degeneracy: FL = 10^-k, Fm = 10^-k, Fm/Jm − FL/JL = ±10^-k,
// contact and motor discriminants ±10^-k, k = 1…14, and the degenerate points
// themselves.  Also: the dispatcher picks the branch symbolic/ picks, and the
// direct partial-fraction formulas do lose their digits near FL = 0 (the
// reason for the stable layer).
#include "exact_reference.hpp"

#include "backlash/numeric/direct_branches.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/symbolic/general_derivation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace {

using backlash::model::MeasuredAt;
using backlash::model::Rational;
using backlash::testing::contact_value;
using backlash::testing::free_value;
using backlash::testing::make_spec;
using backlash::testing::ratio;
using backlash::testing::scaled_error;
using backlash::testing::ten_to_minus;

constexpr double tolerance = 1e-10;
constexpr int reference_digits = 80;

struct Family {
  std::string name;
  bool both_signs;  // perturbation ±10^-k (else +10^-k only)
  // spec for perturbation eps (exact), with sign; eps = 0 is the degenerate point itself
  std::function<backlash::model::CaseSpec(const Rational& eps)> spec;
};

std::vector<Family> families() {
  using M = MeasuredAt;
  return {
      {"contact_discriminant", true,
       [](const Rational& e) {  // F = 1, J = 1: F^2 - 4JK = -4*(1/4)*e
         return make_spec("contact_disc", ratio(1, 2), ratio(1, 2), ratio(1, 2), ratio(1, 2), ratio(1, 4) * (1 + e),
                          ratio(1), ratio(3, 10), M::Load);
       }},
      {"load_FL", false,
       [](const Rational& e) {
         return make_spec("load_FL", ratio(1, 2), ratio(1, 10), ratio(1, 2), e, ratio(1), ratio(1), ratio(3, 10), M::Load);
       }},
      {"load_Fm", false,
       [](const Rational& e) {
         return make_spec("load_Fm", ratio(1, 2), e, ratio(1, 2), ratio(3, 10), ratio(1), ratio(1), ratio(3, 10), M::Load);
       }},
      {"load_Fm_and_FL", false,
       [](const Rational& e) {
         return make_spec("load_both", ratio(1, 2), e, ratio(1, 2), 3 * e, ratio(1), ratio(-1, 2), ratio(3, 10), M::Load);
       }},
      {"load_equal_rates", true,
       [](const Rational& e) {  // Fm/Jm - FL/JL = e
         return make_spec("load_equal", ratio(1, 2), ratio(3, 10), ratio(4, 5), ratio(4, 5) * (ratio(3, 5) - e), ratio(1),
                          ratio(1), ratio(3, 10), M::Load);
       }},
      {"motor_discriminant", true,
       [](const Rational& e) {  // Fm^2 - 4JmK = -e
         return make_spec("motor_disc", ratio(1, 4), ratio(1), ratio(1, 2), ratio(3, 10), 1 + e, ratio(1), ratio(1, 5),
                          M::Motor);
       }},
      {"motor_FL", false,
       [](const Rational& e) {
         return make_spec("motor_FL", ratio(3, 5), ratio(12, 25), ratio(2, 5), e, ratio(1), ratio(1), ratio(1, 5), M::Motor);
       }},
      {"motor_critical_FL", false,
       [](const Rational& e) {
         return make_spec("motor_crit_FL", ratio(1, 4), ratio(1), ratio(1, 2), e, ratio(1), ratio(1), ratio(1, 5), M::Motor);
       }},
      {"motor_discriminant_FL0", true,
       [](const Rational& e) {
         return make_spec("motor_disc_FL0", ratio(1, 4), ratio(1), ratio(1, 2), ratio(0), 1 + e, ratio(2), ratio(1, 5),
                          M::Motor);
       }},
  };
}

struct GridPoint {
  std::string label;
  Rational eps;
};

std::vector<GridPoint> grid(bool both_signs) {
  std::vector<GridPoint> out{{"exactly degenerate", Rational(0)}};
  for (int k = 1; k <= 14; ++k) {
    out.push_back({"+1e-" + std::to_string(k), ten_to_minus(k)});
    if (both_signs) out.push_back({"-1e-" + std::to_string(k), -ten_to_minus(k)});
  }
  return out;
}

class NearDegenerate : public ::testing::TestWithParam<int> {};

TEST_P(NearDegenerate, stable_parametric_evaluator_is_accurate_to_1e_10) {
  const Family family = families().at(static_cast<std::size_t>(GetParam()));
  double worst = 0;
  std::string worst_where;
  for (const GridPoint& point : grid(family.both_signs)) {
    const backlash::model::CaseSpec spec = family.spec(point.eps);
    const auto exact = backlash::testing::exact_case_from_branches(spec);
    const backlash::numeric::Parameters p = backlash::numeric::parameters_of(spec);
    const std::string where = family.name + " " + point.label;
    for (double t : {1e-6, 1e-3, 0.3, 2.5, 11.0, 40.0, 90.0})
      for (double v0 : {-0.8, 1e-3, 1.7}) {
        const backlash::numeric::FreeState s = backlash::numeric::free_state(p, t, v0);
        const std::pair<const char*, std::pair<double, const GiNaC::ex*>> states[] = {
            {"theta_m", {s.theta_m, &exact.theta_m}}, {"dtheta_m", {s.dtheta_m, &exact.dtheta_m}},
            {"theta_L", {s.theta_L, &exact.theta_L}}, {"dtheta_L", {s.dtheta_L, &exact.dtheta_L}},
            {"gap", {s.gap, &exact.gap}}};
        for (const auto& [name, pair] : states) {
          const double expected = free_value(*pair.second, t, v0, reference_digits);
          const double error = scaled_error(pair.first, expected);
          if (error > worst) worst = error, worst_where = where + " " + name;
          EXPECT_LE(error, tolerance) << where << ": " << name << "(t = " << t << ", dtheta_m0 = " << v0
                                      << ") returned " << pair.first << " instead of " << expected;
        }
      }
    for (double t : {1e-6, 1e-3, 0.3, 2.5, 11.0, 40.0, 90.0})
      for (auto [x0, v0] : std::vector<std::pair<double, double>>{{0.0, 0.0}, {1.6, -0.4}, {0.3, 1.1}}) {
        const backlash::numeric::ContactState s = backlash::numeric::contact_state(p, t, x0, v0);
        const double expected[2] = {contact_value(exact.theta_o, t, x0, v0, reference_digits),
                                    contact_value(exact.dtheta_o, t, x0, v0, reference_digits)};
        const double actual[2] = {s.theta_o, s.dtheta_o};
        const char* names[2] = {"theta_o", "dtheta_o"};
        for (int k = 0; k < 2; ++k) {
          const double error = scaled_error(actual[k], expected[k]);
          if (error > worst) worst = error, worst_where = where + " " + names[k];
          EXPECT_LE(error, tolerance) << where << ": " << names[k] << "(t = " << t << ", " << x0 << ", " << v0
                                      << ") returned " << actual[k] << " instead of " << expected[k];
        }
      }
  }
  RecordProperty("worst_scaled_error", std::to_string(worst));
  std::cout << "[ info ] " << family.name << ": worst scaled error " << worst << " (" << worst_where << ")\n";
}

TEST_P(NearDegenerate, dispatcher_picks_the_branch_symbolic_picks) {
  const Family family = families().at(static_cast<std::size_t>(GetParam()));
  for (const GridPoint& point : grid(family.both_signs)) {
    const backlash::model::CaseSpec spec = family.spec(point.eps);
    const auto params = backlash::symbolic::exact_parameters(spec);
    const std::string contact = backlash::symbolic::contact_branch_name(backlash::symbolic::classify_contact(params));
    const std::string free = backlash::symbolic::free_branch_name(backlash::symbolic::classify_free(params));
    const auto chosen = backlash::numeric::select_branches(backlash::numeric::parameters_of(spec));
    EXPECT_EQ(backlash::numeric::branch_name(chosen.contact), contact)
        << family.name << " " << point.label << ": dispatcher returned " << backlash::numeric::branch_name(chosen.contact)
        << " instead of " << contact;
    EXPECT_EQ(backlash::numeric::branch_name(chosen.free), free)
        << family.name << " " << point.label << ": dispatcher returned " << backlash::numeric::branch_name(chosen.free)
        << " instead of " << free;
  }
}

INSTANTIATE_TEST_SUITE_P(Families, NearDegenerate, ::testing::Range(0, 9),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return families().at(static_cast<std::size_t>(info.param)).name;
                         });

// The reason for the stable layer: near FL = 0 the direct load_generic partial
// fractions lose their digits (error ~ 1/FL^2), the stable evaluator does not.
TEST(DirectFormulas, lose_digits_near_merging_poles_where_the_stable_layer_does_not) {
  const auto spec = make_spec("near_FL0", ratio(1, 2), ratio(1, 10), ratio(1, 2), ten_to_minus(8), ratio(1), ratio(1),
                              ratio(3, 10), MeasuredAt::Load);
  const auto exact = backlash::testing::exact_case_from_branches(spec);
  const auto p = backlash::numeric::parameters_of(spec);
  ASSERT_EQ(backlash::numeric::select_branches(p).free, backlash::numeric::Branch::LoadGeneric);
  const double t = 11.0, v0 = 1.0;
  const double expected = free_value(exact.theta_m, t, v0, reference_digits);
  const double direct = backlash::numeric::direct_free_state(backlash::numeric::Branch::LoadGeneric, p, t, v0).theta_m;
  const double stable = backlash::numeric::free_state(p, t, v0).theta_m;
  EXPECT_GT(scaled_error(direct, expected), 1e-6) << "direct load_generic at FL = 1e-8 returned " << direct
                                                  << ", unexpectedly close to " << expected;
  EXPECT_LE(scaled_error(stable, expected), tolerance) << "stable theta_m returned " << stable << " instead of " << expected;
}

// On each branch's own representative point the direct generated formulas and
// the stable evaluator agree with the exact expressions.
TEST(BranchRepresentatives, direct_and_stable_evaluators_equal_the_exact_solution) {
  for (const auto& rep : backlash::numeric::branch_representatives()) {
    const auto& p = rep.parameters;
    const auto spec = make_spec(backlash::numeric::branch_name(rep.branch), backlash::testing::decimal_rational(p.Jm),
                                backlash::testing::decimal_rational(p.Fm), backlash::testing::decimal_rational(p.JL),
                                backlash::testing::decimal_rational(p.FL), backlash::testing::decimal_rational(p.K),
                                backlash::testing::decimal_rational(p.theta_R), backlash::testing::decimal_rational(p.backlash),
                                p.measured_at);
    const auto exact = backlash::testing::exact_case(spec);
    const auto chosen = backlash::numeric::select_branches(p);
    const std::string exact_contact = exact.contact_branch;
    const std::string exact_free = exact.free_branch;
    const std::string own = backlash::numeric::branch_name(rep.branch);
    EXPECT_TRUE(own == exact_contact || own == exact_free)
        << "representative of " << own << " is classified " << exact_contact << "/" << exact_free;
    EXPECT_EQ(backlash::numeric::branch_name(chosen.contact), exact_contact);
    EXPECT_EQ(backlash::numeric::branch_name(chosen.free), exact_free);
    for (double t : {0.0, 0.7, 3.0, 12.0})
      for (double v0 : {-0.6, 1e-4, 1.1}) {
        const auto direct = backlash::numeric::direct_free_state(chosen.free, p, t, v0);
        const auto stable = backlash::numeric::free_state(p, t, v0);
        const std::pair<const char*, std::pair<const GiNaC::ex*, std::pair<double, double>>> states[] = {
            {"theta_m", {&exact.theta_m, {direct.theta_m, stable.theta_m}}},
            {"dtheta_m", {&exact.dtheta_m, {direct.dtheta_m, stable.dtheta_m}}},
            {"theta_L", {&exact.theta_L, {direct.theta_L, stable.theta_L}}},
            {"dtheta_L", {&exact.dtheta_L, {direct.dtheta_L, stable.dtheta_L}}},
            {"gap", {&exact.gap, {direct.gap, stable.gap}}}};
        for (const auto& [name, entry] : states) {
          const double expected = free_value(*entry.first, t, v0);
          EXPECT_LE(scaled_error(entry.second.first, expected), 1e-11)
              << own << ": direct " << name << "(t = " << t << ", " << v0 << ") returned " << entry.second.first
              << " instead of " << expected;
          EXPECT_LE(scaled_error(entry.second.second, expected), 1e-11)
              << own << ": stable " << name << "(t = " << t << ", " << v0 << ") returned " << entry.second.second
              << " instead of " << expected;
        }
        const double x0 = p.theta_R - 0.7, xd0 = 0.25;
        const auto dc = backlash::numeric::direct_contact_state(chosen.contact, p, t, x0, xd0);
        const auto sc = backlash::numeric::contact_state(p, t, x0, xd0);
        const double eo = contact_value(exact.theta_o, t, x0, xd0), ed = contact_value(exact.dtheta_o, t, x0, xd0);
        EXPECT_LE(scaled_error(dc.theta_o, eo), 1e-11) << own << ": direct theta_o returned " << dc.theta_o << " instead of " << eo;
        EXPECT_LE(scaled_error(dc.dtheta_o, ed), 1e-11) << own << ": direct dtheta_o returned " << dc.dtheta_o << " instead of " << ed;
        EXPECT_LE(scaled_error(sc.theta_o, eo), 1e-11) << own << ": stable theta_o returned " << sc.theta_o << " instead of " << eo;
        EXPECT_LE(scaled_error(sc.dtheta_o, ed), 1e-11) << own << ": stable dtheta_o returned " << sc.dtheta_o << " instead of " << ed;
      }
    const double cot = backlash::symbolic::to_double(exact.cot_phi, {});
    EXPECT_NEAR(backlash::numeric::direct_cot_phi(chosen.free, p), cot, 1e-15);
    EXPECT_NEAR(backlash::numeric::cot_phi(p), cot, 1e-15);
  }
}

}  // namespace
