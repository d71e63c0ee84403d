// The event loop at the limit (issue 19, docs/design.md "The event loop"): no closed-form
// evaluation is repeated within an event.
//   item1_no_point_evaluated_twice   on the limit cycles of cases III–VIII (60 s step responses),
//                                    no closed-form evaluation between two events has the arguments
//                                    (t, θ̇m0) or (t, θo0, θ̇o0) of an earlier one: the contact state at a
//                                    separation serves both the spurious-separation check and the
//                                    event, a flight's start x(0) both its search and its certified
//                                    departure (main evaluated each twice: 1 of ~11 evaluations per
//                                    event).
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <set>
#include <string>
#include <utility>

namespace {

using namespace backlash;

// Forwards to `inner`, counting the evaluations whose arguments were already evaluated since `clear`.
class RepeatCountingEvaluator final : public numeric::SegmentEvaluator {
 public:
  explicit RepeatCountingEvaluator(numeric::EvaluatorPtr inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  std::string kind() const override { return inner_->kind(); }
  const numeric::Parameters& parameters() const override { return inner_->parameters(); }
  numeric::BranchSelection branches() const override { return inner_->branches(); }
  double cot_phi() const override { return inner_->cot_phi(); }
  numeric::FreeState free_state(double t, double v0) const override {
    note({0, t, v0, 0});
    return inner_->free_state(t, v0);
  }
  numeric::ContactState contact_state(double t, double x0, double v0) const override {
    note({1, t, x0, v0});
    return inner_->contact_state(t, x0, v0);
  }
  void clear() const { seen_.clear(); }
  mutable long evaluations = 0, repeats = 0;

 private:
  void note(const std::array<double, 4>& call) const {
    ++evaluations;
    if (!seen_.insert(call).second) ++repeats;
  }
  numeric::EvaluatorPtr inner_;
  mutable std::set<std::array<double, 4>> seen_;
};

}  // namespace

TEST(EventLoopRepeats, item1_no_point_evaluated_twice) {
  for (const std::string id : {"III", "IV", "V", "VI", "VII", "VIII"}) {
    const model::CaseSpec spec = model::load_case(id);
    const auto counter = std::make_shared<const RepeatCountingEvaluator>(numeric::case_evaluator(spec));
    const numeric::ValidationResult validated = numeric::validate(counter);
    numeric::SimulationOptions o;
    o.t_end = 60;
    long events = 0, repeats_until_last_event = 0;
    o.event_sink = [&events, &counter, &repeats_until_last_event](const numeric::SimulationEvent&) {
      ++events;
      repeats_until_last_event = counter->repeats;
      counter->clear();
    };
    counter->clear();
    const long evaluations0 = counter->evaluations, repeats0 = counter->repeats;
    numeric::simulate_step(validated.evaluator(), spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0, o);
    // The run's last segment ends at t_end, not at an event: its state at t_end is not counted.
    const long evaluations = counter->evaluations - evaluations0, repeats = repeats_until_last_event - repeats0;
    std::printf("case %-4s %ld events: %ld evaluations, %ld of them repeated within an event\n", id.c_str(), events,
                evaluations, repeats);
    EXPECT_GT(events, 10) << "case " << id;
    EXPECT_EQ(repeats, 0) << "case " << id;
  }
}
