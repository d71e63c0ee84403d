// check_reference_reuse — the gate's odeint references (numeric/reference.hpp) as the map's gate
// reuses them: (1) the reference run, whole or stopped at a sample (the free mode at
// recombination), is Boost.Odeint's own integrate_times on the same stepper, bit for bit, on
// random systems; (2) a contact reference kept from an earlier call on the thread (a hit) is the
// same bits as one computed afresh on a new thread, and an input that differs in any one number
// (one part in 1e9, or −0 for 0) is not taken for a kept one.
#include "backlash/numeric/parameters.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/reference.hpp"

#include <boost/numeric/odeint.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

namespace {

using namespace backlash::numeric;
namespace odeint = boost::numeric::odeint;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_bits(const std::vector<ContactState>& a, const std::vector<ContactState>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i].theta_o, b[i].theta_o) || !same_bits(a[i].dtheta_o, b[i].dtheta_o)) return false;
  return true;
}

Parameters random_parameters(std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.05, 1.0);
  Parameters p;
  p.Jm = unit(random), p.JL = unit(random), p.Fm = unit(random) * 0.5, p.FL = unit(random) * 0.5;
  p.K = 0.5 + unit(random) * 4, p.backlash = 0.3, p.theta_R = 0;
  return p;
}

// Times from 0 to an end in [1, 4) (the reference's own time unit is then 1: no rescaling).
std::vector<double> random_times(std::mt19937_64& random) {
  std::uniform_real_distribution<double> end(1.0, 4.0);
  const double last = end(random);
  const int n = 50 + static_cast<int>(random() % 200);
  std::vector<double> times;
  for (int i = 0; i <= n; ++i) times.push_back(last * i / n);
  return times;
}

// The contact reference as Boost.Odeint's integrate_times computes it (the reference's stepper,
// tolerances and first step: reference.hpp).
std::vector<ContactState> odeint_contact(const Parameters& p, double x0, double v0, const std::vector<double>& times) {
  const double K = p.K, R = p.theta_R, F = p.Fm + p.FL, J = p.Jm + p.JL;
  auto system = [=](const std::array<double, 2>& x, std::array<double, 2>& dx, double) {
    dx[0] = x[1];
    dx[1] = (K * (R - x[0]) - F * x[1]) / J;
  };
  std::array<double, 2> x{x0, v0};
  std::vector<ContactState> out;
  auto stepper = odeint::make_dense_output(1e-12, 1e-12, odeint::runge_kutta_dopri5<std::array<double, 2>>());
  odeint::integrate_times(stepper, system, x, times.begin(), times.end(), std::min(1e-3, times.back() * 1e-4),
                          [&out](const std::array<double, 2>& s, double) { out.push_back({s[0], s[1]}); });
  return out;
}

std::vector<FreeState> odeint_free(const Parameters& p, double v0, const std::vector<double>& times) {
  auto system = [p](const std::array<double, 4>& x, std::array<double, 4>& dx, double) {
    const double drive = p.K * (p.theta_R - x[2]);  // measured at the load
    dx[0] = x[1];
    dx[1] = (drive - p.Fm * x[1]) / p.Jm;
    dx[2] = x[3];
    dx[3] = -(p.FL / p.JL) * x[3];
  };
  const double theta0 = p.theta_R + cot_phi(p) * v0;
  std::array<double, 4> x{theta0, v0, theta0, v0};
  std::vector<FreeState> out;
  auto stepper = odeint::make_dense_output(1e-12, 1e-12, odeint::runge_kutta_dopri5<std::array<double, 4>>());
  odeint::integrate_times(stepper, system, x, times.begin(), times.end(), std::min(1e-3, times.back() * 1e-4),
                          [&out](const std::array<double, 4>& s, double) { out.push_back({s[0], s[1], s[2], s[3], s[2] - s[0]}); });
  return out;
}

TEST(ReferenceRun, takes_odeint_integrate_times_steps_bit_for_bit) {
  std::mt19937_64 random(191128);
  std::uniform_real_distribution<double> start(-2.0, 2.0);
  for (int trial = 0; trial < 40; ++trial) {
    Parameters p = random_parameters(random);
    p.measured_at = backlash::model::MeasuredAt::Load;
    const std::vector<double> times = random_times(random);
    const double x0 = start(random), v0 = start(random);
    ASSERT_TRUE(same_bits(reference_contact_trajectory(p, x0, v0, times), odeint_contact(p, x0, v0, times))) << trial;
    const std::vector<FreeState> ours = reference_free_trajectory(p, v0, times), theirs = odeint_free(p, v0, times);
    ASSERT_EQ(ours.size(), theirs.size()) << trial;
    for (std::size_t i = 0; i < ours.size(); ++i)
      for (const auto member : {&FreeState::theta_m, &FreeState::dtheta_m, &FreeState::theta_L, &FreeState::dtheta_L})
        ASSERT_TRUE(same_bits(ours[i].*member, theirs[i].*member)) << trial << ", sample " << i;
    // Stopped at a random sample: the prefix of the whole run, ending there.
    const std::size_t stop = random() % ours.size();
    std::size_t seen = 0;
    const std::vector<FreeState> stopped =
        reference_free_trajectory(p, v0, times, 1e-12, [&seen, stop](const FreeState&) { return seen++ == stop; });
    ASSERT_EQ(stopped.size(), stop + 1) << trial;
    for (std::size_t i = 0; i < stopped.size(); ++i) ASSERT_TRUE(same_bits(stopped[i].gap, ours[i].gap)) << trial;
  }
}

struct Request {
  Parameters p;
  double x0, v0;
  std::vector<double> times;
  double tolerance;
};

std::vector<ContactState> on_a_new_thread(const Request& r) {
  std::vector<ContactState> out;
  std::thread([&] { out = reference_contact_trajectory(r.p, r.x0, r.v0, r.times, r.tolerance); }).join();
  return out;
}

// One number of the request moved: by one part in 1e9, or 0 to −0 (a start at rest).
Request moved(Request r, int which) {
  const double f = 1 + 1e-9;
  switch (which) {
    case 0: r.p.K *= f; break;
    case 1: r.p.theta_R = r.p.theta_R == 0 ? 1e-9 : r.p.theta_R * f; break;
    case 2: r.p.Fm *= f; break;  // F = Fm + FL
    case 3: r.p.JL *= f; break;  // J = Jm + JL
    case 4: r.x0 = r.x0 == 0 ? -0.0 : r.x0 * f; break;
    case 5: r.v0 = r.v0 == 0 ? -0.0 : r.v0 * f; break;
    case 6: r.times.back() *= f; break;
    default: r.tolerance *= 10; break;
  }
  return r;
}

TEST(ContactReference, kept_references_are_the_bits_of_fresh_ones) {
  std::mt19937_64 random(20261128);
  std::uniform_real_distribution<double> start(-1.5, 1.5);
  std::vector<Request> pool;  // a few systems and starts, asked for again and again (hits and evictions)
  for (int k = 0; k < 12; ++k) {
    Request r{random_parameters(random), k % 4 == 0 ? 0.0 : start(random), k % 3 == 0 ? 0.0 : start(random),
              random_times(random), 1e-12};
    r.p.theta_R = 0.1 * (k + 1);  // away from the start: every run moves
    pool.push_back(r);
  }
  std::vector<std::vector<ContactState>> fresh;
  for (const Request& r : pool) fresh.push_back(on_a_new_thread(r));
  for (int ask = 0; ask < 150; ++ask) {
    const std::size_t k = random() % pool.size();
    const Request& r = pool[k];
    const std::vector<ContactState> kept = reference_contact_trajectory(r.p, r.x0, r.v0, r.times, r.tolerance);
    ASSERT_TRUE(same_bits(kept, fresh[k])) << "request " << k << ", ask " << ask;
    if (ask % 5 == 0) {  // a near twin right after the original: its own run, never the kept one
      const Request twin = moved(r, static_cast<int>(random() % 8));
      const std::vector<ContactState> expected = on_a_new_thread(twin);
      ASSERT_FALSE(same_bits(expected, fresh[k])) << "the test's twin of request " << k << " has the same run";
      ASSERT_TRUE(same_bits(reference_contact_trajectory(twin.p, twin.x0, twin.v0, twin.times, twin.tolerance), expected))
          << "request " << k << "'s twin was answered with another run";
    }
  }
}

}  // namespace
