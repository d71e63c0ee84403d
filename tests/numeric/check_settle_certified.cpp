// The settle time's step response stopped once certified on its cycle (issue 19, maps at tens of
// thousands of points per second; settle.hpp, "Certified on the cycle"):
//   item_map_settle_stops_on_cycle_same_answers   on random parameter sets around the thesis's
//                                                 cases with a cycle (the map's parametric
//                                                 evaluator, θR random) and bands from tight to
//                                                 wide, settle_time gives the status, time and band
//                                                 of the run to t_end (SettleOptions::stop_on_cycle
//                                                 off), and of the definition on every sample; and
//                                                 it does stop early (the point of it), never before
//                                                 the last sample outside the band;
//   item_map_settle_not_stopped_without_a_stable_cycle   no stop where the certificate does not
//                                                 apply: no cycle (the motion comes to rest), or a
//                                                 band the cycle's own swing leaves no room in.
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/settle.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace backlash;

// θo at k·h of the step response to t_end, every sample.
std::vector<double> every_sample(const numeric::ValidatedEvaluator& e, const numeric::SettleOptions& s) {
  std::vector<double> out;
  numeric::SimulationOptions o;
  o.t_end = s.t_end;
  o.sample_interval = s.t_end / s.samples;
  o.sample_sink = [&out](const numeric::TrajectorySample& x) { out.push_back(x.theta_o); };
  const numeric::SimulationResult r = numeric::simulate_step(e, s.step, o);
  EXPECT_FALSE(numeric::stopped_early(r.status)) << r.stop_reason;
  return out;
}

// The same result, bit for bit (NaN equal to NaN).
void expect_same(const numeric::Settle& a, const numeric::Settle& b, const std::string& what) {
  EXPECT_EQ(a.status, b.status) << what;
  EXPECT_TRUE(a.time == b.time || (std::isnan(a.time) && std::isnan(b.time))) << what << ": " << a.time << " vs " << b.time;
  EXPECT_EQ(a.band_low, b.band_low) << what;
  EXPECT_EQ(a.band_high, b.band_high) << what;
}

struct Drawn {
  numeric::Parameters p;
  double step;
  std::string name;
};

// Parameter sets around cases III–VIII: each inertia, friction and K times a log-uniform factor
// in [1/2, 2] (every fifth without load friction), θR uniform in [−5, 5], the step times a
// log-uniform factor in [1/3, 3] — the ranges a design map sweeps.
std::vector<Drawn> drawn(int count) {
  std::mt19937 random(19);
  std::uniform_real_distribution<double> log_factor(std::log(0.5), std::log(2.0)), reference(-5, 5),
      log_step(std::log(1.0 / 3), std::log(3.0));
  const std::vector<std::string> ids = {"III", "IV", "V", "VI", "VII", "VIII"};
  std::vector<Drawn> out;
  for (int i = 0; i < count; ++i) {
    const std::string id = ids[static_cast<std::size_t>(i) % ids.size()];
    const model::CaseSpec spec = model::load_case(id);
    numeric::Parameters p = numeric::case_evaluator(spec)->parameters();
    for (double* x : {&p.Jm, &p.Fm, &p.JL, &p.FL, &p.K}) *x *= std::exp(log_factor(random));
    if (i % 5 == 4) p.FL = 0;
    p.theta_R = reference(random);
    const double step = (spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0) * std::exp(log_step(random));
    out.push_back({p, step, "case " + id + " #" + std::to_string(i)});
  }
  return out;
}

}  // namespace

TEST(SettleCertified, item_map_settle_stops_on_cycle_same_answers) {
  int cycles = 0, stopped = 0, compared = 0;
  for (const Drawn& d : drawn(150)) {
    const numeric::ValidationResult v = numeric::validate(numeric::parametric_evaluator(d.p));
    if (!v.passed()) continue;
    const numeric::ValidatedEvaluator& e = v.evaluator();
    const numeric::LimitCycle cycle = numeric::find_limit_cycle(e);
    cycles += cycle.status == numeric::CycleStatus::LimitCycle;
    for (double fraction : {0.005, 0.02, 0.1}) {
      numeric::SettleOptions o;
      o.step = d.step;
      o.fraction = fraction;
      const numeric::Settle fast = numeric::settle_time(e, cycle, o);
      numeric::SettleOptions full_options = o;
      full_options.stop_on_cycle = false;
      const numeric::Settle full = numeric::settle_time(e, cycle, full_options);
      const std::string what = d.name + ", fraction " + std::to_string(fraction);
      expect_same(fast, full, what);
      EXPECT_TRUE(std::isnan(full.stopped_at)) << what;
      // The definition (settle.hpp) on every sample.
      const std::vector<double> theta_o = every_sample(e, o);
      const auto inside = [&fast](double x) { return x >= fast.band_low && x <= fast.band_high; };
      std::size_t n = theta_o.size();
      while (n > 0 && inside(theta_o[n - 1])) --n;
      const bool settled = inside(theta_o.back());
      EXPECT_EQ(fast.status, settled ? "settled" : "not_settled") << what;
      if (settled) {
        EXPECT_EQ(fast.time, static_cast<double>(n) * o.t_end / o.samples) << what;
      }
      ++compared;
      if (std::isnan(fast.stopped_at)) continue;
      ++stopped;
      EXPECT_EQ(fast.status, "settled") << what;
      EXPECT_GE(fast.stopped_at, fast.time - o.t_end / o.samples) << what << ": stopped before the last sample outside";
      EXPECT_LT(fast.stopped_at, o.t_end) << what;
    }
  }
  std::printf("%d settle times compared, %d stopped early; %d of the parameter sets with a cycle\n", compared, stopped, cycles);
  EXPECT_GE(cycles, 75);
  EXPECT_GE(stopped, compared / 3);  // the 2 % and 10 % bands of most cycles certify well before 60 s
}

TEST(SettleCertified, item_map_settle_not_stopped_without_a_stable_cycle) {
  // Cases I and II: no cycle (the backlash is outside the loop); the response comes to rest.
  for (const std::string id : {"I", "II"}) {
    const model::CaseSpec spec = model::load_case(id);
    const numeric::ValidationResult v = numeric::validate(numeric::case_evaluator(spec));
    ASSERT_TRUE(v.passed()) << id;
    const numeric::LimitCycle cycle = numeric::find_limit_cycle(v.evaluator());
    ASSERT_NE(cycle.status, numeric::CycleStatus::LimitCycle) << id;
    numeric::SettleOptions o;
    o.step = spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0;
    const numeric::Settle s = numeric::settle_time(v.evaluator(), cycle, o);
    EXPECT_TRUE(std::isnan(s.stopped_at)) << id;
  }
  // Case V with a band narrower than nothing: fraction 0 leaves no room beyond the cycle's swing.
  const model::CaseSpec spec = model::load_case("V");
  const numeric::ValidationResult v = numeric::validate(numeric::case_evaluator(spec));
  const numeric::LimitCycle cycle = numeric::find_limit_cycle(v.evaluator());
  ASSERT_EQ(cycle.status, numeric::CycleStatus::LimitCycle);
  numeric::SettleOptions o;
  o.step = static_cast<double>(spec.experiment->step);
  o.fraction = 0;
  const numeric::Settle s = numeric::settle_time(v.evaluator(), cycle, o);
  EXPECT_TRUE(std::isnan(s.stopped_at));
  numeric::SettleOptions full = o;
  full.stop_on_cycle = false;
  expect_same(s, numeric::settle_time(v.evaluator(), cycle, full), "case V, fraction 0");
}
