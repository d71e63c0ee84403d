// The closed-form simulator's event loop at the limit (issue 19, docs/design.md "The event loop"):
// counts, not timings.
//   item1_no_allocation_per_event         a run with ten times the events allocates no more than a
//                                         short one: the steady loop (certified searches, flights,
//                                         impacts, the Zeno window) allocates nothing per event;
//   item1_evaluations_independent_of_horizon
//                                         the closed-form evaluations per event over the same first
//                                         events are the same for t_end = 60 s and 60,000 s (the first
//                                         search interval comes from the mode's own time scale, not
//                                         from t_end).
// tests/support/counting_operator_new.hpp counts every heap allocation of this binary (the library's too).
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/validation.hpp"
#include "counting_evaluator.hpp"
#include "counting_operator_new.hpp"  // counts every heap allocation (one TU only)

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <new>
#include <string>


namespace {

using namespace backlash;

using backlash::testing::CountingEvaluator;

struct Counted {
  std::shared_ptr<const CountingEvaluator> counter;
  numeric::ValidationResult validated;
  double step;
};

Counted& counted_case(const std::string& id) {
  static std::map<std::string, std::unique_ptr<Counted>> cache;
  auto& slot = cache[id];
  if (!slot) {
    const model::CaseSpec spec = model::load_case(id);
    auto counter = std::make_shared<const CountingEvaluator>(numeric::case_evaluator(spec));
    const double step = spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0;
    slot = std::make_unique<Counted>(Counted{counter, numeric::validate(counter), step});
  }
  return *slot;
}

struct Cost {
  long events = 0, allocations = 0, evaluations = 0;
};

// One step response with the events sunk (not kept), counting what the run itself costs.
Cost run(const std::string& id, double t_end, long max_events) {
  Counted& c = counted_case(id);
  numeric::SimulationOptions o;
  o.t_end = t_end;
  o.max_events = max_events;
  Cost cost;
  o.event_sink = [&cost](const numeric::SimulationEvent&) { ++cost.events; };
  const numeric::ValidatedEvaluator& evaluator = c.validated.evaluator();
  const long evaluations0 = c.counter->evaluations;
  const long allocations0 = backlash::testing::heap_allocations.load();
  const numeric::SimulationResult r = numeric::simulate_step(evaluator, c.step, o);
  cost.allocations = backlash::testing::heap_allocations.load() - allocations0;
  cost.evaluations = c.counter->evaluations - evaluations0;
  EXPECT_FALSE(numeric::stopped_early(r.status) && r.status != numeric::SimulationStatus::EventLimit) << r.stop_reason;
  return cost;
}

}  // namespace

TEST(EventLoopCost, item1_no_allocation_per_event) {
  for (const std::string id : {"III", "IV", "V", "VI", "VII", "VIII"}) {
    const Cost short_run = run(id, 60, 100000), long_run = run(id, 600, 100000);
    std::printf("case %-4s 60 s: %ld events, %ld allocations; 600 s: %ld events, %ld allocations\n", id.c_str(),
                short_run.events, short_run.allocations, long_run.events, long_run.allocations);
    ASSERT_GT(long_run.events, 5 * short_run.events) << "case " << id << ": a limit cycle keeps producing events";
    EXPECT_EQ(long_run.allocations, short_run.allocations) << "case " << id;
  }
}

TEST(EventLoopCost, item1_evaluations_independent_of_horizon) {
  for (const std::string id : {"I", "II", "III", "IV", "V", "VI", "VII", "VIII"}) {
    const long events = id == "I" || id == "II" ? 3 : 30;
    const Cost near = run(id, 60, events), far = run(id, 60000, events);
    std::printf("case %-4s first %ld events: %.1f evaluations per event to 60 s, %.1f to 60000 s\n", id.c_str(), events,
                static_cast<double>(near.evaluations) / near.events, static_cast<double>(far.evaluations) / far.events);
    EXPECT_EQ(near.events, far.events);
    // The searches halve t_end − t unsampled down to the first length either test could pass at,
    // a length set by the mode; the two horizons' dyadic lengths differ by a factor within
    // [1/2, 2], so the deciding level can shift by one: at most one more node sampled on each side
    // (2 evaluations) in each of an event's at most 2 searches (a flight's two, a contact's one).
    // A search that starts from t_end instead costs ~log2(1000) = 10 levels more per search.
    const double per_event_near = static_cast<double>(near.evaluations) / near.events;
    const double per_event_far = static_cast<double>(far.evaluations) / far.events;
    EXPECT_LE(std::fabs(per_event_far - per_event_near), 4.0) << "case " << id;
  }
}
