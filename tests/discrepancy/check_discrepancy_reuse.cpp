// The discrepancy workflow's simulations at the least work that keeps every answer (issue 19,
// "discrepancy in seconds"; docs/discrepancy.md, "Work budget"):
//   item_fits_sample_only_the_fitted_rows  a fit reads only the fitted samples (seven blocks of
//           ten): its simulations compute those and the last one, not the held-out blocks — each
//           sample with the bits the whole grid gives it (nominal, Coulomb friction, restitution,
//           a delay integrated numerically), the same events and the same work counted;
//   item_a_whole_grid_simulation_serves_a_fit  a point simulated on the whole grid is not
//           simulated again for a fit (kept), its work counted again (the budget is a count);
//   item_a_fit_prefix_samples_its_rows  a fit's shorter horizon: the fitted rows below it and its
//           last row, nothing after it;
//   item_a_held_simulation_outlives_the_kept_ones  a simulation held (a screened partner's best
//           point, where its pair's fit starts) serves its point after 300 others have pushed it out
//           of the 256 kept, with the same bits and its work counted again — and, released, no longer.
// On main the simulator computed every sample of every simulation (no Grid): this file does not
// build there.
#include "../../discrepancy/src/internal.hpp"

#include "backlash/model/case_spec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace {

using namespace backlash;
using discrepancy::detail::ModelPoint;
using discrepancy::detail::Observations;
using discrepancy::detail::Simulator;

constexpr double kStep = 0.62;  // case V's experiment

/// A 10 s record at 20 Hz (its values do not matter here: the grid does), cut in ten blocks,
/// the third, sixth and ninth held out (workflow.cpp, split_blocks).
Observations record() {
  Observations o;
  const std::size_t n = 200;
  for (std::size_t i = 0; i < n; ++i) o.t.push_back(0.05 * static_cast<double>(i));
  o.columns = {std::vector<double>(n, 0.0)};
  o.which = {0};
  o.sigma = {1e-3};
  o.quantum = {0};
  o.skip.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t block = 10 * i / n;
    (block % 3 == 2 ? o.holdout_indices : o.fit_indices).push_back(i);
    o.all_indices.push_back(i);
  }
  return o;
}

std::vector<ModelPoint> points() {
  ModelPoint nominal{numeric::parameters_of(model::load_case("V")), {}};
  ModelPoint coulomb = nominal, restitution = nominal, delay = nominal;
  coulomb.e.coulomb_load = 0.05 * nominal.p.K * kStep;
  restitution.e.restitution = 0.6;
  delay.e.delay = 0.03 * numeric::servo_period(nominal.p);
  return {nominal, coulomb, restitution, delay};
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(DiscrepancyReuse, item_fits_sample_only_the_fitted_rows) {
  const Observations o = record();
  for (const ModelPoint& m : points()) {
    SCOPED_TRACE(m.e.describe());
    Simulator whole(o, kStep, o.t.back()), fit(o, kStep, o.t.back());
    std::vector<numeric::SimulationEvent> events_whole, events_fit;
    long cost_whole = 0, cost_fit = 0;
    const auto all = whole.traces(m, o.size(), &events_whole, &cost_whole, Simulator::Grid::all);
    const auto fitted = fit.traces(m, o.size(), &events_fit, &cost_fit, Simulator::Grid::fitted);
    ASSERT_TRUE(all && fitted);
    for (std::size_t i : o.fit_indices) EXPECT_TRUE(same_bits((*all)[0][i], (*fitted)[0][i])) << "row " << i;
    for (std::size_t i : o.holdout_indices) EXPECT_TRUE(std::isnan((*fitted)[0][i])) << "row " << i;
    EXPECT_EQ(cost_whole, cost_fit);
    EXPECT_EQ(whole.work(), fit.work());
    EXPECT_FALSE(events_whole.empty());  // case V's step: contacts and separations within 10 s
    ASSERT_EQ(events_whole.size(), events_fit.size());
    for (std::size_t k = 0; k < events_whole.size(); ++k) EXPECT_TRUE(same_bits(events_whole[k].t, events_fit[k].t));
    // The last row (199) is fitted: the held-out blocks are all that is left out.
    EXPECT_EQ(whole.samples_computed(), static_cast<long>(o.size()));
    EXPECT_EQ(fit.samples_computed(), static_cast<long>(o.fit_indices.size()));
  }
}

TEST(DiscrepancyReuse, item_a_whole_grid_simulation_serves_a_fit) {
  const Observations o = record();
  const ModelPoint m = points()[1];
  Simulator simulator(o, kStep, o.t.back());
  const auto all = simulator.traces(m, o.size());
  const long work = simulator.work(), samples = simulator.samples_computed();
  const auto fitted = simulator.traces(m, o.size(), nullptr, nullptr, Simulator::Grid::fitted);
  ASSERT_TRUE(all && fitted);
  EXPECT_EQ(simulator.cache_hits(), 1);
  EXPECT_EQ(simulator.samples_computed(), samples);
  EXPECT_EQ(simulator.work(), 2 * work);  // charged again: the budget does not depend on what was kept
  EXPECT_EQ(simulator.simulations(), 2);
  // A fit's simulation does not serve the whole grid (its held-out rows were not computed).
  Simulator other(o, kStep, o.t.back());
  (void)other.traces(m, o.size(), nullptr, nullptr, Simulator::Grid::fitted);
  const auto whole = other.traces(m, o.size());
  ASSERT_TRUE(whole);
  EXPECT_EQ(other.cache_hits(), 0);
  for (std::size_t i = 0; i < o.size(); ++i) EXPECT_TRUE(same_bits((*whole)[0][i], (*all)[0][i])) << "row " << i;
}

TEST(DiscrepancyReuse, item_a_fit_prefix_samples_its_rows) {
  const Observations o = record();
  const ModelPoint m = points()[3];  // the delayed model: integrated numerically
  Simulator whole(o, kStep, o.t.back()), fit(o, kStep, o.t.back());
  // A horizon ending in the third block (held out): the fitted rows below and its last row.
  const std::size_t samples = 55;
  const auto all = whole.traces(m, samples);
  const auto fitted = fit.traces(m, samples, nullptr, nullptr, Simulator::Grid::fitted);
  ASSERT_TRUE(all && fitted);
  ASSERT_EQ((*fitted)[0].size(), samples);
  long fitted_below = 0;
  for (std::size_t i = 0; i + 1 < samples; ++i) {
    const bool is_fitted = 10 * i / o.size() % 3 != 2;
    fitted_below += is_fitted;
    if (is_fitted) EXPECT_TRUE(same_bits((*all)[0][i], (*fitted)[0][i])) << "row " << i;
    else EXPECT_TRUE(std::isnan((*fitted)[0][i])) << "row " << i;
  }
  EXPECT_TRUE(same_bits((*all)[0][samples - 1], (*fitted)[0][samples - 1]));
  EXPECT_EQ(fit.samples_computed(), fitted_below + 1);
  EXPECT_EQ(whole.samples_computed(), static_cast<long>(samples));
  EXPECT_EQ(whole.work(), fit.work());
  // A horizon inside the first two blocks (all fitted): the whole grid, one simulation for both.
  Simulator shared(o, kStep, o.t.back());
  (void)shared.traces(m, 30);
  (void)shared.traces(m, 30, nullptr, nullptr, Simulator::Grid::fitted);
  EXPECT_EQ(shared.cache_hits(), 1);
}

TEST(DiscrepancyReuse, item_a_held_simulation_outlives_the_kept_ones) {
  const Observations o = record();
  const ModelPoint m = points()[1];
  Simulator simulator(o, kStep, o.t.back());
  const auto first = simulator.traces(m, o.size(), nullptr, nullptr, Simulator::Grid::fitted);
  ASSERT_TRUE(first);
  Simulator::Held held = simulator.hold(m, o.size(), Simulator::Grid::fitted);
  EXPECT_TRUE(held);
  EXPECT_FALSE(simulator.hold(points()[2], o.size(), Simulator::Grid::fitted));  // never simulated: nothing to hold
  auto push_out = [&](int from) {  // 300 other model points, 20 samples each: more than the 256 kept
    for (int k = from; k < from + 300; ++k) {
      ModelPoint other = m;
      other.e.coulomb_load *= 1 + 1e-3 * (k + 1);
      (void)simulator.traces(other, 20, nullptr, nullptr, Simulator::Grid::fitted);
    }
  };
  push_out(0);
  const long work = simulator.work(), samples = simulator.samples_computed();
  const int hits = simulator.cache_hits();
  const auto again = simulator.traces(m, o.size(), nullptr, nullptr, Simulator::Grid::fitted);
  ASSERT_TRUE(again);
  EXPECT_EQ(simulator.cache_hits(), hits + 1);
  EXPECT_EQ(simulator.samples_computed(), samples);
  EXPECT_GT(simulator.work(), work);  // charged again: the budget does not depend on what was kept
  for (std::size_t i : o.fit_indices) EXPECT_TRUE(same_bits((*again)[0][i], (*first)[0][i])) << "row " << i;
  held.reset();  // released: pushed out like any other
  push_out(300);
  (void)simulator.traces(m, o.size(), nullptr, nullptr, Simulator::Grid::fitted);
  EXPECT_EQ(simulator.samples_computed(), samples + 300 * 20 + static_cast<long>(o.fit_indices.size()));
}

}  // namespace
