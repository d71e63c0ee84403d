// The discrepancy search on records as real machines make them (issue 21, second part), on
// records of the INDEPENDENT odeint generator (generator.hpp):
//   Item1*  a bounded search: simulations kept and reused leave the work counted (the budget)
//           and the answer as they were, whichever thread simulated a point first;
//   Item2*  outliers: two spikes side by side (which the isolated-spike test missed) are listed
//           with their sample index and give no weight; an effect under them is still named;
//   Item3*  a pair whose second effect is worthless alone (its single fit at the range's end)
//           is named together: the best single plus one, refitted together.
// Records can be written for a look with main's command line: BACKLASH_WRITE_RECORDS=DIR.
#include "generator.hpp"

#include "backlash/discrepancy/discrepancy.hpp"
#include "backlash/measurements/measured_record.hpp"
#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace backlash;

constexpr double kStep = 0.62;    // case V's experiment
constexpr double kNoise = 0.001;  // σ as a fraction of the step

generated_data::RecordSpec case_v_record(std::uint64_t seed) {
  generated_data::RecordSpec r;
  r.parameters = numeric::parameters_of(model::load_case("V"));
  r.step = kStep;
  r.noise = kNoise;
  r.seed = seed;
  return r;
}

void write(const measurements::MeasuredRecord& data, const std::string& name) {
  if (const char* folder = std::getenv("BACKLASH_WRITE_RECORDS"))
    std::ofstream(std::string(folder) + "/" + name + ".csv") << measurements::format_measured_csv(data);
}

/// Two spikes of ±20 σ side by side at `count` places spread over the record: the samples hit.
std::vector<std::size_t> add_spike_pairs(measurements::MeasuredRecord& data, int count) {
  std::vector<std::size_t> hit;
  const double size = 20 * kNoise * kStep;
  for (int k = 0; k < count; ++k) {
    const std::size_t i = (2 * k + 1) * data.size() / (2 * count) + 3;
    const double sign = k % 2 ? -1 : 1;
    data.theta_out[i] += sign * size;
    data.theta_out[i + 1] += sign * size;
    hit.push_back(i), hit.push_back(i + 1);
  }
  return hit;
}

std::set<std::string> effects_named(const discrepancy::DiscrepancyResult& r) {
  std::set<std::string> out;
  for (const discrepancy::Candidate& c : r.effects)
    if (!discrepancy::is_parameter_correction(c.effect)) out.insert(c.effect);
  return out;
}

// ------------------------------------------------------------------ item 1

TEST(SearchItem1, item1_kept_simulations_leave_the_work_and_the_answer_as_they_were) {
  // Kept simulations are charged again, so the work — the budget's count — and everything the
  // search says are the same with one thread or two (which thread simulates a point first, and
  // so which finds it kept, changes from run to run).
  generated_data::RecordSpec spec = case_v_record(21);
  spec.effects.torque_offset = 0.04 * numeric::parameters_of(model::load_case("V")).K * kStep;
  const measurements::MeasuredRecord data = generated_data::generate_record(spec);
  discrepancy::DiscrepancyOptions options;
  options.candidates = {"torque_offset", "saturation", "coulomb_load"};
  options.parameters = {"load.J", "K"};
  options.threads = 1;
  const discrepancy::DiscrepancyResult one = discrepancy::find_discrepancy(model::load_case("V"), data, kStep, options);
  options.threads = 2;
  const discrepancy::DiscrepancyResult two = discrepancy::find_discrepancy(model::load_case("V"), data, kStep, options);
  EXPECT_TRUE(one.reason.empty()) << one.reason;
  EXPECT_STREQ(discrepancy::to_string(one.status), "effect_found");
  EXPECT_EQ(one.work, two.work);
  EXPECT_EQ(one.simulations, two.simulations);
  EXPECT_EQ(one.gap_after, two.gap_after);
  ASSERT_EQ(one.rounds.size(), two.rounds.size());
  for (std::size_t k = 0; k < one.rounds.size(); ++k) {
    ASSERT_EQ(one.rounds[k].size(), two.rounds[k].size());
    for (std::size_t i = 0; i < one.rounds[k].size(); ++i) {
      EXPECT_EQ(one.rounds[k][i].effect, two.rounds[k][i].effect);
      EXPECT_EQ(one.rounds[k][i].simulations, two.rounds[k][i].simulations) << one.rounds[k][i].effect;
      EXPECT_EQ(one.rounds[k][i].bic, two.rounds[k][i].bic) << one.rounds[k][i].effect;
    }
  }
}

// ------------------------------------------------------------------ item 2

TEST(SearchItem2, item2_spikes_side_by_side_are_listed_and_the_clean_record_is_quiet) {
  measurements::MeasuredRecord data = generated_data::generate_record(case_v_record(22));
  const std::vector<std::size_t> hit = add_spike_pairs(data, 8);
  write(data, "clean_with_spike_pairs");
  const discrepancy::DiscrepancyResult r = discrepancy::find_discrepancy(model::load_case("V"), data, kStep);
  EXPECT_STREQ(discrepancy::to_string(r.status), "no_discrepancy") << "gap " << r.gap_before;
  std::vector<std::size_t> listed;
  for (const discrepancy::Outlier& o : r.outliers) {
    listed.push_back(o.index);
    EXPECT_DOUBLE_EQ(o.t, data.t[o.index]);
    EXPECT_GT(std::fabs(o.size), 10) << "at t = " << o.t;  // ±20 σ, seen against a neighbour spiked alike
  }
  EXPECT_EQ(listed, hit);
}

TEST(SearchItem2, item2_an_effect_under_spikes_side_by_side_is_named) {
  // The "outliers + saturation": the limit within 5 % (its σ on a clean record is ~0.1 %).
  generated_data::RecordSpec spec = case_v_record(23);
  const double limit = 0.5 * numeric::parameters_of(model::load_case("V")).K * kStep;
  spec.effects.saturation = limit;
  measurements::MeasuredRecord data = generated_data::generate_record(spec);
  add_spike_pairs(data, 8);
  write(data, "saturation_with_spike_pairs");
  const discrepancy::DiscrepancyResult r = discrepancy::find_discrepancy(model::load_case("V"), data, kStep);
  EXPECT_STREQ(discrepancy::to_string(r.status), "effect_found");
  ASSERT_EQ(effects_named(r), std::set<std::string>{"saturation"});
  EXPECT_TRUE(r.parameter_corrections.empty());
  EXPECT_NEAR(r.effects.front().parameters.front().value, limit, 0.05 * limit);
}

// ------------------------------------------------------------------ item 3

TEST(SearchItem3, item3_a_partner_worthless_alone_is_named_with_the_best_single) {
  // A delay and Coulomb friction on the load: alone the friction's fit ends at the bottom of its
  // range (ΔBIC > 0), the delay's is decisive but leaves 10 σ; fitted together they meet the record.
  generated_data::RecordSpec spec = case_v_record(100);
  const numeric::Parameters p = spec.parameters;
  spec.effects.coulomb_load = 0.05 * p.K * kStep;
  spec.effects.delay = 0.03 * numeric::servo_period(p);
  const measurements::MeasuredRecord data = generated_data::generate_record(spec);
  write(data, "coulomb_load_and_delay");
  const discrepancy::DiscrepancyResult r = discrepancy::find_discrepancy(model::load_case("V"), data, kStep);
  EXPECT_STREQ(discrepancy::to_string(r.status), "effect_found") << "gap after " << r.gap_after;
  EXPECT_EQ(effects_named(r), (std::set<std::string>{"coulomb_load", "delay"}));
  EXPECT_TRUE(r.parameter_corrections.empty());
}

}  // namespace
