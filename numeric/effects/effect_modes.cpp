#include "effects/effect_modes.hpp"

#include "evaluators/phi_functions.hpp"
#include "hybrid/balancing.hpp"

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <vector>

namespace backlash::numeric {

namespace {

bool at_motor(const Parameters& p) { return p.measured_at == model::MeasuredAt::Motor; }

// The drive torque in a regime for the measured shaft at θo (no delay in a closed-form mode).
double drive_at(const Parameters& p, const Effects& e, double theta_o, int regime) {
  return drive_torque_in_regime(p, e, theta_o, regime);
}

}  // namespace

std::string Mode::describe() const {
  std::ostringstream out;
  auto slip = [](int s) { return s > 0 ? "+" : s < 0 ? "-" : "stuck"; };
  switch (kind) {
    case ModeKind::Contact: out << "contact face " << face << " pair " << slip(slip_motor); break;
    case ModeKind::Free: out << "free (left face " << face << ") motor " << slip(slip_motor) << " load " << slip(slip_load); break;
    case ModeKind::Mesh: out << "mesh face " << face << " motor " << slip(slip_motor) << " load " << slip(slip_load); break;
  }
  if (regime != 0) out << ", drive clipped " << (regime > 0 ? "+L" : "-L");
  return out.str();
}

std::vector<Mode> reachable_modes(const Parameters& p, const Effects& e) {
  (void)p;
  std::vector<Mode> modes;
  const std::vector<int> regimes = e.saturating() ? std::vector<int>{0, 1, -1} : std::vector<int>{0};
  const std::vector<int> pair_slips = e.coulomb() ? std::vector<int>{1, -1, 0} : std::vector<int>{1, -1};
  const std::vector<int> motor_slips = e.coulomb_motor > 0 ? std::vector<int>{1, -1, 0} : std::vector<int>{1, -1};
  const std::vector<int> load_slips = e.coulomb_load > 0 ? std::vector<int>{1, -1, 0} : std::vector<int>{1, -1};
  for (int face : {-1, 1})
    for (int regime : regimes) {
      if (!e.compliant())
        for (int s : pair_slips) modes.push_back({ModeKind::Contact, face, regime, s, s});
      for (int sm : motor_slips)
        for (int sl : load_slips) {
          modes.push_back({ModeKind::Free, face, regime, sm, sl});
          if (e.compliant()) modes.push_back({ModeKind::Mesh, face, regime, sm, sl});
        }
    }
  return modes;
}

double penetration(const Parameters& p, int face, const HybridState& s) {
  return face * (s.theta_L - s.theta_m) - p.backlash / 2;
}

double mesh_force(const Parameters& p, const Effects& e, int face, const HybridState& s) {
  return e.mesh_stiffness * penetration(p, face, s) + e.mesh_damping * face * (s.dtheta_L - s.dtheta_m);
}

double motor_static_torque(const Parameters& p, const Effects& e, const HybridState& s) {
  double torque = drive_at(p, e, measured(p, s), s.drive_regime);
  if (e.compliant() && s.in_contact) torque += s.face * mesh_force(p, e, s.face, s);
  return torque;
}

double load_static_torque(const Parameters& p, const Effects& e, const HybridState& s) {
  if (e.compliant() && s.in_contact) return -s.face * mesh_force(p, e, s.face, s);
  return 0;
}

double contact_torque(const Parameters& p, const Effects& e, const Mode& m, const HybridState& s) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL, omega = s.dtheta_m;
  const int slip = m.slip_motor;
  if (slip == 0) return 0;
  const double acceleration =
      (drive_at(p, e, measured(p, s), m.regime) - F * omega - (e.coulomb_motor + e.coulomb_load) * slip) / J;
  return p.JL * acceleration + p.FL * omega + e.coulomb_load * slip;
}

// ------------------------------------------------------------------ the generic flow (mesh modes)

// The test ‖V‖∞·‖V⁻¹‖∞ ≤ limit with each row sum of moduli |z| = hypot(re, im) bracketed first
// without hypot, max(|re|, |im|) ≤ |z| ≤ |re| + |im| (a margin of 1e-6 relative covers the
// brackets' own rounding): when the brackets of the product decide the test, that is the exact
// test's answer; only otherwise (or with an entry not finite) are the moduli formed.
// Templated on the matrix type: the mesh flow passes matrices of at most 5×5 held without the
// heap (the same operations, the same bits as on Eigen::MatrixXcd).
namespace {
template <class ComplexMatrix>
bool well_conditioned(const ComplexMatrix& vectors, const ComplexMatrix& inverse, double limit) {
  bool finite = true;
  const auto brackets = [&finite](const ComplexMatrix& X, double& low, double& high) {
    low = high = 0;
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      double row_low = 0, row_high = 0;
      for (Eigen::Index j = 0; j < X.cols(); ++j) {
        const double re = std::fabs(X(i, j).real()), im = std::fabs(X(i, j).imag());
        row_low += std::max(re, im);
        row_high += re + im;
      }
      finite = finite && std::isfinite(row_high);
      low = std::max(low, row_low);
      high = std::max(high, row_high);
    }
  };
  double low_v = 0, high_v = 0, low_i = 0, high_i = 0;
  brackets(vectors, low_v, high_v);
  brackets(inverse, low_i, high_i);
  if (finite && high_v * high_i * (1 + 1e-6) <= limit) return true;
  if (finite && low_v * low_i * (1 - 1e-6) > limit) return false;
  const double condition =
      vectors.cwiseAbs().rowwise().sum().maxCoeff() * inverse.cwiseAbs().rowwise().sum().maxCoeff();
  return std::isfinite(condition) && condition <= limit;
}
}  // namespace

bool well_conditioned_basis(const Eigen::MatrixXcd& vectors, const Eigen::MatrixXcd& inverse, double limit) {
  return well_conditioned(vectors, inverse, limit);
}

// z̃(τ) = e^{Mτ} z̃0 for the augmented M = [[A, c], [0, 0]]: by the eigen-decomposition of M when
// it is diagonalisable with a well-conditioned basis (the generic mesh mode: two complex pairs
// and the augmentation's 0), else by Eigen's Padé exponential at each τ.
struct ModeFlow::Generic {
  using Matrix5 = Eigen::Matrix<double, 5, 5>;
  using ComplexMatrix5 = Eigen::Matrix<std::complex<double>, 5, 5>;
  using ComplexVector5 = Eigen::Matrix<std::complex<double>, 5, 1>;
  // m × m with m ≤ 5 known only at run time, held without the heap: Eigen's EigenSolver,
  // PartialPivLU and Padé exponential give these the bits they give Eigen::MatrixXd/MatrixXcd
  // (the same operations; checked on 2·10⁵ random and mesh-shaped matrices), without the
  // allocations of a dynamic matrix per decomposition and per sample.
  using MatrixUpTo5 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
  using ComplexMatrixUpTo5 = Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, 0, 5, 5>;
  int n = 4;
  Matrix5 M = Matrix5::Zero();
  MatrixUpTo5 augmented;  // M's leading m × m block, formed once (the exponential's, per sample)
  Eigen::Matrix<double, 5, 1> z0 = Eigen::Matrix<double, 5, 1>::Zero();
  bool diagonal = false;
  ComplexVector5 lambda, q;
  ComplexMatrix5 V;
  std::array<double, 5> lambda_cubed{};  // |λ_j|³ (pow(|λ_j|, 3), the same bits), for every witness's bound

  double modulus_cubed(int j) const { return lambda_cubed[static_cast<std::size_t>(j)]; }

  // The eigen-decomposition of an augmented matrix, kept per thread for the last few matrices:
  // a mesh mode is entered again and again with the same matrix (the gap constant snapped to
  // the face makes the augmentation column repeat), and the decomposition is most of a mesh
  // segment's cost.  Exact comparison of the matrix: a hit gives the same bits as a recomputation.
  struct Decomposition {
    Matrix5 M;
    int m = 0;
    bool diagonal = false;
    ComplexVector5 lambda;
    ComplexMatrix5 V, inverse;
    std::array<double, 5> lambda_cubed{};  // Generic::lambda_cubed, formed once per decomposition
  };
  // x == y (Eigen's ==: element by element, +0 == −0, a NaN equals nothing), the augmentation
  // column first and stopping at the first difference: that column moves with every segment's
  // start (the drive, the mesh's constant), so a kept entry of another segment is told apart at once.
  static bool same_matrix(const Matrix5& x, const Matrix5& y) {
    const double* a = x.data();
    const double* b = y.data();
    for (int i = 20; i < 25; ++i)
      if (!(a[i] == b[i])) return false;
    for (int i = 0; i < 20; ++i)
      if (!(a[i] == b[i])) return false;
    return true;
  }
  // pow(|λ_j|, 3) for j < m: once per conjugate pair (|λ̄| is |λ|, hypot's bits being those of
  // |Re|, |Im|), and +0 for λ = 0 (pow(0, 3)).
  static void moduli_cubed(const ComplexVector5& lambda, int m, std::array<double, 5>& out) {
    out = {};
    for (int j = 0; j < m; ++j) {
      const auto k = static_cast<std::size_t>(j);
      if (lambda(j) == 0.0) out[k] = 0.0;
      else if (j > 0 && lambda(j).imag() != 0 && lambda(j) == std::conj(lambda(j - 1))) out[k] = out[k - 1];
      else out[k] = std::pow(std::abs(lambda(j)), 3);
    }
  }
  // V⁻¹ by Eigen's PartialPivLU, as on a dynamic matrix; for 5 × 5 (a mesh mode's augmented
  // matrix) the fixed-size LU, whose unrolled loops give the same bits (the same operations in
  // the same order: checked against the dynamic one on 2·10⁴ random complex matrices and on
  // every output) for fewer instructions.
  static ComplexMatrixUpTo5 inverse_of(const ComplexMatrixUpTo5& vectors) {
    if (vectors.rows() == 5 && vectors.cols() == 5) {
      const ComplexMatrix5 square = vectors;
      const Eigen::PartialPivLU<ComplexMatrix5> lu(square);
      return ComplexMatrixUpTo5(lu.inverse());
    }
    return Eigen::PartialPivLU<ComplexMatrixUpTo5>(vectors).inverse();
  }
  static const Decomposition& decomposition(const Matrix5& M, int m) {
    constexpr std::size_t capacity = 16;
    thread_local std::vector<Decomposition> cache = [] {
      std::vector<Decomposition> v;
      v.reserve(capacity);
      return v;
    }();
    thread_local std::size_t next = 0;
    for (const Decomposition& d : cache)
      if (d.m == m && same_matrix(d.M, M)) return d;
    // Computed in its slot (a new one, else the oldest in turn), not copied there.
    Decomposition* slot = nullptr;
    if (cache.size() < capacity) {
      slot = &cache.emplace_back();
    } else {
      slot = &cache[next];
      next = (next + 1) % capacity;
    }
    Decomposition& d = *slot;
    d.M = M;
    d.m = m;
    d.diagonal = false;
    d.lambda = ComplexVector5::Zero();
    d.V = ComplexMatrix5::Zero();
    d.inverse = ComplexMatrix5::Zero();
    Eigen::EigenSolver<MatrixUpTo5> solver(M.topLeftCorner(m, m), true);
    if (solver.info() == Eigen::Success) {
      const ComplexMatrixUpTo5 vectors = solver.eigenvectors();
      const ComplexMatrixUpTo5 inverse = inverse_of(vectors);
      if (well_conditioned(vectors, inverse, 1e7)) {
        d.V.topLeftCorner(m, m) = vectors;
        d.inverse.topLeftCorner(m, m) = inverse;
        d.lambda.head(m) = solver.eigenvalues();
        d.diagonal = true;
        moduli_cubed(d.lambda, m, d.lambda_cubed);
      }
    }
    return d;
  }

  Generic(const LinearSegment& s, const SmallVector& start) : n(static_cast<int>(s.A.rows())) {
    M.topLeftCorner(n, n) = s.A;
    M.block(0, n, n, 1) = s.c;
    z0.head(n) = start;
    z0(n) = 1;
    const int m = n + 1;
    const Decomposition& d = decomposition(M, m);
    if (!d.diagonal) {
      augmented = M.topLeftCorner(m, m);
      return;
    }
    V = d.V;
    lambda = d.lambda;
    q = ComplexVector5::Zero();
    q.head(m) = d.inverse.topLeftCorner(m, m) * z0.head(m).cast<std::complex<double>>();
    lambda_cubed = d.lambda_cubed;
    diagonal = true;
  }

  // The eigen-decomposition's weights w_j = e^{λ_j τ} q_j (diagonal only): cexp once per conjugate
  // pair (cexp(z̄) is conj(cexp(z)), bit for bit) and not at all for λ = 0 (e^0 = 1).
  ComplexVector5 weights(double tau) const {
    const int m = n + 1;
    ComplexVector5 w = ComplexVector5::Zero();
    for (int j = 0; j < m; ++j) {
      if (lambda(j) == 0.0) {
        w(j) = std::complex<double>(1, 0) * q(j);
      } else if (j + 1 < m && lambda(j + 1) == std::conj(lambda(j)) && lambda(j).imag() != 0) {
        const std::complex<double> e = std::exp(lambda(j) * tau);
        w(j) = e * q(j);
        w(j + 1) = std::conj(e) * q(j + 1);
        ++j;
      } else {
        w(j) = std::exp(lambda(j) * tau) * q(j);
      }
    }
    return w;
  }
  // z_i = Re Σ_j V_ij w_j: only the real parts are summed, each Re(V_ij w_j) = ac − bd as the
  // complex product forms it (the full product, with its recovery of infinities, where that is NaN).
  double row(int i, const ComplexVector5& w) const {
    double sum = 0;
    for (int j = 0; j <= n; ++j) sum += real_of_product(V(i, j), w(j));
    return sum;
  }

  [[gnu::noinline]] SmallVector at(double tau) const {  // out of local(): inlined, its frame slows every closed-form flow
    if (diagonal) {
      const ComplexVector5 w = weights(tau);
      SmallVector z(n);
      for (int i = 0; i < n; ++i) z(i) = row(i, w);
      return z;
    }
    const MatrixUpTo5 E = (augmented * tau).exp();
    return SmallVector((E * z0.head(n + 1)).head(n));
  }
  /// at(τ)(i) alone (diagonal only: the exponential's product forms every row at once).
  double at(double tau, int i) const { return row(i, weights(tau)); }
};

// ------------------------------------------------------------------ ModeFlow

namespace {

// The contact mode's system: z = (d, ω) with d = θo − θR − y* under the linear drive, else
// z = (Δ, ω) with the drive as a constant (saturated) or an external input.
void contact_system(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start,
                    bool drive_external, ModeSystem& sys) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const double T = e.coulomb_motor + e.coulomb_load;
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double offset = std::fabs(drive_constant(e, 0));
  const double theta_o0 = measured(p, start);
  const bool linear_drive = m.regime == 0 && !drive_external;
  LinearSegment& s = sys.segment;
  const double omega0 = start.dtheta_m;
  if (m.slip_motor == 0) return;  // stuck: nothing moves
  sys.z0_noise(1) = 4 * eps * std::fabs(omega0);
  s.A(0, 1) = 1;
  s.A(1, 1) = -F / J;
  if (linear_drive) {  // z = (d, ω), d = θo − θR − y*: J d'' + F d' + K d = 0
    const double y_star = (drive_constant(e, 0) - T * m.slip_motor) / p.K;
    s.A(1, 0) = -p.K / J;
    sys.z0 << theta_o0 - p.theta_R - y_star, omega0;
    sys.z0_noise(0) = 4 * eps * (std::fabs(theta_o0) + std::fabs(p.theta_R) + (offset + T) / p.K);
  } else {  // z = (Δ, ω): J Δ'' + F Δ' = D − T s
    const double drive = drive_external ? 0.0 : drive_constant(e, m.regime);
    s.c(1) = (drive - T * m.slip_motor) / J;
    sys.c_magnitude(1) = ((drive_external ? 0.0 : e.saturation + offset) + T) / J;
    if (drive_external) sys.drive_column(1) = 1 / J;
    sys.z0 << 0, omega0;
  }
}

// The mesh engaged on face σ: the spring-damper force couples the motor and the load rows.
void add_mesh_coupling(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start,
                       ModeSystem& sys) {
  LinearSegment& s = sys.segment;
  // σP = kc (x0 + ΔL − Δm) − σ kc b/2 + cc (θ̇L − θ̇m) acts on the motor (+σP) and the load (−σP).
  const double kc = e.mesh_stiffness, cc = e.mesh_damping, sigma = m.face;
  const double x0 = start.theta_L - start.theta_m;
  const double constant = kc * x0 - sigma * kc * p.backlash / 2;
  const double constant_magnitude = kc * (std::fabs(start.theta_L) + std::fabs(start.theta_m) + p.backlash / 2);
  if (m.slip_motor != 0) {
    s.A(1, 0) += -kc / p.Jm;
    s.A(1, 1) += -cc / p.Jm;
    s.A(1, 2) += kc / p.Jm;
    s.A(1, 3) += cc / p.Jm;
    s.c(1) += constant / p.Jm;
    sys.c_magnitude(1) += constant_magnitude / p.Jm;
  }
  if (m.slip_load != 0) {
    s.A(3, 0) += kc / p.JL;
    s.A(3, 1) += cc / p.JL;
    s.A(3, 2) += -kc / p.JL;
    s.A(3, 3) += -cc / p.JL;
    s.c(3) += -constant / p.JL;
    sys.c_magnitude(3) += constant_magnitude / p.JL;
  }
}

}  // namespace

ModeSystem mode_system(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start,
                       bool drive_external) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double offset = std::fabs(drive_constant(e, 0));
  ModeSystem sys;
  const int n = m.kind == ModeKind::Contact ? 2 : 4;
  sys.segment = LinearSegment{SmallMatrix::Zero(n, n), SmallVector::Zero(n)};
  sys.z0 = SmallVector::Zero(n);
  sys.z0_noise = SmallVector::Zero(n);
  sys.c_magnitude = SmallVector::Zero(n);
  sys.drive_column = SmallVector::Zero(n);
  LinearSegment& s = sys.segment;
  const double theta_o0 = measured(p, start);
  const bool linear_drive = m.regime == 0 && !drive_external;
  if (m.kind == ModeKind::Contact) {
    contact_system(p, e, m, start, drive_external, sys);
    return sys;
  }
  // Free flight and mesh: z = (Δm, θ̇m, ΔL, θ̇L).
  sys.z0 << 0, start.dtheta_m, 0, start.dtheta_L;
  sys.z0_noise << 0, 4 * eps * std::fabs(start.dtheta_m), 0, 4 * eps * std::fabs(start.dtheta_L);
  s.A(0, 1) = 1;
  s.A(2, 3) = 1;
  if (m.slip_motor != 0) {
    double drive = 0, drive_magnitude = 0;
    if (drive_external) {
      sys.drive_column(1) = 1 / p.Jm;
    } else {
      drive = drive_at(p, e, theta_o0, m.regime);
      drive_magnitude = (linear_drive ? p.K * (std::fabs(p.theta_R) + std::fabs(theta_o0)) : e.saturation) + offset;
      if (linear_drive) (at_motor(p) ? s.A(1, 0) : s.A(1, 2)) = -p.K / p.Jm;
    }
    s.A(1, 1) = -p.Fm / p.Jm;
    s.c(1) = (drive - e.coulomb_motor * m.slip_motor) / p.Jm;
    sys.c_magnitude(1) = (drive_magnitude + e.coulomb_motor) / p.Jm;
  }
  if (m.slip_load != 0) {
    s.A(3, 3) = -p.FL / p.JL;
    s.c(3) = -e.coulomb_load * m.slip_load / p.JL;
    sys.c_magnitude(3) = e.coulomb_load / p.JL;
  }
  if (m.kind == ModeKind::Mesh) add_mesh_coupling(p, e, m, start, sys);
  return sys;
}

ModeFlow::ModeFlow(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start)
    : p_(p), e_(e), mode_(m), start_(start), system_(mode_system(p, e, m, start, false)) {
  const double J = p.Jm + p.JL, F = p.Fm + p.FL;
  const double T = e.coulomb_motor + e.coulomb_load;
  if (m.kind == ModeKind::Contact) {
    if (m.slip_motor != 0 && m.regime == 0) {
      y_star_ = (drive_constant(e, 0) - T * m.slip_motor) / p.K;
      contact_rates_ = damped_rates(F / (2 * J), p.K / J);
    } else if (m.slip_motor != 0) {
      beta_ = F / J;
      g_ = system_.segment.c(1);
    }
    theta_o_constant_ = theta_o_error().constant;
    return;
  }
  if (m.kind == ModeKind::Mesh) {
    generic_ = std::make_shared<const Generic>(system_.segment, system_.z0);
    return;
  }
  // Free flight: closed forms.
  a_ = p.Fm / p.Jm;
  b_ = p.FL / p.JL;
  k_ = p.K / p.Jm;
  gL_ = system_.segment.c(3);
  if (m.slip_motor == 0) {
    motor_form_ = 0;
  } else if (m.regime != 0 || (!at_motor(p) && m.slip_load == 0)) {
    motor_form_ = 1;  // constant drive
    gm_ = system_.segment.c(1);
  } else if (at_motor(p)) {
    motor_form_ = 2;  // its own closed loop
    y_star_ = (drive_constant(e, 0) - e.coulomb_motor * m.slip_motor) / p.K;
    motor_rates_ = damped_rates(p.Fm / (2 * p.Jm), p.K / p.Jm);
    motor_y0_ = measured(p, start) - p.theta_R - y_star_;
  } else {
    motor_form_ = 3;  // driven by the moving load
    c0_ = system_.segment.c(1);
  }
}

// The kernels of a free flight at x = −(Fm/Jm)τ, y = −(FL/JL)τ: all of coupled_kernels when the
// motor is driven by the moving load, else only the nodes the motor and the load use (the same
// bits: coupled_kernels forms e^x, φ1, φ2 of each node by phi_pair; the rest stay 0).
CoupledKernels ModeFlow::free_kernels(double x, double y) const {
  if (motor_form_ == 3) return coupled_kernels(x, y);
  return node_kernels(x, y, true, true);
}

// The kernels of the nodes asked for (the motor's x when its drive is constant, the load's y when
// it slips), each by phi_pair as coupled_kernels forms it; the rest 0.
CoupledKernels ModeFlow::node_kernels(double x, double y, bool motor, bool load) const {
  CoupledKernels k{0, 0, 0, 0, 0, 0, 0, 0, 0};
  if (motor && motor_form_ == 1) {
    const PhiPair px = phi_pair(x);
    k.exp_x = px.e, k.phi1_x = px.phi1, k.phi2_x = px.phi2;
  }
  if (load && mode_.slip_load != 0) {
    const PhiPair py = phi_pair(y);
    k.exp_y = py.e, k.phi1_y = py.phi1, k.phi2_y = py.phi2;
  }
  return k;
}

[[gnu::always_inline]] inline void ModeFlow::load_part(double tau, const CoupledKernels& k, double& z2, double& z3) const {
  const double vL0 = system_.z0(3), t2 = tau * tau;
  if (mode_.slip_load == 0) {
    z2 = 0;
    z3 = 0;
  } else {
    z2 = vL0 * tau * k.phi1_y + gL_ * t2 * k.phi2_y;
    z3 = vL0 * k.exp_y + gL_ * tau * k.phi1_y;
  }
}

[[gnu::always_inline]] inline void ModeFlow::motor_part(double tau, const CoupledKernels& k, double& z0, double& z1) const {
  const double vm0 = system_.z0(1), vL0 = system_.z0(3), t2 = tau * tau;
  switch (motor_form_) {
    case 0:
      z0 = 0;
      z1 = 0;
      break;
    case 1:
      z0 = vm0 * tau * k.phi1_x + gm_ * t2 * k.phi2_x;
      z1 = vm0 * k.exp_x + gm_ * tau * k.phi1_x;
      break;
    case 2: {
      const double y0 = motor_y0_;
      const DampedPair dp = damped_pair(motor_rates_, tau);
      z0 = y0 * (dp.c - 1) + (vm0 + motor_rates_.alpha * y0) * dp.s;
      z1 = vm0 * dp.c - (motor_rates_.alpha * vm0 + motor_rates_.w2 * y0) * dp.s;
      break;
    }
    default:
      z0 = vm0 * tau * k.phi1_x + c0_ * t2 * k.phi2_x - k_ * vL0 * t2 * tau * k.a2 - k_ * gL_ * t2 * t2 * k.a3;
      z1 = vm0 * k.exp_x + c0_ * tau * k.phi1_x - k_ * vL0 * t2 * k.a1 - k_ * gL_ * t2 * tau * k.a2;
      break;
  }
}

SmallVector ModeFlow::local(double tau) const {
  const Mode& m = mode_;
  if (generic_) return generic_->at(tau);
  if (m.kind == ModeKind::Contact) {
    SmallVector z(2);
    if (m.slip_motor == 0) {
      z << 0, 0;
    } else if (m.regime == 0) {
      const DampedPair dp = damped_pair(contact_rates_, tau);
      const double d0 = system_.z0(0), w0 = system_.z0(1);
      const double alpha = contact_rates_.alpha, w2 = contact_rates_.w2;
      z << d0 * dp.c + (w0 + alpha * d0) * dp.s, w0 * dp.c - (alpha * w0 + w2 * d0) * dp.s;
    } else {
      const double x = -beta_ * tau, w0 = system_.z0(1);
      const Phi12 f = phi12(x);
      z << w0 * tau * f.phi1 + g_ * tau * tau * f.phi2, w0 * std::exp(x) + g_ * tau * f.phi1;
    }
    return z;
  }
  SmallVector z(4);
  const CoupledKernels k = free_kernels(-a_ * tau, -b_ * tau);
  load_part(tau, k, z(2), z(3));
  motor_part(tau, k, z(0), z(1));
  return z;
}

// A contact's θo is state_of's θR + constant + z(0); a free flight's the measured shaft's start
// plus its own local coordinate, from the kernels of its node alone (the load's are the same bits
// whether coupled_kernels or phi_pair forms them; a motor driven by the moving load needs all); a
// mesh mode's from its coordinate's row of the eigen-decomposition alone (each row is summed on its own).
double ModeFlow::measured_at(double tau) const {
  const Mode& m = mode_;
  if (generic_) {  // a mesh mode: its measured shaft's row of the eigen-decomposition alone
    if (!generic_->diagonal) return measured(p_, state(tau));
    return at_motor(p_) ? start_.theta_m + generic_->at(tau, 0) : start_.theta_L + generic_->at(tau, 2);
  }
  if (m.kind == ModeKind::Contact) return measured_of(local(tau));
  double position = 0, rate = 0;
  if (p_.measured_at == model::MeasuredAt::Motor) {
    if (motor_form_ == 3) return start_.theta_m + local(tau)(0);
    motor_part(tau, node_kernels(-a_ * tau, -b_ * tau, true, false), position, rate);
    return start_.theta_m + position;
  }
  load_part(tau, node_kernels(-a_ * tau, -b_ * tau, false, true), position, rate);
  return start_.theta_L + position;
}

double ModeFlow::measured_of(const SmallVector& z) const {
  if (mode_.kind == ModeKind::Contact) return p_.theta_R + theta_o_constant_ + z(0);
  return at_motor(p_) ? start_.theta_m + z(0) : start_.theta_L + z(2);
}

HybridState ModeFlow::state_of(const SmallVector& z) const {
  HybridState h;
  const Mode& m = mode_;
  if (m.kind == ModeKind::Contact) {
    const double theta_o = p_.theta_R + theta_o_constant_ + z(0);
    h = state_on_face(p_, m.face, theta_o, z(1), true);
    h.motor_stuck = h.load_stuck = m.slip_motor == 0;
  } else {
    h.theta_m = start_.theta_m + z(0);
    h.dtheta_m = z(1);
    h.theta_L = start_.theta_L + z(2);
    h.dtheta_L = z(3);
    h.in_contact = m.kind == ModeKind::Mesh;
    h.face = m.face;
    h.motor_stuck = m.slip_motor == 0;
    h.load_stuck = m.slip_load == 0;
  }
  h.drive_regime = m.regime;
  return h;
}

bool ModeFlow::uses_matrix_exponential() const { return generic_ && !generic_->diagonal; }

namespace {

// μ∞(A) = max_i (a_ii + Σ_{j≠i} |a_ij|), the logarithmic norm: ‖e^{At}‖∞ ≤ e^{μ∞(A) t}.
double log_norm(const SmallMatrix& A) {
  double mu = -INFINITY;
  for (Eigen::Index i = 0; i < A.rows(); ++i)
    mu = std::max(mu, A(i, i) + A.row(i).cwiseAbs().sum() - std::fabs(A(i, i)));
  return mu;
}

// One norm ‖D·‖∞ for the bound of a flow by the matrix exponential: |r·z| ≤ ‖r D⁻¹‖₁ ‖D z‖∞,
// ‖D z(t)‖∞ ≤ e^{μ∞(DAD⁻¹)(t − a)} ‖D z(a)‖∞ for z' = A z.
struct ScaledNorm {
  SmallVector scale;
  double weight = 0, growth = 0;
  ScaledNorm(const SmallMatrix& A, const SmallRow& r, const SmallVector& d) : scale(d) {
    weight = r.cwiseQuotient(d.transpose()).cwiseAbs().sum();
    growth = std::max(0.0, log_norm(d.asDiagonal() * A * d.cwiseInverse().asDiagonal()));
  }
  double bound(const SmallVector& z, double h) const {
    return weight * std::exp(growth * h) * z.cwiseProduct(scale).cwiseAbs().maxCoeff();
  }
};

}  // namespace

// A flow by the matrix exponential has no sum of exponentials to bound: sup over [a, b] of
// |d^k/dτ^k row·z| = |row A^{k−1} z'(τ)| is bounded from z'(a) = A z(a) + c in the plain norm
// ‖·‖∞ and in the balanced one (the certified search's own, first_crossing.hpp), the smaller
// of the two.  Balancing alone can be useless: a mesh of stiffness 1e-100 puts 1e-100 next to
// entries of order 1 and the balancing factors span 1e50, so every bound overflows and the
// search bisects to its resolution as if grazing (issue 18 item 10).
std::function<double(double, double)> ModeFlow::matrix_exponential_bound(const SmallRow& row, int order) const {
  const SmallMatrix A = system_.segment.A;
  SmallRow r = row;
  for (int k = 1; k < order; ++k) r = r * A;
  const SmallVector d = detail::balancing(A).cast<double>();
  const std::array<ScaledNorm, 2> norms{ScaledNorm(A, r, SmallVector::Ones(A.rows())), ScaledNorm(A, r, d)};
  return [this, norms, A](double a, double b) {
    const SmallVector z = A * local(a) + system_.segment.c;
    const double bound = std::fmin(norms[0].bound(z, b - a), norms[1].bound(z, b - a));
    return bound * (1 + 1e-9) + 1e-300;
  };
}

std::function<double(double, double)> ModeFlow::derivative_bound(const SmallRow& row, int order) const {
  if (generic_ && !generic_->diagonal) return matrix_exponential_bound(row, order);
  if (!generic_) return {};
  const Generic& g = *generic_;
  const int m = g.n + 1;
  // (|c_j||λ_j|^order, Re λ_j), at most m = 5 terms: held by value, no vector per witness.
  std::array<std::pair<double, double>, 5> terms{};
  int count = 0;
  for (int j = 0; j < m; ++j) {
    std::complex<double> c = 0;
    for (int i = 0; i < g.n; ++i) c += row(i) * g.V(i, j);
    const double power = order == 3 ? g.modulus_cubed(j) : std::pow(std::abs(g.lambda(j)), order);
    const double size = std::abs(c * g.q(j)) * power;
    if (size > 0) terms[count++] = {size, g.lambda(j).real()};
  }
  // A conjugate pair's two terms share Re λ: its exponential is formed once (the same bits).
  return [terms, count](double a, double b) {
    double bound = 0, last_rate = NAN, growth = 0;
    for (int k = 0; k < count; ++k) {
      const auto& [size, rate] = terms[k];
      if (!(rate == last_rate)) growth = std::exp(rate * (rate > 0 ? b : a)), last_rate = rate;
      bound += size * growth;
    }
    return bound * (1 + 1e-9) + 1e-300;
  };
}

HybridState ModeFlow::state(double tau) const { return state_of(local(tau)); }

ModeFlow::Functional ModeFlow::theta_o_error() const {
  Functional f;
  if (mode_.kind == ModeKind::Contact) {
    f.row = SmallRow::Zero(2);
    f.row(0) = 1;
    f.constant = mode_.slip_motor != 0 && mode_.regime == 0 ? y_star_ : measured(p_, start_) - p_.theta_R;
    f.magnitude = std::fabs(measured(p_, start_)) + std::fabs(p_.theta_R) + std::fabs(y_star_);
    return f;
  }
  f.row = SmallRow::Zero(4);
  f.row(at_motor(p_) ? 0 : 2) = 1;
  f.constant = measured(p_, start_) - p_.theta_R;
  f.magnitude = std::fabs(measured(p_, start_)) + std::fabs(p_.theta_R);
  return f;
}

ModeFlow::Functional ModeFlow::gap_functional() const {
  Functional f;
  if (mode_.kind == ModeKind::Contact) {
    f.row = SmallRow::Zero(2);
    f.constant = mode_.face * p_.backlash / 2;
    f.magnitude = p_.backlash / 2;
    return f;
  }
  f.row = SmallRow::Zero(4);
  f.row(0) = -1;
  f.row(2) = 1;
  f.constant = start_.theta_L - start_.theta_m;
  f.magnitude = std::fabs(start_.theta_L) + std::fabs(start_.theta_m);
  // A flight that starts on a face (after a separation or an impact, placed there exactly)
  // starts exactly at ±b/2: its gap is not the rounding of θL − θm, which would put a
  // millionth of a tiny bounce's height into the constant.
  for (int face : {-1, 1})
    if (std::fabs(f.constant - face * p_.backlash / 2) <= 8 * std::numeric_limits<double>::epsilon() * f.magnitude)
      f.constant = face * p_.backlash / 2;
  return f;
}

ModeFlow::Functional ModeFlow::motor_velocity() const {
  Functional f;
  f.row = SmallRow::Zero(system_.segment.A.rows());
  f.row(1) = 1;
  return f;
}

ModeFlow::Functional ModeFlow::load_velocity() const {
  Functional f;
  f.row = SmallRow::Zero(system_.segment.A.rows());
  f.row(mode_.kind == ModeKind::Contact ? 1 : 3) = 1;
  return f;
}

double ModeFlow::gap(const SmallVector& z) const {
  const Functional f = gap_functional();
  return f.row.dot(z) + f.constant;
}

double ModeFlow::theta_o(const SmallVector& z) const {
  const Functional f = theta_o_error();
  return p_.theta_R + f.row.dot(z) + f.constant;
}

}  // namespace backlash::numeric
