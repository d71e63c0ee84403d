// Issue 19, maps at tens of thousands of points per second: a map point's set-up done once.
//   item_map_point_run_constants_built_once_per_point   a line of case-V points swept with the
//                                                 settle time (each point: its limit cycle's half
//                                                 cycles, the step response, the stop's check — ~5
//                                                 simulate() runs) builds the runs' parameter-set
//                                                 constants (segments, witness modes:
//                                                 numeric/hybrid/run_constants.hpp) once per point,
//                                                 on 1 and on 2 threads, with the same rows;
//   item_map_point_run_constants_follow_the_parameters   runs alternating between two parameter
//                                                 sets give each its own answer, the one of a run
//                                                 on that set alone (the shared constants are
//                                                 never another set's), one set kept per thread.
// Counts and agreement only, never timings (the speed: bench/map_throughput.sh).
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"
#include "backlash/numeric/limit_cycle.hpp"
#include "backlash/numeric/sweep.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace {

using namespace backlash;

numeric::Parameters case_v() {
  numeric::Parameters p = numeric::case_evaluator(model::load_case("V"))->parameters();
  p.theta_R = 0;  // as the map's sweep runs it (error coordinates)
  return p;
}

// 24 points of case V along FL/F ∈ [0, 1] (F = Fm + FL kept): one warm-start series.
std::vector<numeric::SweepPoint> line() {
  const numeric::Parameters base = case_v();
  const double F = base.Fm + base.FL;
  std::vector<numeric::SweepPoint> points;
  for (int k = 0; k < 24; ++k) {
    numeric::SweepPoint point;
    point.series = "V";
    point.x = k / 23.0;
    point.parameters = base;
    point.parameters.FL = F * point.x;
    point.parameters.Fm = F - point.parameters.FL;
    points.push_back(point);
  }
  return points;
}

}  // namespace

TEST(MapPointSetup, item_map_point_run_constants_built_once_per_point) {
  const std::vector<numeric::SweepPoint> points = line();
  const model::CaseSpec spec = model::load_case("V");
  numeric::SweepOptions options;
  options.settle.step = spec.experiment ? static_cast<double>(spec.experiment->step) : 1.0;
  std::vector<std::vector<numeric::SweepRow>> runs;
  for (const int threads : {1, 2}) {
    options.threads = threads;
    options.block = 8;  // 3 blocks: both threads get some
    const long before = numeric::run_constants_built();
    runs.push_back(numeric::run_sweep(points, options));
    const long built = numeric::run_constants_built() - before;
    long searched = 0;
    for (const numeric::SweepRow& row : runs.back()) {
      searched += row.status == numeric::SweepStatus::LimitCycle || row.status == numeric::SweepStatus::None;
      EXPECT_EQ(row.settle.status, "settled") << row.point.x;
    }
    EXPECT_EQ(searched, static_cast<long>(points.size())) << "every point of the line is searched";
    // Each point's runs share one set: built at its first run, by the thread that computes the point.
    EXPECT_EQ(built, searched) << threads << " thread(s)";
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (std::size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(runs[0][i].cycle.separation_velocity, runs[1][i].cycle.separation_velocity) << i;
    EXPECT_EQ(runs[0][i].settle.time, runs[1][i].settle.time) << i;
  }
}

TEST(MapPointSetup, item_map_point_run_constants_follow_the_parameters) {
  numeric::Parameters a = case_v(), b = a;
  b.JL *= 2.5, b.FL *= 0.5;
  const numeric::ValidationResult va = numeric::validate(numeric::parametric_evaluator(a));
  const numeric::ValidationResult vb = numeric::validate(numeric::parametric_evaluator(b));
  ASSERT_TRUE(va.passed() && vb.passed());
  const numeric::LimitCycle alone_a = numeric::find_limit_cycle(va.evaluator());
  const numeric::LimitCycle alone_b = numeric::find_limit_cycle(vb.evaluator());
  ASSERT_NE(alone_a.separation_velocity, alone_b.separation_velocity);
  for (int round = 0; round < 3; ++round) {  // each round starts with b's constants kept (alone_b, hb2)
    const long before = numeric::run_constants_built();
    const numeric::HalfCycle ha = numeric::half_cycle(va.evaluator(), alone_a.separation_velocity, true);
    const numeric::HalfCycle hb = numeric::half_cycle(vb.evaluator(), alone_b.separation_velocity, true);
    EXPECT_EQ(numeric::run_constants_built() - before, 2) << "alternating sets: each run builds its own";
    const numeric::HalfCycle ha2 = numeric::half_cycle(va.evaluator(), alone_a.separation_velocity, true);
    const numeric::HalfCycle ha3 = numeric::half_cycle(va.evaluator(), alone_a.separation_velocity, true);
    EXPECT_EQ(numeric::run_constants_built() - before, 3) << "the same set again: built once";
    const numeric::HalfCycle hb2 = numeric::half_cycle(vb.evaluator(), alone_b.separation_velocity, true);
    EXPECT_EQ(numeric::run_constants_built() - before, 4) << "back to the other set: built again";
    EXPECT_EQ(hb2.v_out, hb.v_out);
    EXPECT_EQ(hb2.extremes.theta_o_max, hb.extremes.theta_o_max);
    for (const numeric::HalfCycle* h : {&ha2, &ha3}) {
      EXPECT_EQ(h->v_out, ha.v_out);
      EXPECT_EQ(h->extremes.theta_o_max, ha.extremes.theta_o_max);
    }
    EXPECT_EQ(std::max(ha.extremes.theta_o_max, -ha.extremes.theta_o_min), alone_a.theta_o_max);  // θR = 0: mirrored
    EXPECT_NE(hb.v_out, ha.v_out);
  }
}
