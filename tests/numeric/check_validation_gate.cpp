// check_validation_gate — every evaluator passes the gate against Boost.Odeint
// (max abs error ≤ 1e-9 per state over each segment's whole horizon), for the
// eight thesis cases (generated, parametric, direct) and every pole-structure
// branch (parametric, direct); the gate refuses an evaluator that is wrong,
// with a clear status, and hands out no ValidatedEvaluator for it.  The reference stopped at
// recombination (the gate's free mode) is the same bits as the whole run up to there.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/parameters.hpp"
#include "backlash/numeric/reference.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using namespace backlash::numeric;

void expect_passes(const EvaluatorPtr& evaluator, const std::string& where) {
  ASSERT_TRUE(evaluator) << where << ": no evaluator";
  const ValidationResult result = validate(evaluator);
  EXPECT_EQ(result.status(), ValidationStatus::Passed) << where << ": " << result.report().evaluator << "\n"
                                                       << result.report().summary();
  for (const StateError& s : result.report().states) {
    EXPECT_LE(s.max_abs_error, 1e-9) << where << ": " << s.state << " max |error| returned " << s.max_abs_error
                                     << " instead of <= 1e-9 (at t = " << s.at_t << ")";
    EXPECT_GT(s.samples, 0) << where << ": " << s.state << " was never compared";
  }
  EXPECT_NO_THROW((void)result.evaluator());
  EXPECT_EQ(result.report().states.size(), 8u);
}

class ThesisCase : public ::testing::TestWithParam<std::string> {};

TEST_P(ThesisCase, generated_parametric_and_direct_evaluators_pass) {
  const backlash::model::CaseSpec spec = backlash::model::load_case(GetParam());
  const EvaluatorPtr generated = case_evaluator(spec);
  EXPECT_EQ(generated->kind(), "case") << "case " << GetParam() << " is not served by its generated header";
  expect_passes(generated, "case " + GetParam() + " generated");
  expect_passes(parametric_evaluator(parameters_of(spec)), "case " + GetParam() + " parametric");
  expect_passes(direct_branch_evaluator(parameters_of(spec)), "case " + GetParam() + " direct");
}

INSTANTIATE_TEST_SUITE_P(Cases, ThesisCase, ::testing::Values("I", "II", "III", "IV", "V", "VI", "VII", "VIII"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return "case_" + info.param; });

class BranchPoint : public ::testing::TestWithParam<int> {};

TEST_P(BranchPoint, parametric_and_direct_evaluators_pass) {
  const BranchRepresentative& rep = branch_representatives().at(static_cast<std::size_t>(GetParam()));
  const std::string name = branch_name(rep.branch);
  const BranchSelection chosen = select_branches(rep.parameters);
  EXPECT_TRUE(chosen.contact == rep.branch || chosen.free == rep.branch)
      << "the dispatcher returned " << branch_name(chosen.contact) << "/" << branch_name(chosen.free) << " instead of "
      << name << " for its representative";
  expect_passes(parametric_evaluator(rep.parameters), "branch " + name + " parametric");
  expect_passes(direct_branch_evaluator(rep.parameters), "branch " + name + " direct");
}

INSTANTIATE_TEST_SUITE_P(Branches, BranchPoint, ::testing::Range(0, branch_count),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::string(branch_name(all_branches().at(static_cast<std::size_t>(info.param))));
                         });

TEST(Branches, every_branch_has_one_representative_in_order) {
  ASSERT_EQ(branch_representatives().size(), static_cast<std::size_t>(branch_count));
  for (int i = 0; i < branch_count; ++i) {
    EXPECT_EQ(branch_representatives()[i].branch, all_branches()[i]);
    EXPECT_EQ(branch_from_name(branch_name(all_branches()[i])), all_branches()[i]);
  }
  EXPECT_FALSE(branch_from_name("no_such_branch").has_value());
}

// An evaluator with a deliberate 1e-6 error in theta_m.
class Wrong final : public SegmentEvaluator {
 public:
  explicit Wrong(EvaluatorPtr inner) : inner_(std::move(inner)) {}
  std::string name() const override { return "wrong theta_m"; }
  std::string kind() const override { return "test"; }
  const Parameters& parameters() const override { return inner_->parameters(); }
  BranchSelection branches() const override { return inner_->branches(); }
  double cot_phi() const override { return inner_->cot_phi(); }
  FreeState free_state(double t, double v0) const override {
    FreeState s = inner_->free_state(t, v0);
    s.theta_m += 1e-6 * t;
    return s;
  }
  ContactState contact_state(double t, double x0, double v0) const override { return inner_->contact_state(t, x0, v0); }

 private:
  EvaluatorPtr inner_;
};

TEST(Gate, refuses_an_evaluator_that_disagrees_with_odeint) {
  const EvaluatorPtr wrong = std::make_shared<Wrong>(generated_case_evaluator("V"));
  const ValidationResult result = validate(wrong);
  EXPECT_EQ(result.status(), ValidationStatus::Failed) << result.report().summary();
  EXPECT_STREQ(to_string(result.status()), "failed");
  bool theta_m_failed = false;
  for (const StateError& s : result.report().states) {
    if (s.state == "theta_m") theta_m_failed = !s.passed;
    else EXPECT_TRUE(s.passed) << s.state << " failed although only theta_m is wrong";
  }
  EXPECT_TRUE(theta_m_failed);
  try {
    (void)result.evaluator();
    ADD_FAILURE() << "a failed evaluator was handed out";
  } catch (const ValidationFailed& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("wrong theta_m"), std::string::npos) << message;
    EXPECT_NE(message.find("theta_m max |error|"), std::string::npos) << message;
  }
}

TEST(Gate, reports_where_the_maximum_error_occurs) {
  const ValidationResult result = validate(std::make_shared<Wrong>(generated_case_evaluator("V")));
  for (const StateError& s : result.report().states)
    if (s.state == "theta_m") {
      // the injected error 1e-6·t is largest at the end of the longest segment
      EXPECT_NEAR(s.max_abs_error, 1e-6 * s.at_t, 1e-9);
      EXPECT_GT(s.at_t, 1.0);
    }
  EXPECT_NE(result.report().summary().find("FAIL"), std::string::npos);
}

TEST(Gate, validated_evaluator_forwards_to_the_evaluator) {
  const ValidationResult result = validate(generated_case_evaluator("III"));
  ASSERT_TRUE(result.passed());
  const ValidatedEvaluator& v = result.evaluator();
  const FreeState a = v.free_state(1.5, 0.2), b = v.evaluator().free_state(1.5, 0.2);
  EXPECT_EQ(a.theta_m, b.theta_m);
  EXPECT_EQ(v.cot_phi(), v.evaluator().cot_phi());
  EXPECT_EQ(v.report().evaluator, "case III (generated)");
}

TEST(Evaluators, case_files_with_other_numbers_get_the_parametric_evaluator) {
  backlash::model::CaseSpec spec = backlash::model::load_case("V");
  spec.FL = backlash::model::Rational(1, 7);
  EXPECT_EQ(case_evaluator(spec)->kind(), "parametric");
  EXPECT_EQ(generated_case_evaluator("nope"), nullptr);
  EXPECT_EQ(generated_case_ids(), backlash::model::thesis_case_ids());
}

// The gate stops the free mode's reference at the first sample of recombination
// (validation.cpp): what it compares must be the bits of the run to the end, up to that sample.
TEST(ReferenceTrajectory, stopped_run_is_the_prefix_of_the_whole_run) {
  Parameters p = parameters_of(backlash::model::load_case("V"));
  p.theta_R = 0;
  std::vector<double> times;
  for (int i = 0; i <= 400; ++i) times.push_back(0.1 * i);
  for (const double v0 : {-2.0, -0.3, 1.0, 2.0}) {
    const std::vector<FreeState> whole = reference_free_trajectory(p, v0, times);
    ASSERT_EQ(whole.size(), times.size());
    std::size_t first = 0;  // the first sample whose gap has changed by b/2
    while (first < whole.size() && std::fabs(whole[first].gap) < p.backlash / 2) ++first;
    ASSERT_LT(first, whole.size()) << "v0 = " << v0 << ": the gap never changes by b/2";
    const std::vector<FreeState> stopped = reference_free_trajectory(
        p, v0, times, 1e-12, [&p](const FreeState& s) { return std::fabs(s.gap) >= p.backlash / 2; });
    ASSERT_EQ(stopped.size(), first + 1) << "v0 = " << v0;
    for (std::size_t i = 0; i < stopped.size(); ++i) {
      EXPECT_EQ(stopped[i].theta_m, whole[i].theta_m) << "v0 = " << v0 << ", sample " << i;
      EXPECT_EQ(stopped[i].dtheta_m, whole[i].dtheta_m) << "v0 = " << v0 << ", sample " << i;
      EXPECT_EQ(stopped[i].theta_L, whole[i].theta_L) << "v0 = " << v0 << ", sample " << i;
      EXPECT_EQ(stopped[i].dtheta_L, whole[i].dtheta_L) << "v0 = " << v0 << ", sample " << i;
      EXPECT_EQ(stopped[i].gap, whole[i].gap) << "v0 = " << v0 << ", sample " << i;
    }
  }
}

}  // namespace
