// The event loop at the limit (issue 19, docs/design.md "The event loop"): no closed-form
// evaluation is repeated within an event.
//   item1_no_point_evaluated_twice   on the limit cycles of cases III–VIII (60 s step responses),
//                                    no closed-form evaluation between two events has the arguments
//                                    (t, θ̇m0) or (t, θo0, θ̇o0) of an earlier one: the contact state at a
//                                    separation serves both the spurious-separation check and the
//                                    event, a flight's start x(0) both its search and its certified
//                                    departure (main evaluated each twice: 1 of ~11 evaluations per
//                                    event).
#include "counting_evaluator.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

using namespace backlash;

TEST(EventLoopRepeats, item1_no_point_evaluated_twice) {
  for (const std::string id : {"III", "IV", "V", "VI", "VII", "VIII"}) {
    const model::CaseSpec spec = model::load_case(id);
    const auto counter = std::make_shared<const backlash::testing::CountingEvaluator>(numeric::case_evaluator(spec), true);
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
