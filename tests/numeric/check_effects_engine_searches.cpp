// The effects engine per event (issue 19): a mesh mode's flow, a segment's kept witness constants
// and a free flight's kernels, as the engine's speed-ups left them.
//   compliance_flow_is_the_augmented_exponential
//                                 a mesh mode's flow (its kept eigen-decomposition) is the
//                                 augmented matrix's exponential e^{Mτ} z̃0 (Eigen's Padé) within
//                                 1e-12 of the state's scale, on mesh modes from random starts;
//   check_matrix_exponential_flow_as_dynamic
//                                 a mesh flow by the matrix exponential (a body stuck: the augmented
//                                 matrix is defective) is e^{Mτ} z̃0 formed on Eigen::MatrixXd bit for
//                                 bit (the flow holds M in a heap-free matrix of at most 5×5), from
//                                 random starts and times;
//   check_eigen_flow_as_dynamic   a mesh flow by its eigen-decomposition (kept per thread, its V⁻¹ by
//                                 the fixed-size 5 × 5 LU, |λ_j|³ once per conjugate pair) gives the
//                                 bits of the decomposition formed on Eigen::MatrixXd / MatrixXcd, each
//                                 |λ_j|³ by pow: its states and its bound on |w'''|, from random starts;
//   item_effects_kept_constants_stay_put
//                                 a kept witness's constants stay where they are while they are in use:
//                                 the cache replaces its least recently used entry, so an entry used
//                                 again is not the next one overwritten (main's round robin replaced
//                                 it), and it stays bit for bit WitnessMode(A, c, e);
//   check_kept_constants_by_group
//                                 a segment's witnesses found by A's group (kept_mode_group) get the
//                                 constants of their own A and e, bit for bit, with matrices that differ
//                                 in one element only (each of the 16), segments interleaved at random
//                                 and more entries than the cache holds;
//   free_kernels_as_coupled       a free flight's kernels of one node (phi_pair) are coupled_kernels'
//                                 own, bit for bit;
//   check_conditioning_decided_as_by_the_moduli
//                                 the mesh flow's test of its eigenbasis (bounds on the moduli first)
//                                 answers as the test on the moduli themselves, on random bases with
//                                 the limit placed at, just around and far from their condition;
//   check_mesh_bound_holds        the mesh modes' bound on |w'''| over [a, b] (a conjugate pair's
//                                 exponential formed once) is not below |eᵀA²(A z + c)| anywhere on it;
//   check_sampling_as_before      the sampling's shortcuts give the bits of what they replace (issue 19):
//                                 phi12 is phi(1, ·), phi(2, ·); real_of_product is (a * b).real(),
//                                 with infinities, NaNs and overflow among the operands; a contact
//                                 state is placed at θR + theta_o_error().constant + z(0);
//   check_theta_o_alone_as_the_state
//                                 a flow's θo alone (ModeFlow::measured_at) is measured(p, state(τ)) bit
//                                 for bit, on every contact and free mode of cases I, II (at the motor)
//                                 and V, VIII (at the load) with each motor form, from random starts; a
//                                 run sampling θo alone (SimulationOptions::sample_theta_o_only) has the
//                                 full run's θo samples and events, its other fields NaN — with closed
//                                 forms, a compliant mesh, a delay (rigid and meshed), Stribeck friction;
//                                 a mesh mode's θo alone is its state's on case V's mesh flows.
#include "effects/effect_modes.hpp"
#include "effects/effects_engine.hpp"
#include "evaluators/phi_functions.hpp"

#include "backlash/model/case_spec.hpp"
#include "backlash/numeric/effects_simulation.hpp"
#include "backlash/numeric/evaluator.hpp"
#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/validation.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <complex>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace backlash;

numeric::Effects compliance() {
  numeric::Effects e;
  e.mesh_stiffness = 400;
  e.mesh_damping = 4;
  return e;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Case V with compliance(): `check(mode, flow)` on each mesh mode's flow from `trials` random starts
// (the teeth overlapping on its face by up to 1e-3 rad).
template <class Check>
void for_mesh_flows(std::mt19937& random, int trials, const Check& check) {
  const numeric::Parameters p = numeric::parameters_of(model::load_case("V"));
  const numeric::Effects e = compliance();
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const numeric::Mode& m : numeric::reachable_modes(p, e)) {
    if (m.kind != numeric::ModeKind::Mesh) continue;
    for (int trial = 0; trial < trials; ++trial) {
      numeric::HybridState start;
      start.in_contact = true;
      start.face = m.face;
      start.theta_m = 0.6 + 0.3 * unit(random);
      start.theta_L = start.theta_m + m.face * (p.backlash / 2 + 1e-3 * std::fabs(unit(random)));
      start.dtheta_m = unit(random);
      start.dtheta_L = unit(random);
      check(m, numeric::ModeFlow(p, e, m, start));
    }
  }
}

}  // namespace

TEST(EffectsEngineSearches, compliance_flow_is_the_augmented_exponential) {
  std::mt19937 random(19);
  int checked = 0;
  for_mesh_flows(random, 20, [&checked](const numeric::Mode& m, const numeric::ModeFlow& flow) {
    ASSERT_FALSE(flow.uses_matrix_exponential()) << m.describe();
    const int n = static_cast<int>(flow.segment().A.rows());
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
    M.topLeftCorner(n, n) = flow.segment().A;
    M.block(0, n, n, 1) = flow.segment().c;
    Eigen::VectorXd z0(n + 1);
    z0.head(n) = flow.local_start();
    z0(n) = 1;
    for (double tau : {1e-3, 0.05, 0.4, 2.0}) {
      const Eigen::VectorXd reference = ((M * tau).exp() * z0).head(n);
      const numeric::SmallVector z = flow.local(tau);
      const double scale = std::max(1.0, reference.cwiseAbs().maxCoeff());
      EXPECT_LE((z - reference).cwiseAbs().maxCoeff(), 1e-12 * scale) << m.describe() << ", tau " << tau;
      ++checked;
    }
  });
  EXPECT_GT(checked, 0);
}

TEST(EffectsEngineSearches, check_matrix_exponential_flow_as_dynamic) {
  const numeric::Parameters p = numeric::parameters_of(model::load_case("V"));
  const numeric::Effects e = compliance();
  std::mt19937 random(33);
  std::uniform_real_distribution<double> unit(-1, 1);
  int checked = 0;
  for (int face : {-1, 1})
    for (auto [sm, sl] : {std::pair{0, 1}, std::pair{1, 0}, std::pair{0, -1}, std::pair{-1, 0}})
      for (int trial = 0; trial < 5; ++trial) {
        const numeric::Mode m{numeric::ModeKind::Mesh, face, 0, sm, sl};
        numeric::HybridState start;
        start.in_contact = true;
        start.face = face;
        start.theta_m = 0.6 + 0.3 * unit(random);
        start.theta_L = start.theta_m + face * (p.backlash / 2 + 1e-3 * std::fabs(unit(random)));
        start.dtheta_m = sm == 0 ? 0 : unit(random);
        start.dtheta_L = sl == 0 ? 0 : unit(random);
        const numeric::ModeFlow flow(p, e, m, start);
        ASSERT_TRUE(flow.uses_matrix_exponential()) << m.describe();
        const int n = static_cast<int>(flow.segment().A.rows());
        Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
        M.topLeftCorner(n, n) = flow.segment().A;
        M.block(0, n, n, 1) = flow.segment().c;
        Eigen::Matrix<double, 5, 1> z0 = Eigen::Matrix<double, 5, 1>::Zero();
        z0.head(n) = flow.local_start();
        z0(n) = 1;
        for (double tau : {1e-3 * std::fabs(unit(random)), 0.3 * std::fabs(unit(random)), 20 * std::fabs(unit(random))}) {
          const Eigen::MatrixXd E = (M * tau).exp();
          const numeric::SmallVector reference((E * z0.head(n + 1)).head(n));
          const numeric::SmallVector z = flow.local(tau);
          for (int i = 0; i < n; ++i) EXPECT_TRUE(same_bits(z(i), reference(i))) << m.describe() << ", tau " << tau;
          ++checked;
        }
      }
  EXPECT_EQ(checked, 2 * 4 * 5 * 3);
}

TEST(EffectsEngineSearches, check_eigen_flow_as_dynamic) {
  using Complex = std::complex<double>;
  std::mt19937 random(2019);
  int checked = 0;
  for_mesh_flows(random, 30, [&checked](const numeric::Mode& m, const numeric::ModeFlow& flow) {
    ASSERT_FALSE(flow.uses_matrix_exponential()) << m.describe();
    const int n = static_cast<int>(flow.segment().A.rows()), size = n + 1;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(size, size);
    M.topLeftCorner(n, n) = flow.segment().A;
    M.block(0, n, n, 1) = flow.segment().c;
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(M, true);
    ASSERT_EQ(solver.info(), Eigen::Success);
    const Eigen::MatrixXcd V = solver.eigenvectors();
    const Eigen::VectorXcd lambda = solver.eigenvalues();
    Eigen::Matrix<Complex, 5, 5> inverse = Eigen::Matrix<Complex, 5, 5>::Zero();
    inverse.topLeftCorner(size, size) = Eigen::PartialPivLU<Eigen::MatrixXcd>(V).inverse();
    Eigen::Matrix<double, 5, 1> z0 = Eigen::Matrix<double, 5, 1>::Zero();
    z0.head(n) = flow.local_start();
    z0(n) = 1;
    Eigen::Matrix<Complex, 5, 1> q = Eigen::Matrix<Complex, 5, 1>::Zero();
    q.head(size) = inverse.topLeftCorner(size, size) * z0.head(size).cast<Complex>();
    for (double tau : {1e-3, 0.05, 0.4, 2.0}) {
      const numeric::SmallVector z = flow.local(tau);
      for (int i = 0; i < n; ++i) {
        double sum = 0;
        for (int j = 0; j < size; ++j) sum += numeric::real_of_product(V(i, j), std::exp(lambda(j) * tau) * q(j));
        EXPECT_TRUE(same_bits(z(i), sum)) << m.describe() << ", tau " << tau << ", row " << i;
      }
    }
    const numeric::SmallRow row = numeric::SmallRow::Random(n);
    const auto bound = flow.derivative_bound(row, 3);
    for (auto [a, b] : {std::pair{0.0, 0.1}, std::pair{0.3, 2.0}}) {
      double expected = 0;
      for (int j = 0; j < size; ++j) {
        Complex c = 0;
        for (int i = 0; i < n; ++i) c += row(i) * V(i, j);
        const double rate = lambda(j).real();
        expected += std::abs(c * q(j)) * std::pow(std::abs(lambda(j)), 3) * std::exp(rate * (rate > 0 ? b : a));
      }
      EXPECT_TRUE(same_bits(bound(a, b), expected * (1 + 1e-9) + 1e-300)) << m.describe();
    }
    ++checked;
  });
  EXPECT_GT(checked, 0);
}

TEST(EffectsEngineSearches, item_effects_kept_constants_stay_put) {
  using numeric::SmallMatrix;
  using numeric::SmallRow;
  using numeric::SmallVector;
  std::thread([] {
    constexpr int capacity = 32;  // the cache's (effects_simulation.cpp)
    std::mt19937 random(7);
    std::uniform_real_distribution<double> entry(-2, 2);
    const auto matrix = [&] {
      SmallMatrix A(4, 4);
      for (int i = 0; i < 16; ++i) A.data()[i] = entry(random);
      return A;
    };
    SmallVector c(4);
    c << 1, -2, 0.5, 3;
    SmallRow e(4);
    e << 1, 0, -1, 0;
    std::vector<SmallMatrix> matrices;
    for (int k = 0; k < capacity; ++k) matrices.push_back(matrix());
    for (const SmallMatrix& A : matrices) numeric::detail::kept_witness_mode(A, c, e);
    // The first entry used again, then a new matrix: the entry replaced is not the one just used.
    const numeric::WitnessMode* used = &numeric::detail::kept_witness_mode(matrices[0], c, e);
    numeric::detail::kept_witness_mode(matrix(), c, e);
    const numeric::WitnessMode rebuilt(matrices[0], c, e);
    EXPECT_TRUE(used->A == matrices[0] && used->e == e) << "the entry in use was replaced";
    EXPECT_TRUE(same_bits(used->mu_A, rebuilt.mu_A) && same_bits(used->norm_eA2, rebuilt.norm_eA2) &&
                same_bits(used->eA2c, rebuilt.eA2c));
  }).join();
}

TEST(EffectsEngineSearches, check_kept_constants_by_group) {
  using numeric::SmallMatrix;
  using numeric::SmallRow;
  using numeric::SmallVector;
  std::thread([] {
    std::mt19937 random(23);
    std::uniform_real_distribution<double> entry(-2, 2);
    SmallMatrix base(4, 4);
    for (int i = 0; i < 16; ++i) base.data()[i] = entry(random);
    std::vector<SmallMatrix> matrices{base};
    for (int i = 0; i < 16; ++i) {  // each differs from base in element i alone
      matrices.push_back(base);
      matrices.back().data()[i] += 0.5;
    }
    std::vector<SmallRow> rows(3, SmallRow(4));
    rows[0] << 1, 0, -1, 0;
    rows[1] << 0, 1, 0, -1;
    rows[2] << 0, 1, 0, 0;
    std::uniform_int_distribution<std::size_t> pick(0, matrices.size() - 1);
    for (int segment = 0; segment < 400; ++segment) {
      const SmallMatrix& A = matrices[pick(random)];
      SmallVector c(4);
      for (int i = 0; i < 4; ++i) c(i) = entry(random);
      const std::uint64_t group = numeric::detail::kept_mode_group(A);
      for (std::size_t k = segment % 2 == 0 ? 0 : 1; k < rows.size(); ++k) {
        const numeric::WitnessMode& kept = numeric::detail::kept_witness_mode(group, A, c, rows[k]);
        const numeric::WitnessMode rebuilt(A, c, rows[k]);
        ASSERT_TRUE(kept.A == A && kept.e == rows[k]) << "segment " << segment << " witness " << k;
        ASSERT_TRUE(same_bits(kept.mu_A, rebuilt.mu_A) && same_bits(kept.norm_eA3, rebuilt.norm_eA3) &&
                    same_bits(kept.eAc, rebuilt.eAc) && same_bits(kept.ec, rebuilt.ec))
            << "segment " << segment << " witness " << k;
      }
    }
  }).join();
}

TEST(EffectsEngineSearches, free_kernels_as_coupled) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> exponent(-6, 2), sign(-1, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const double x = -std::pow(10.0, exponent(random)), y = -std::pow(10.0, exponent(random)) * (sign(random) > 0.9 ? -1 : 1);
    const numeric::CoupledKernels k = numeric::coupled_kernels(x, y);
    const numeric::PhiPair px = numeric::phi_pair(x), py = numeric::phi_pair(y);
    EXPECT_TRUE(same_bits(k.exp_x, px.e) && same_bits(k.phi1_x, px.phi1) && same_bits(k.phi2_x, px.phi2)) << x;
    EXPECT_TRUE(same_bits(k.exp_y, py.e) && same_bits(k.phi1_y, py.phi1) && same_bits(k.phi2_y, py.phi2)) << y;
  }
}

TEST(EffectsEngineSearches, check_conditioning_decided_as_by_the_moduli) {
  std::mt19937 random(1919);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> size_of(2, 5), exponent(-8, 8);
  int decided = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = size_of(random);
    Eigen::MatrixXcd V(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) V(i, j) = {unit(random) * std::ldexp(1.0, exponent(random) / 2), unit(random)};
    if (trial % 97 == 0) V(0, 0) = {NAN, 0};
    if (trial % 89 == 0) V(n - 1, 0) = {INFINITY, 1};
    const Eigen::MatrixXcd inverse = Eigen::PartialPivLU<Eigen::MatrixXcd>(V).inverse();
    const double condition = V.cwiseAbs().rowwise().sum().maxCoeff() * inverse.cwiseAbs().rowwise().sum().maxCoeff();
    for (double factor : {1.0, 1 + 1e-15, 1 - 1e-15, 1 + 1e-7, 1 - 1e-7, 1.5, 0.7, 1e3, 1e-3}) {
      const double limit = std::isfinite(condition) ? condition * factor : 1e7 * factor;
      const bool exact = std::isfinite(condition) && condition <= limit;
      EXPECT_EQ(numeric::well_conditioned_basis(V, inverse, limit), exact)
          << "trial " << trial << ", condition " << condition << ", limit " << limit;
      ++decided;
    }
  }
  EXPECT_EQ(decided, 2000 * 9);
}

TEST(EffectsEngineSearches, check_mesh_bound_holds) {
  std::mt19937 random(23), rows(29);
  std::uniform_real_distribution<double> unit(-1, 1);
  int checked = 0;
  for_mesh_flows(random, 10, [&](const numeric::Mode& m, const numeric::ModeFlow& flow) {
    const numeric::SmallMatrix& A = flow.segment().A;
    numeric::SmallRow row(A.rows());
    for (Eigen::Index i = 0; i < row.size(); ++i) row(i) = unit(rows);
    const auto bound = flow.derivative_bound(row, 3);
    ASSERT_TRUE(static_cast<bool>(bound)) << m.describe();
    const numeric::SmallRow third = row * A * A;  // w''' = e A² z'
    for (double a : {0.0, 0.01, 0.3}) {
      const double b = a + 0.05 * (1 + std::fabs(unit(rows)));
      const double M3 = bound(a, b);
      double largest = 0;
      for (int k = 0; k <= 64; ++k) {
        const numeric::SmallVector z = flow.local(a + (b - a) * k / 64);
        const numeric::SmallVector rate = A * z + flow.segment().c;
        double w3 = 0;
        for (Eigen::Index i = 0; i < rate.size(); ++i) w3 += third(i) * rate(i);
        largest = std::max(largest, std::fabs(w3));
      }
      EXPECT_GE(M3, largest * (1 - 1e-9)) << m.describe() << " on [" << a << ", " << b << "]";
      EXPECT_LE(M3, 1e6 * largest + 1e-6) << m.describe() << ": far above |w'''|, every interval would be halved";
      ++checked;
    }
  });
  EXPECT_GT(checked, 0);
}

TEST(EffectsEngineSearches, check_sampling_as_before) {
  std::mt19937 random(1907);
  std::uniform_real_distribution<double> exponent(-8, 3), unit(-1, 1);
  for (int trial = 0; trial < 20000; ++trial) {
    double x = (unit(random) > 0 ? 1 : -1) * std::pow(10.0, exponent(random));
    if (trial % 50 == 0) x = std::nextafter(trial % 100 == 0 ? 1.0 : -1.0, unit(random) > 0 ? 2.0 : -2.0);
    const numeric::Phi12 f = numeric::phi12(x);
    EXPECT_TRUE(same_bits(f.phi1, numeric::phi(1, x)) && same_bits(f.phi2, numeric::phi(2, x))) << x;
  }
  const double specials[] = {0.0, -0.0, 1.0, -2.5, 1e300, -1e300, 1e-300, INFINITY, -INFINITY, NAN};
  std::uniform_int_distribution<int> pick(0, 2 * static_cast<int>(std::size(specials)) - 1);
  const auto entry = [&] {
    const int k = pick(random);
    return k < static_cast<int>(std::size(specials)) ? specials[k] : unit(random) * std::pow(10.0, 4 * exponent(random));
  };
  int recovered = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const std::complex<double> a(entry(), entry()), b(entry(), entry());
    const double expected = (a * b).real(), got = numeric::real_of_product(a, b);
    const double naive = a.real() * b.real() - a.imag() * b.imag();
    if (std::isnan(naive) && !std::isnan(expected)) ++recovered;
    EXPECT_TRUE(same_bits(got, expected) || (std::isnan(got) && std::isnan(expected)))
        << a << " * " << b << ": " << got << " against " << expected;
  }
  EXPECT_GT(recovered, 0) << "no operands where the product recovers an infinity: the fallback is untested";
  // Contact states: θo placed from the mode's functional.
  const numeric::Parameters p = numeric::parameters_of(model::load_case("V"));
  numeric::Effects e;
  e.coulomb_motor = 0.01;
  e.coulomb_load = 0.02;
  e.saturation = 0.8;
  e.torque_offset = 0.05;
  int contacts = 0;
  for (const numeric::Mode& m : numeric::reachable_modes(p, e)) {
    if (m.kind != numeric::ModeKind::Contact) continue;
    for (int trial = 0; trial < 5; ++trial) {
      const numeric::HybridState start =
          numeric::state_on_face(p, m.face, 0.6 + 0.3 * unit(random), m.slip_motor * std::fabs(unit(random)), true);
      const numeric::ModeFlow flow(p, e, m, start);
      for (double tau : {0.0, 0.01, 0.7, 3.0}) {
        const numeric::SmallVector z = flow.local(tau);
        const numeric::HybridState h = flow.state(tau);
        const numeric::HybridState expected =
            numeric::state_on_face(p, m.face, p.theta_R + flow.theta_o_error().constant + z(0), z(1), true);
        EXPECT_TRUE(same_bits(h.theta_m, expected.theta_m) && same_bits(h.theta_L, expected.theta_L) &&
                    same_bits(h.dtheta_m, expected.dtheta_m) && same_bits(h.dtheta_L, expected.dtheta_L))
            << m.describe() << ", tau " << tau;
        ++contacts;
      }
    }
  }
  EXPECT_GT(contacts, 0);
}

TEST(EffectsEngineSearches, check_theta_o_alone_as_the_state) {
  std::mt19937 random(33);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<numeric::Effects> sets(4);
  sets[1].coulomb_motor = 0.01, sets[1].coulomb_load = 0.02;                          // stuck and slipping shafts
  sets[2].saturation = 0.05, sets[2].torque_offset = 0.03;                            // a clipped drive
  sets[3].coulomb_load = 0.02, sets[3].saturation = 0.8, sets[3].torque_offset = -0.01;
  int free_at_motor = 0, free_at_load = 0, contacts = 0;
  for (const char* id : {"I", "II", "V", "VIII"}) {
    const numeric::Parameters p = numeric::parameters_of(model::load_case(id));
    for (const numeric::Effects& e : sets)
      for (const numeric::Mode& m : numeric::reachable_modes(p, e)) {
        if (m.kind == numeric::ModeKind::Mesh) continue;
        for (int trial = 0; trial < 6; ++trial) {
          numeric::HybridState start;
          if (m.kind == numeric::ModeKind::Contact) {
            start = numeric::state_on_face(p, m.face, 0.6 + 0.3 * unit(random), m.slip_motor * std::fabs(unit(random)), true);
          } else {
            start.theta_m = 0.6 + 0.3 * unit(random);
            start.theta_L = start.theta_m + 0.5 * p.backlash * unit(random);
            start.dtheta_m = m.slip_motor == 0 ? 0 : unit(random);
            start.dtheta_L = m.slip_load == 0 ? 0 : unit(random);
            start.face = m.face;
          }
          const numeric::ModeFlow flow(p, e, m, start);
          for (double tau : {0.0, 1e-3, 0.3, 2.0, 17.0}) {
            const double got = flow.measured_at(tau), expected = numeric::measured(p, flow.state(tau));
            EXPECT_TRUE(same_bits(got, expected))
                << "case " << id << ", " << m.describe() << ", tau " << tau << ": returned " << got << " instead of " << expected;
          }
          if (m.kind == numeric::ModeKind::Contact) ++contacts;
          else if (p.measured_at == model::MeasuredAt::Motor) ++free_at_motor;
          else ++free_at_load;
        }
      }
  }
  EXPECT_GT(contacts, 0);
  EXPECT_GT(free_at_motor, 0);
  EXPECT_GT(free_at_load, 0);
  // The mesh modes' flows (case V, at the load), by their eigen-decomposition or the exponential.
  const numeric::Parameters case_v = numeric::parameters_of(model::load_case("V"));
  int meshes = 0;
  for_mesh_flows(random, 6, [&](const numeric::Mode& m, const numeric::ModeFlow& flow) {
    for (double tau : {0.0, 1e-3, 0.3, 2.0, 17.0}) {
      const double got = flow.measured_at(tau), expected = numeric::measured(case_v, flow.state(tau));
      EXPECT_TRUE(same_bits(got, expected)) << m.describe() << ", tau " << tau << ": returned " << got << " instead of " << expected;
    }
    ++meshes;
  });
  EXPECT_GT(meshes, 0);
  // Whole runs: the samples of θo alone against the full ones, for each kind of segment — closed
  // forms (rigid and mesh), the delayed model's integration (rigid and mesh), Stribeck friction's.
  std::vector<std::pair<const char*, numeric::Effects>> runs{{"closed forms", sets[3]}};
  runs.emplace_back("mesh", compliance());
  runs.back().second.coulomb_load = 0.02;
  runs.emplace_back("delay", sets[3]);
  runs.back().second.delay = 0.05;
  runs.emplace_back("delayed mesh", compliance());
  runs.back().second.delay = 0.02;
  runs.emplace_back("Stribeck", numeric::Effects{});
  runs.back().second.stribeck_motor_static = 0.03, runs.back().second.stribeck_motor_kinetic = 0.02;
  runs.back().second.stribeck_motor_velocity = 0.05;
  for (const char* id : {"I", "V"})
    for (const auto& [kind, effects] : runs) {
      const std::string what = std::string("case ") + id + ", " + kind;
      const model::CaseSpec spec = model::load_case(id);
      const numeric::ValidationResult nominal = numeric::validate(numeric::case_evaluator(spec));
      ASSERT_TRUE(nominal.passed());
      const numeric::EffectValidationResult gate = numeric::validate_effects(nominal.evaluator(), effects);
      ASSERT_TRUE(gate.passed()) << what;
      numeric::SimulationOptions full;
      full.t_end = 30;
      for (int k = 0; k <= 3000; ++k) full.sample_times.push_back(0.01 * k);
      numeric::SimulationOptions alone = full;
      alone.sample_theta_o_only = true;
      const numeric::SimulationResult a = numeric::simulate_effects_step(gate.model(), 0.62, full, {.general_engine = true});
      const numeric::SimulationResult b = numeric::simulate_effects_step(gate.model(), 0.62, alone, {.general_engine = true});
      ASSERT_EQ(a.samples.size(), full.sample_times.size()) << what;
      ASSERT_EQ(b.samples.size(), a.samples.size()) << what;
      ASSERT_EQ(b.events.size(), a.events.size()) << what;
      EXPECT_GT(a.events.size(), 2u) << what;
      int differing = 0;
      for (std::size_t k = 0; k < a.samples.size(); ++k) {
        const bool same = same_bits(a.samples[k].t, b.samples[k].t) && same_bits(a.samples[k].theta_o, b.samples[k].theta_o);
        if (!same && ++differing <= 3)
          ADD_FAILURE() << what << ", sample " << k << ": returned " << b.samples[k].theta_o << " instead of " << a.samples[k].theta_o;
        EXPECT_TRUE(std::isnan(b.samples[k].theta_m) && std::isnan(b.samples[k].dtheta_L)) << what << ", sample " << k;
      }
      EXPECT_EQ(differing, 0) << what;
      for (std::size_t i = 0; i < a.events.size(); ++i) EXPECT_TRUE(same_bits(a.events[i].t, b.events[i].t)) << what << ", event " << i;
    }
}
