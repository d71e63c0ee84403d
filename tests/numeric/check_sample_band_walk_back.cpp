// The sample band's walk back over pending segments between θo's turns (issue 19, map throughput;
// TrajectoryRecorder::defer_last_outside and flush, numeric/hybrid/trajectory_recorder.cpp):
//   item1_walk_back_keeps_the_definitions_samples   on random runs of damped oscillations of θo
//                                                   (segments with their closed-form turns, bands
//                                                   and margins from tight to wide), the recorder
//                                                   records exactly the samples the walk sample by
//                                                   sample records (no turns given), among them every
//                                                   one the definition needs — the last one certainly
//                                                   outside the band and every later one that may be
//                                                   outside — bit for bit, in time order, each once,
//                                                   and counts the others as left out; and it
//                                                   evaluates fewer samples than that walk (the point).
#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/hybrid_simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

namespace {

using namespace backlash;
using numeric::HybridState;
using numeric::TrajectoryRecorder;

// θo(τ) = c + A e^{−ατ} cos(ωτ + φ) on [0, duration]: both shafts at θo, so that measured() reads
// it whichever shaft the parameters measure.
struct Segment {
  double t0, duration, c, A, alpha, omega, phi;
  double theta_o(double tau) const { return c + A * std::exp(-alpha * tau) * std::cos(omega * tau + phi); }
  HybridState at(double tau) const {
    const double o = theta_o(tau);
    return HybridState{o, 0, o, 0, true, -1};
  }
  // The zeros of θ̇o in (0, duration), ascending: ωτ + φ = atan(−α/ω) + jπ; −1 past `capacity`.
  int turns(double* out, int capacity) const {
    const double base = std::atan(-alpha / omega);
    int n = 0;
    for (long j = static_cast<long>(std::floor((phi - base) / M_PI)) - 1;; ++j) {
      const double tau = (base + static_cast<double>(j) * M_PI - phi) / omega;
      if (tau <= 0) continue;
      if (tau >= duration) return n;
      if (n == capacity) return -1;
      out[n++] = tau;
    }
  }
};

struct Recorded {
  std::vector<std::pair<double, double>> samples;  // (t, θo) as the sink saw them
  long long left_out = 0;
  long evaluations = 0;  // of θo, at the pending walks and at the segments' last samples
};

Recorded record(const numeric::Parameters& p, double h, const std::vector<Segment>& run,
                const TrajectoryRecorder::BandTest& band, bool with_turns) {
  Recorded out;
  numeric::SimulationOptions o;
  o.sample_interval = h;
  o.sample_sink = [&out](const numeric::TrajectorySample& s) { out.samples.push_back({s.t, s.theta_o}); };
  numeric::SimulationResult r;
  TrajectoryRecorder recorder(p, o, r);
  for (const Segment& s : run) {
    std::array<double, TrajectoryRecorder::kMaxTurns> times;
    const int count = with_turns ? s.turns(times.data(), static_cast<int>(times.size())) : -1;
    const auto at = [s, &out](double tau) {
      ++out.evaluations;
      return s.at(tau);
    };
    recorder.defer_last_outside(s.t0, s.t0 + s.duration, at, band, times.data(), count);
  }
  recorder.flush(band);
  out.left_out = r.samples_left_out;
  return out;
}

}  // namespace

TEST(SampleBandWalkBack, item1_walk_back_keeps_the_definitions_samples) {
  const numeric::Parameters p = numeric::case_evaluator(model::load_case("V"))->parameters();
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0, 1);
  long walked_plain = 0, walked = 0, runs_with_bisection = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const double h = 0.01 + 0.05 * u(rng);
    const TrajectoryRecorder::BandTest band{-1, 1, trial % 4 == 0 ? 0.0 : std::pow(10.0, -4 + 3.5 * u(rng))};
    std::vector<Segment> run;
    double t = 0;
    const int segments = 1 + static_cast<int>(12 * u(rng));
    for (int i = 0; i < segments; ++i) {
      Segment s{t, 0.05 + 4 * u(rng), -0.9 + 1.8 * u(rng), 3 * u(rng) * std::pow(0.7, i), 0.6 * u(rng),
                1 + 8 * u(rng), 2 * M_PI * u(rng)};
      run.push_back(s);
      t += s.duration;
    }
    // The definition: the run's samples k·h (each in the segment that holds it: t0 < k·h ≤ t0 + duration,
    // the first also at 0), the last one certainly outside and every later one that may be outside.
    std::vector<std::pair<double, double>> all;
    for (long long k = 0;; ++k) {
      const double tk = static_cast<double>(k) * h;
      const Segment* s = nullptr;
      for (const Segment& c : run)
        if (tk <= c.t0 + c.duration && (tk > c.t0 || (k == 0 && c.t0 == 0))) {
          s = &c;
          break;
        }
      if (!s) break;
      all.push_back({tk, s->theta_o(tk - s->t0)});
    }
    std::size_t from = 0;
    for (std::size_t i = 0; i < all.size(); ++i)
      if (band.outside(all[i].second)) from = i;
    std::vector<std::pair<double, double>> expected;
    for (std::size_t i = from; i < all.size(); ++i)
      if (band.may_be_outside(all[i].second)) expected.push_back(all[i]);

    const Recorded got = record(p, h, run, band, true), plain = record(p, h, run, band, false);
    ASSERT_EQ(got.samples, plain.samples) << "trial " << trial;
    // Every one the definition needs, each a sample of the run bit for bit, in time order.
    std::size_t i = 0, j = 0;
    for (; i < got.samples.size(); ++i) {
      while (j < all.size() && all[j].first < got.samples[i].first) ++j;
      ASSERT_TRUE(j < all.size() && all[j] == got.samples[i]) << "trial " << trial << ": sample at t = " << got.samples[i].first;
      ++j;
    }
    for (const auto& x : expected)
      EXPECT_TRUE(std::find(got.samples.begin(), got.samples.end(), x) != got.samples.end())
          << "trial " << trial << ": sample at t = " << x.first << " not recorded";
    EXPECT_EQ(got.left_out + static_cast<long long>(got.samples.size()), static_cast<long long>(all.size())) << "trial " << trial;
    EXPECT_EQ(got.left_out, plain.left_out) << "trial " << trial;
    walked += got.evaluations, walked_plain += plain.evaluations;
    runs_with_bisection += got.evaluations < plain.evaluations;
  }
  std::printf("θo evaluated %ld times walking between turns, %ld sample by sample; fewer in %ld runs\n", walked, walked_plain,
              runs_with_bisection);
  EXPECT_LT(2 * walked, walked_plain);
}
