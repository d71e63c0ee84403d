// The torque-domain regression of the measured-drive workflow on a drive with a gap
// (two_body_signals.hpp): signs, the load's side, the compared samples, least squares, Ceres's
// covariance.
#include "two_body_signals.hpp"

#include "quiet_ceres.hpp"

#include <Eigen/Dense>
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace backlash::discrepancy::two_body {

const char* const kName[kCount] = {"motor.J", "motor.F", "load.J", "load.F", "coulomb_motor", "coulomb_load", "torque_offset"};

std::vector<signed char> signs_of(const std::vector<double>& q, const std::vector<double>& v, double rest_speed, bool counted) {
  const std::size_t n = q.size();
  std::vector<signed char> sign(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool changed = !counted || (i > 0 && q[i] != q[i - 1]) || (i + 1 < n && q[i + 1] != q[i]);
    sign[i] = !changed || std::fabs(v[i]) <= rest_speed ? 0 : v[i] > 0 ? 1 : -1;
  }
  return sign;
}

namespace {

std::vector<double> filtered_signs(const Signals& s, const std::vector<signed char>& sign) {
  return measurements::zero_phase_filter(std::vector<double>(sign.begin(), sign.end()), s.filter);
}

}  // namespace

LoadSide load_side(const Signals& s, std::vector<double> qL, bool counted) {
  LoadSide l;
  l.qL = std::move(qL);
  const measurements::Derivatives d = measurements::derivatives(measurements::zero_phase_filter(l.qL, s.filter), s.fs);
  l.vL = d.velocity;
  l.aL = d.acceleration;
  l.sL = signs_of(l.qL, l.vL, s.rest_speed, counted);
  l.sL_f = filtered_signs(s, l.sL);
  return l;
}

namespace {

// The column of parameter i at sample k: r = Uf − Σ θ_i·c_i.
double column(const Signals& s, const LoadSide& l, int i, std::size_t k) {
  switch (i) {
    case kJm: return s.am[k];
    case kFm: return s.vm[k];
    case kJL: return l.aL[k];
    case kFL: return l.vL[k];
    case kTm: return s.sm_f[k];
    case kTL: return l.sL_f[k];
    default: return -1;  // T0
  }
}

double residual_at(const Signals& s, const LoadSide& l, const Theta& m, std::size_t k) {
  double r = s.Uf[k];
  for (int i = 0; i < kCount; ++i) r -= m[i] * column(s, l, i, k);
  return r;
}

}  // namespace

std::vector<double> residuals(const Signals& s, const LoadSide& l, const Theta& m) {
  std::vector<double> r(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) r[k] = residual_at(s, l, m, k);
  return r;
}

LinearFit solve(const Signals& s, const LoadSide& l, const Theta& start, const FreeSet& free,
                const std::vector<std::size_t>& samples) {
  LinearFit out;
  std::vector<int> cols;
  for (int i = 0; i < kCount; ++i)
    if (free[i]) cols.push_back(i);
  Theta x = start;
  if (samples.size() < cols.size() + 2) return out;
  for (int attempt = 0; attempt < kCount && !cols.empty(); ++attempt) {
    Eigen::MatrixXd A(samples.size(), cols.size());
    Eigen::VectorXd y(samples.size());
    for (std::size_t row = 0; row < samples.size(); ++row) {
      const std::size_t k = samples[row];
      double rhs = s.Uf[k];
      for (int i = 0; i < kCount; ++i)
        if (!free[i] || std::find(cols.begin(), cols.end(), i) == cols.end()) rhs -= x[i] * column(s, l, i, k);
      for (std::size_t c = 0; c < cols.size(); ++c) A(row, c) = column(s, l, cols[c], k);
      y(row) = rhs;
    }
    const Eigen::VectorXd solution = A.colPivHouseholderQr().solve(y);
    if (!solution.allFinite()) return out;
    for (std::size_t c = 0; c < cols.size(); ++c) x[cols[c]] = solution(c);
    // A negative friction (Coulomb or viscous) refitted at 0.
    auto negative = std::find_if(cols.begin(), cols.end(), [&](int i) { return i != kJm && i != kJL && i != kT0 && x[i] < 0; });
    if (negative == cols.end()) break;
    x[*negative] = 0;
    cols.erase(negative);
    out.clamped = true;
  }
  if (!(x[kJm] > 0) || !(x[kJL] > 0) || x[kFm] < 0 || x[kFL] < 0) return out;
  out.m = x;
  out.ok = true;
  out.sse = 0;
  for (std::size_t k : samples) out.sse += std::pow(residual_at(s, l, x, k), 2);
  return out;
}

namespace {

// The runs of flight: consecutive samples inside the faces by the margin, the load moving one way.
std::vector<std::pair<std::size_t, std::size_t>> flights_of(const Signals& s, const LoadSide& l, double x0, double b) {
  double count = INFINITY;
  for (std::size_t k = 1; k < s.size(); ++k)
    if (l.qL[k] != l.qL[k - 1]) count = std::min(count, std::fabs(l.qL[k] - l.qL[k - 1]));
  const double inside = b / 2 - 0.15 * b - 2 * (std::isfinite(count) ? count : 0);
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t start = s.begin;
  for (std::size_t k = s.begin; k <= s.end; ++k) {
    const bool in = k < s.end && inside > 0 && std::fabs(l.qL[k] - s.qm[k] - x0) < inside && l.sL[k] != 0;
    if (in && k > start && l.sL[k] == l.sL[start]) continue;
    if (k > start && k - start >= 8 && l.sL[start] != 0) runs.emplace_back(start, k);
    start = in ? k : k + 1;
  }
  return runs;
}

}  // namespace

FlightFit flight_coulomb(const Signals& s, const LoadSide& l, double x0, double b, double alpha) {
  FlightFit out;
  const auto runs = flights_of(s, l, x0, b);
  std::size_t n = 0;
  for (const auto& [a, e] : runs) n += e - a;
  const std::size_t cols = 2 * runs.size() + 1;
  if (n < 20 || n < cols + 5) return out;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(cols));
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  Eigen::Index row = 0;
  for (std::size_t r = 0; r < runs.size(); ++r)
    for (std::size_t k = runs[r].first; k < runs[r].second; ++k, ++row) {
      const double t = s.t[k] - s.t[runs[r].first], at = alpha * t;
      const double phi1 = at < 1e-6 ? t : -std::expm1(-at) / alpha;
      const double phi2 = at < 1e-6 ? t * t / 2 : t / alpha + std::expm1(-at) / (alpha * alpha);
      A(row, static_cast<Eigen::Index>(2 * r)) = 1, A(row, static_cast<Eigen::Index>(2 * r + 1)) = phi1;
      A(row, static_cast<Eigen::Index>(cols - 1)) = -l.sL[k] * phi2;
      y(row) = l.qL[k];
    }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::VectorXd x = qr.solve(y);
  const Eigen::VectorXd x0fit = A.leftCols(static_cast<Eigen::Index>(cols - 1)).colPivHouseholderQr().solve(y);
  if (!x.allFinite() || !x0fit.allFinite()) return out;
  const Eigen::VectorXd r = y - A * x;
  const double sse = r.squaredNorm(), sse0 = (y - A.leftCols(static_cast<Eigen::Index>(cols - 1)) * x0fit).squaredNorm();
  const double tau = tau_int_or_one(std::vector<double>(r.data(), r.data() + r.size()));
  const double n_eff = static_cast<double>(n) / tau;
  const Eigen::MatrixXd cov = (A.transpose() * A).inverse();
  out.ok = true, out.samples = n, out.flights = runs.size();
  out.beta = x(static_cast<Eigen::Index>(cols - 1));
  out.sigma = std::sqrt(cov(static_cast<Eigen::Index>(cols - 1), static_cast<Eigen::Index>(cols - 1)) * sse / static_cast<double>(n - cols) * tau);
  out.delta_bic = n_eff * std::log(std::max(sse, 1e-300) / std::max(sse0, 1e-300)) + std::log(n_eff);
  return out;
}

double tau_int_or_one(const std::vector<double>& r) {
  if (r.size() < 2 || std::all_of(r.begin(), r.end(), [&](double x) { return x == r.front(); })) return 1;
  return std::max(1.0, measurements::integrated_autocorrelation_time(r).tau);
}

namespace {

struct FunctionCost {
  const std::function<void(const double*, double*)>* f;
  bool operator()(double const* const* x, double* r) const {
    (*f)(x[0], r);
    return true;
  }
};

}  // namespace

std::vector<double> ceres_sigma(const std::function<void(const double*, double*)>& residual, std::size_t n,
                                std::vector<double>& x, const std::vector<double>& lower, bool polish, double relative_step) {
  detail::quiet_ceres();
  const std::size_t k = x.size();
  std::vector<double> sigma(k, NAN);
  if (k == 0 || n <= k) return sigma;
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = relative_step;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<FunctionCost, ceres::CENTRAL>(new FunctionCost{&residual},
                                                                                       ceres::TAKE_OWNERSHIP, diff);
  cost->AddParameterBlock(static_cast<int>(k));
  cost->SetNumResiduals(static_cast<int>(n));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (std::size_t j = 0; j < k; ++j)
    if (std::isfinite(lower[j])) problem.SetParameterLowerBound(x.data(), static_cast<int>(j), lower[j]);
  if (polish) {
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 30;
    options.logging_type = ceres::SILENT;
    options.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
  }
  std::vector<double> r(n);
  residual(x.data(), r.data());
  const double tau = tau_int_or_one(r);
  const double variance = std::inner_product(r.begin(), r.end(), r.begin(), 0.0) / static_cast<double>(n - k);
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks{{x.data(), x.data()}};
  if (!covariance.Compute(blocks, &problem)) return sigma;
  std::vector<double> c(k * k);
  covariance.GetCovarianceBlock(x.data(), x.data(), c.data());
  for (std::size_t j = 0; j < k; ++j) sigma[j] = std::sqrt(c[j * k + j] * variance * tau);
  return sigma;
}

}  // namespace backlash::discrepancy::two_body
