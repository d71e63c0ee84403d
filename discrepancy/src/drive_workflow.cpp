// The discrepancy workflow on a measured drive (measured_drive.hpp): inverse dynamics in
// the torque domain, effects named one after another by the decisive rule, the position
// checked over windows restarted from the measured state.
#include "backlash/discrepancy/measured_drive.hpp"

#include "backlash/measurements/inverse_dynamics_signals.hpp"
#include "backlash/numeric/measured_drive.hpp"

#include <Eigen/Dense>
#include <boost/math/tools/minima.hpp>
#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace backlash::discrepancy {

const std::vector<std::string>& drive_vocabulary() {
  static const std::vector<std::string> vocabulary{"coulomb_motor", "torque_offset", "delay", "saturation"};
  return vocabulary;
}

namespace {

// ------------------------------------------------------------------ the torque-domain model

// The parameters of r(t) = û(t − τ) + T0 − (J·â + F·v̂ + Tc·sgn v̂), û = filtered sat_L(gain·drive).
enum Index { kJ = 0, kF, kTc, kT0, kL, kTau, kCount };
const char* const kEffectParameter[kCount] = {"J", "F", "torque", "torque", "limit", "tau"};

struct Theta {
  double v[kCount] = {1, 0, 0, 0, INFINITY, 0};
  double& operator[](int i) { return v[i]; }
  double operator[](int i) const { return v[i]; }
};

struct FreeSet {
  bool on[kCount] = {};
  int count() const { return static_cast<int>(std::count(std::begin(on), std::end(on), true)); }
};

int index_of_effect(const std::string& effect) {
  if (effect == "coulomb_motor" || effect == "coulomb_load") return kTc;
  if (effect == "torque_offset") return kT0;
  if (effect == "saturation") return kL;
  if (effect == "delay") return kTau;
  return -1;
}

// One record, prepared for inverse dynamics: derivatives of the position and the drive through
// the same zero-phase filter.
struct Prepared {
  std::string name;
  std::vector<double> t, q;        // as measured
  double fs = 0;
  std::vector<double> v, a;        // filtered derivatives
  std::vector<double> qf;          // filtered position (window starts)
  std::vector<double> drive;       // gain·drive, as logged
  std::vector<double> drive_raw;   // the drive column itself (the simulator applies the gain)
  std::vector<double> drive_f;     // gain·drive through the filter
  std::vector<signed char> sign;   // sgn v̂, 0 at rest
  std::vector<std::size_t> fit, holdout, all;
  std::size_t size() const { return t.size(); }
};

struct Band {
  measurements::ButterworthLowPass filter;
  double cutoff = 0, floor = NAN;
  bool from_spectrum = true;
  double rest_speed = 0;
};

Prepared prepare(const std::string& name, const measurements::MeasuredRecord& record, double gain, double t_end,
                 const Band& band, double fs, double holdout_fraction) {
  Prepared p;
  p.name = name;
  std::size_t n = record.size();
  while (n > 0 && record.t[n - 1] > t_end) --n;
  p.t.assign(record.t.begin(), record.t.begin() + static_cast<std::ptrdiff_t>(n));
  p.q.assign(record.theta_out.begin(), record.theta_out.begin() + static_cast<std::ptrdiff_t>(n));
  p.drive_raw.assign(record.drive->begin(), record.drive->begin() + static_cast<std::ptrdiff_t>(n));
  p.fs = fs;
  p.drive.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.drive[i] = gain * p.drive_raw[i];
  p.qf = measurements::zero_phase_filter(p.q, band.filter);
  const measurements::Derivatives d = measurements::derivatives(p.qf, fs);
  p.v = d.velocity;
  p.a = d.acceleration;
  p.drive_f = measurements::zero_phase_filter(p.drive, band.filter);
  p.sign.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.sign[i] = std::fabs(p.v[i]) <= band.rest_speed ? 0 : p.v[i] > 0 ? 1 : -1;
  const int every = holdout_fraction > 0 ? std::max(2, static_cast<int>(std::lround(1 / holdout_fraction))) : 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int block = static_cast<int>(10 * i / n);
    (every > 0 && block % every == every - 1 ? p.holdout : p.fit).push_back(i);
    p.all.push_back(i);
  }
  return p;
}

// û(t − τ) for a limit L: the drive clipped, filtered, delayed (linear interpolation between
// samples of the filtered drive; before the record's start its first value).
std::vector<double> drive_torque(const Prepared& p, const Band& band, double L, double tau) {
  std::vector<double> filtered;
  const std::vector<double>* base = &p.drive_f;
  if (std::isfinite(L)) {
    std::vector<double> clipped(p.drive);
    for (double& u : clipped) u = std::clamp(u, -L, L);
    filtered = measurements::zero_phase_filter(clipped, band.filter);
    base = &filtered;
  }
  if (tau == 0) return base == &p.drive_f ? p.drive_f : filtered;
  std::vector<double> out(p.size());
  const double shift = tau * p.fs;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double s = static_cast<double>(k) - shift;
    if (s <= 0) {
      out[k] = (*base)[0];
      continue;
    }
    const std::size_t i = static_cast<std::size_t>(s);
    const double f = s - static_cast<double>(i);
    out[k] = i + 1 < p.size() ? (1 - f) * (*base)[i] + f * (*base)[i + 1] : (*base)[i];
  }
  return out;
}

// The residual at sample k: moving, the drive minus the torque the motion needs; at rest,
// the part of the torque outside the band ±Tc that Coulomb friction holds.
double residual(const Prepared& p, const std::vector<double>& U, const Theta& m, std::size_t k) {
  const double z = U[k] + m[kT0] - m[kJ] * p.a[k] - m[kF] * p.v[k];
  if (p.sign[k] == 0) return z - std::clamp(z, -m[kTc], m[kTc]);
  return z - m[kTc] * p.sign[k];
}

double sse_on(const Prepared& p, const std::vector<double>& U, const Theta& m, const std::vector<std::size_t>& samples) {
  double s = 0;
  for (std::size_t k : samples) {
    const double r = residual(p, U, m, k);
    s += r * r;
  }
  return s;
}

std::vector<double> residuals_of(const Prepared& p, const std::vector<double>& U, const Theta& m) {
  std::vector<double> r(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) r[k] = residual(p, U, m, k);
  return r;
}

// The ranges of the nonlinear parameters (and the edge rule).
struct Ranges {
  double tau_max = 0, tau_min = 0;  // the scan's smallest non-zero delay
  double L_min = 0, L_max = 0;
};

Ranges ranges_of(const Prepared& p) {
  Ranges r;
  const double duration = p.t.back() - p.t.front();
  r.tau_max = std::min(0.1, 0.05 * duration);
  r.tau_min = 0.1 / p.fs;
  double peak = 0;
  for (double u : p.drive) peak = std::max(peak, std::fabs(u));
  r.L_max = peak;
  r.L_min = 0.05 * peak;
  return r;
}

struct Work {
  const Prepared& p;
  const Band& band;
  Ranges ranges;
  int least_squares = 0;
};

// The linear parameters (J, F, Tc, T0 where free) by least squares on the moving samples of
// `samples`, the others held.  Tc < 0 is refitted at Tc = 0 (then `clamped`).
struct Linear {
  Theta m;
  bool ok = false;
  bool clamped = false;
  double sse = INFINITY;
};

Linear solve_linear(Work& w, const std::vector<double>& U, Theta m, FreeSet free, const std::vector<std::size_t>& samples) {
  ++w.least_squares;
  Linear out;
  for (int attempt = 0; attempt < 2; ++attempt) {
    std::vector<int> columns;
    for (int i : {kJ, kF, kTc, kT0})
      if (free.on[i]) columns.push_back(i);
    if (!columns.empty()) {
      std::size_t rows = 0;
      for (std::size_t k : samples) rows += w.p.sign[k] != 0;
      Eigen::MatrixXd A(rows, columns.size());
      Eigen::VectorXd y(rows);
      std::size_t row = 0;
      for (std::size_t k : samples) {
        if (w.p.sign[k] == 0) continue;
        // U + T0 − J a − F v − Tc s = r: the free terms on the left, the held ones into y.
        double rhs = U[k];
        const double col[kCount] = {w.p.a[k], w.p.v[k], static_cast<double>(w.p.sign[k]), -1.0, 0, 0};
        for (int i : {kJ, kF, kTc, kT0})
          if (!free.on[i]) rhs -= m[i] * col[i];
        for (std::size_t c = 0; c < columns.size(); ++c) A(row, c) = col[columns[c]];
        y(row++) = rhs;
      }
      if (rows < columns.size() + 2) return out;
      const Eigen::VectorXd x = A.colPivHouseholderQr().solve(y);
      if (!x.allFinite()) return out;
      for (std::size_t c = 0; c < columns.size(); ++c) m[columns[c]] = x(c);
    }
    if (free.on[kTc] && m[kTc] < 0) {
      m[kTc] = 0;
      free.on[kTc] = false;
      out.clamped = true;
      continue;
    }
    break;
  }
  if (!(m[kJ] > 0) || m[kF] < 0) return out;  // not a physical drive: a failed fit
  out.m = m;
  out.ok = true;
  out.sse = sse_on(w.p, U, m, samples);
  return out;
}

// The whole fit: the nonlinear parameters (τ, L) by a scan and Brent's minimisation of the
// profiled least-squares cost, the linear ones by least squares at each point.
Linear fit(Work& w, Theta start, const FreeSet& free, const std::vector<std::size_t>& samples) {
  auto at = [&](const Theta& m) {
    const std::vector<double> U = drive_torque(w.p, w.band, m[kL], m[kTau]);
    return solve_linear(w, U, m, free, samples);
  };
  Linear best = at(start);
  std::vector<int> nonlinear;
  for (int i : {kTau, kL})
    if (free.on[i]) nonlinear.push_back(i);
  if (nonlinear.empty()) return best;
  auto grid = [&](int i) {
    std::vector<double> g;
    if (i == kTau) {
      g.push_back(0);
      for (int j = 0; j <= 24; ++j) g.push_back(w.ranges.tau_min * std::pow(w.ranges.tau_max / w.ranges.tau_min, j / 24.0));
    } else {
      for (int j = 0; j <= 24; ++j) g.push_back(w.ranges.L_min * std::pow(w.ranges.L_max / w.ranges.L_min, j / 24.0));
    }
    return g;
  };
  // Coordinate by coordinate: a scan, then Brent in the best point's bracket; twice round when
  // both are free.
  const int sweeps = nonlinear.size() > 1 ? 2 : 1;
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (int i : nonlinear) {
      const std::vector<double> g = grid(i);
      std::size_t arg = 0;
      double best_cost = INFINITY;
      for (std::size_t j = 0; j < g.size(); ++j) {
        Theta m = best.ok ? best.m : start;
        m[i] = g[j];
        const Linear l = at(m);
        if (l.ok && l.sse < best_cost) best_cost = l.sse, arg = j;
        if (l.ok && l.sse < best.sse) best = l;
      }
      const double lo = g[arg == 0 ? 0 : arg - 1], hi = g[std::min(arg + 1, g.size() - 1)];
      if (!(hi > lo)) continue;
      Theta base = best.ok ? best.m : start;
      const auto [x, cost] = boost::math::tools::brent_find_minima(
          [&](double value) {
            Theta m = base;
            m[i] = value;
            const Linear l = at(m);
            return l.ok ? l.sse : INFINITY;
          },
          lo, hi, 30);
      Theta m = base;
      m[i] = x;
      const Linear l = at(m);
      if (l.ok && l.sse < best.sse) best = l;
      (void)cost;
    }
  return best;
}

bool at_edge(const Work& w, const Theta& m, const FreeSet& free, bool clamped) {
  if (clamped) return true;
  if (free.on[kTau] && (m[kTau] < 1.01 * w.ranges.tau_min || m[kTau] > 0.99 * w.ranges.tau_max)) return true;
  if (free.on[kL] && (m[kL] < 1.01 * w.ranges.L_min || m[kL] > 0.99 * w.ranges.L_max)) return true;
  return false;
}

// ------------------------------------------------------------------ uncertainty (Ceres)

struct TorqueCost final : ceres::CostFunction {
  Work* w;
  FreeSet free;
  std::vector<int> order;
  Theta fixed;
  TorqueCost(Work* work, const FreeSet& f, const Theta& m) : w(work), free(f), fixed(m) {
    for (int i = 0; i < kCount; ++i)
      if (f.on[i]) order.push_back(i);
    set_num_residuals(static_cast<int>(w->p.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(order.size()));
  }
  Theta theta(const double* x) const {
    Theta m = fixed;
    for (std::size_t j = 0; j < order.size(); ++j) m[order[j]] = x[j];
    return m;
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Theta m = theta(parameters[0]);
    const std::vector<double> U = drive_torque(w->p, w->band, m[kL], m[kTau]);
    const std::size_t n = w->p.size(), k = order.size();
    for (std::size_t i = 0; i < n; ++i) residuals[i] = residual(w->p, U, m, i);
    if (!jacobians || !jacobians[0]) return true;
    double* J = jacobians[0];
    for (std::size_t c = 0; c < k; ++c) {
      const int which = order[c];
      if (which == kTau || which == kL) {  // central differences through the filter and the shift
        const double h = which == kTau ? 0.25 / w->p.fs : 1e-4 * m[kL];
        Theta up = m, down = m;
        up[which] += h;
        down[which] = std::max(0.0, down[which] - h);
        const double span = up[which] - down[which];
        const std::vector<double> Uu = drive_torque(w->p, w->band, up[kL], up[kTau]);
        const std::vector<double> Ud = drive_torque(w->p, w->band, down[kL], down[kTau]);
        for (std::size_t i = 0; i < n; ++i)
          J[i * k + c] = (residual(w->p, Uu, up, i) - residual(w->p, Ud, down, i)) / span;
        continue;
      }
      for (std::size_t i = 0; i < n; ++i) {
        double d = 0;
        if (w->p.sign[i] != 0) {
          const double col[4] = {-w->p.a[i], -w->p.v[i], -static_cast<double>(w->p.sign[i]), 1.0};
          d = col[which];
        } else {  // at rest: the dead zone's slope
          const double z = U[i] + m[kT0] - m[kJ] * w->p.a[i] - m[kF] * w->p.v[i];
          if (std::fabs(z) > m[kTc]) {
            const double col[4] = {-w->p.a[i], -w->p.v[i], z > 0 ? -1.0 : 1.0, 1.0};
            d = col[which];
          }
        }
        J[i * k + c] = d;
      }
    }
    return true;
  }
};

void quiet_ceres() {
  static const bool once = [] {
    FLAGS_minloglevel = google::GLOG_FATAL;
    return true;
  }();
  (void)once;
}

// Polishes a whole-record fit with Levenberg–Marquardt (all free parameters together) and
// returns one standard deviation per parameter: Ceres's covariance scaled by the residual
// variance and by τ_int (the residuals are not independent).
struct Polished {
  Theta m;
  double sigma[kCount] = {NAN, NAN, NAN, NAN, NAN, NAN};
  double tau_int = 1;
};

Polished polish(Work& w, const Theta& start, const FreeSet& free) {
  quiet_ceres();
  Polished out;
  out.m = start;
  auto* cost = new TorqueCost(&w, free, start);
  std::vector<double> x;
  for (int i : cost->order) x.push_back(start[i]);
  if (x.empty()) {
    delete cost;
    return out;
  }
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (std::size_t j = 0; j < cost->order.size(); ++j) {
    const int which = cost->order[j];
    if (which == kTc || which == kTau) problem.SetParameterLowerBound(x.data(), static_cast<int>(j), 0.0);
    if (which == kTau) problem.SetParameterUpperBound(x.data(), static_cast<int>(j), w.ranges.tau_max);
    if (which == kL) {
      problem.SetParameterLowerBound(x.data(), static_cast<int>(j), w.ranges.L_min);
      problem.SetParameterUpperBound(x.data(), static_cast<int>(j), w.ranges.L_max);
    }
    if (which == kJ) problem.SetParameterLowerBound(x.data(), static_cast<int>(j), 1e-12 * std::fabs(start[kJ]));
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const Theta polished = cost->theta(x.data());
  const std::vector<double> U = drive_torque(w.p, w.band, polished[kL], polished[kTau]);
  const double sse_polished = sse_on(w.p, U, polished, w.p.all);
  const std::vector<double> U0 = drive_torque(w.p, w.band, start[kL], start[kTau]);
  if (sse_polished <= sse_on(w.p, U0, start, w.p.all)) out.m = polished;
  else for (std::size_t j = 0; j < cost->order.size(); ++j) x[j] = start[cost->order[j]];
  const std::vector<double> r = residuals_of(w.p, drive_torque(w.p, w.band, out.m[kL], out.m[kTau]), out.m);
  out.tau_int = std::max(1.0, measurements::integrated_autocorrelation_time(r).tau);
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks{{x.data(), x.data()}};
  const std::size_t k = x.size(), n = r.size();
  if (n > k && covariance.Compute(blocks, &problem)) {
    std::vector<double> c(k * k);
    covariance.GetCovarianceBlock(x.data(), x.data(), c.data());
    const double variance = std::inner_product(r.begin(), r.end(), r.begin(), 0.0) / static_cast<double>(n - k);
    for (std::size_t j = 0; j < k; ++j) out.sigma[cost->order[j]] = std::sqrt(c[j * k + j] * variance * out.tau_int);
  }
  return out;
}

// ------------------------------------------------------------------ position over windows

numeric::RigidDrive rigid_drive(const Theta& m, double gain) {
  numeric::RigidDrive d;
  d.J = m[kJ];
  d.F = m[kF];
  d.coulomb = m[kTc];
  d.offset = m[kT0];
  d.saturation = m[kL];
  d.delay = m[kTau];
  d.gain = gain;
  return d;
}

struct WindowPrediction {
  std::vector<double> x;  // the prediction at every sample (restarted at each window start)
  std::vector<double> starts;
  double rms = 0;
  int windows = 0;
};

WindowPrediction predict_windows(const Prepared& p, const Theta& m, double gain, double window, double rest_speed) {
  WindowPrediction out;
  out.x.assign(p.size(), NAN);
  const std::size_t length = std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(window * p.fs)));
  const numeric::RigidDrive drive = rigid_drive(m, gain);
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t first = 0; first + 1 < p.size(); first += length) {
    const std::size_t last = std::min(first + length, p.size() - 1);
    const double v0 = std::fabs(p.v[first]) <= rest_speed ? 0.0 : p.v[first];
    const numeric::MeasuredDriveRun run =
        numeric::simulate_measured_drive(drive, p.t, p.drive_raw, first, last, p.qf[first], v0);
    for (std::size_t k = first; k <= last; ++k) {
      out.x[k] = run.x[k - first];
      if (k > first) {
        const double e = p.q[k] - out.x[k];
        sum += e * e;
        ++count;
      }
    }
    out.starts.push_back(p.t[first]);
    ++out.windows;
  }
  out.rms = std::sqrt(sum / std::max<std::size_t>(1, count));
  return out;
}

// ------------------------------------------------------------------ localisation

std::vector<TorqueRegion> classes_of(const Prepared& p, const std::vector<double>& before, const std::vector<double>& after) {
  const std::size_t n = p.size();
  std::vector<double> abs_a(p.a.size());
  for (std::size_t i = 0; i < n; ++i) abs_a[i] = std::fabs(p.a[i]);
  std::vector<double> sorted = abs_a;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(9 * n / 10), sorted.end());
  const double high = sorted[9 * n / 10];
  // Reversals: ±20 ms around a change of the sign of v̂ between moving samples.
  std::vector<char> reversal(n, 0);
  const std::ptrdiff_t half = std::max<std::ptrdiff_t>(1, std::lround(0.02 * p.fs));
  int last_sign = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.sign[i] == 0) continue;
    if (last_sign != 0 && p.sign[i] != last_sign)
      for (std::ptrdiff_t j = static_cast<std::ptrdiff_t>(i) - half; j <= static_cast<std::ptrdiff_t>(i) + half; ++j)
        if (j >= 0 && j < static_cast<std::ptrdiff_t>(n)) reversal[static_cast<std::size_t>(j)] = 1;
    last_sign = p.sign[i];
  }
  auto region = [&](const std::string& kind, auto&& in) {
    TorqueRegion r;
    r.kind = kind;
    double sb = 0, sa = 0, mb = 0, ma = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!in(i)) continue;
      ++r.samples;
      sb += before[i] * before[i], sa += after[i] * after[i], mb += before[i], ma += after[i];
    }
    if (r.samples > 0) {
      r.rms_before = std::sqrt(sb / r.samples), r.rms_after = std::sqrt(sa / r.samples);
      r.mean_before = mb / r.samples, r.mean_after = ma / r.samples;
    }
    return r;
  };
  return {region("forward", [&](std::size_t i) { return p.sign[i] > 0 && !reversal[i]; }),
          region("backward", [&](std::size_t i) { return p.sign[i] < 0 && !reversal[i]; }),
          region("reversal", [&](std::size_t i) { return reversal[i] != 0; }),
          region("rest", [&](std::size_t i) { return p.sign[i] == 0 && !reversal[i]; }),
          region("high acceleration", [&](std::size_t i) { return abs_a[i] > high; })};
}

// The record between reversals (and rests): one stretch per direction of motion.
std::vector<TorqueRegion> stretches_of(const Prepared& p, const std::vector<double>& before, const std::vector<double>& after) {
  std::vector<TorqueRegion> out;
  const std::size_t n = p.size();
  std::size_t start = 0;
  auto kind_of = [&](std::size_t i) { return p.sign[i] > 0 ? "forward" : p.sign[i] < 0 ? "backward" : "rest"; };
  for (std::size_t i = 1; i <= n; ++i) {
    if (i < n && p.sign[i] == p.sign[start]) continue;
    TorqueRegion r;
    r.kind = kind_of(start);
    r.t_start = p.t[start];
    r.t_end = p.t[i - 1];
    double sb = 0, sa = 0, mb = 0, ma = 0;
    for (std::size_t k = start; k < i; ++k) sb += before[k] * before[k], sa += after[k] * after[k], mb += before[k], ma += after[k];
    r.samples = static_cast<int>(i - start);
    r.rms_before = std::sqrt(sb / r.samples), r.rms_after = std::sqrt(sa / r.samples);
    r.mean_before = mb / r.samples, r.mean_after = ma / r.samples;
    out.push_back(r);
    start = i;
  }
  return out;
}

double rms_of(const std::vector<double>& r) {
  return std::sqrt(std::inner_product(r.begin(), r.end(), r.begin(), 0.0) / std::max<std::size_t>(1, r.size()));
}

// The torque residual's noise level: the drive's and the position's noise propagated through
// the filter and the differences (the sum of squares of each operator's impulse response).
double noise_level(double fs, const Band& band, double drive_noise, double position_noise, const Theta& m) {
  const std::size_t n = 4096, middle = n / 2;
  std::vector<double> impulse(n, 0.0);
  impulse[middle] = 1;
  const std::vector<double> h = measurements::zero_phase_filter(impulse, band.filter);
  const measurements::Derivatives d = measurements::derivatives(h, fs);
  double hh = 0, vv = 0, aa = 0;
  for (std::size_t i = 0; i < n; ++i) hh += h[i] * h[i], vv += d.velocity[i] * d.velocity[i], aa += d.acceleration[i] * d.acceleration[i];
  return std::sqrt(drive_noise * drive_noise * hh + position_noise * position_noise * (m[kJ] * m[kJ] * aa + m[kF] * m[kF] * vv));
}

}  // namespace

DriveDiscrepancyResult find_drive_discrepancy(const model::CaseSpec& spec, const measurements::MeasuredRecord& data,
                                              const DriveOptions& options, const measurements::MeasuredRecord* validation) {
  const auto started = std::chrono::steady_clock::now();
  const std::string where = spec.source.filename().string();
  if (!spec.experiment || spec.experiment->kind != model::ExperimentKind::Drive)
    throw std::invalid_argument(where + ": the model's [experiment] is not a measured drive (kind = \"drive\")");
  if (spec.backlash != 0)
    throw std::invalid_argument(where + ": backlash: a measured-drive model is a rigid drive (backlash 0); a drive with a gap and a logged drive is not supported");
  if (!data.drive) throw std::invalid_argument(data.source.string() + ": no drive column: a measured-drive model needs the logged drive");
  if (validation && !validation->drive)
    throw std::invalid_argument(validation->source.string() + ": no drive column: a measured-drive model needs the logged drive");
  const double gain = model::to_double(spec.experiment->drive_gain);
  const double t_end = spec.experiment->t_end ? model::to_double(*spec.experiment->t_end) : INFINITY;

  DriveDiscrepancyResult result;
  result.given = numeric::parameters_of(spec);
  const numeric::Effects file_effects = numeric::effects_of(spec);
  (void)numeric::rigid_drive_of(result.given, file_effects, gain);  // refuses effects that need a gap

  // The free nominal parameters: on a rigid drive only J and F show.
  FreeSet nominal_free;
  std::vector<std::pair<std::string, int>> free_names;
  for (const std::string& name : spec.fit_free) {
    int which = -1;
    if (name == "motor.J" || name == "load.J") which = kJ;
    else if (name == "motor.F" || name == "load.F") which = kF;
    else
      throw std::invalid_argument(where + ": fit.free: " + name +
                                  (name == "K" ? " is not part of a measured-drive model (the loop is open)"
                                               : " cannot be fitted on a rigid drive"));
    if (nominal_free.on[which])
      throw std::invalid_argument(where + ": fit.free: motor." + std::string(which == kJ ? "J" : "F") + " and load." +
                                  (which == kJ ? "J" : "F") + " cannot both be free: on a rigid drive only their sum shows");
    nominal_free.on[which] = true;
    free_names.push_back({name, which});
  }

  // The band: uniform sampling, the cut-off, the filter.
  std::size_t n = data.size();
  while (n > 0 && data.t[n - 1] > t_end) --n;
  if (n < 200) throw std::invalid_argument(data.source.string() + ": fewer than 200 samples before t_end: too short for inverse dynamics");
  const std::vector<double> t(data.t.begin(), data.t.begin() + static_cast<std::ptrdiff_t>(n));
  const std::vector<double> q(data.theta_out.begin(), data.theta_out.begin() + static_cast<std::ptrdiff_t>(n));
  double fs = 0;
  try {
    fs = measurements::uniform_sample_rate(t);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(data.source.string() + ": t: " + error.what());
  }
  Band band;
  if (std::isfinite(options.cutoff)) {
    band.cutoff = options.cutoff;
    band.from_spectrum = false;
  } else {
    const measurements::CutoffDecision c = measurements::cutoff_from_spectrum(q, fs);
    band.cutoff = c.cutoff_hz;
    band.floor = c.noise_floor;
  }
  band.filter = measurements::design_butterworth_low_pass(band.cutoff, fs);
  result.sample_rate = fs;
  result.cutoff = band.cutoff;
  result.cutoff_from_spectrum = band.from_spectrum;
  result.spectrum_floor = band.floor;
  result.position_noise = estimate_noise(q);
  {
    std::vector<double> u(n);
    for (std::size_t i = 0; i < n; ++i) u[i] = gain * (*data.drive)[i];
    result.drive_noise = estimate_noise(u);
  }
  {  // at rest: slower than three σ of the velocity noise the filter lets through
    std::vector<double> impulse(4096, 0.0);
    impulse[2048] = 1;
    const measurements::Derivatives d = measurements::derivatives(measurements::zero_phase_filter(impulse, band.filter), fs);
    double vv = 0;
    for (double x : d.velocity) vv += x * x;
    band.rest_speed = 3 * result.position_noise * std::sqrt(vv);
  }
  result.rest_speed = band.rest_speed;

  const Prepared p = prepare(data.source.filename().string(), data, gain, t_end, band, fs, options.holdout_fraction);
  Work w{p, band, ranges_of(p)};

  // The model as given, then the best nominal model.
  Theta given;
  given[kJ] = result.given.Jm + result.given.JL;
  given[kF] = result.given.Fm + result.given.FL;
  given[kTc] = file_effects.coulomb_motor + file_effects.coulomb_load;
  given[kT0] = file_effects.torque_offset;
  given[kL] = file_effects.saturation;
  given[kTau] = file_effects.delay;
  result.rms_given = rms_of(residuals_of(p, drive_torque(p, band, given[kL], given[kTau]), given));
  Theta nominal = given;
  std::vector<double> nominal_sigma(kCount, NAN);
  if (nominal_free.count() > 0) {
    const Linear l = fit(w, given, nominal_free, p.all);
    if (!l.ok)
      throw std::invalid_argument(where + ": fit.free: the free nominal parameters do not fit the record to a physical drive (J > 0, F >= 0)");
    const Polished polished = polish(w, l.m, nominal_free);
    nominal = polished.m;
    for (const auto& [name, which] : free_names) {
      const double held = which == kJ ? (name == "motor.J" ? result.given.JL : result.given.Jm)
                                      : (name == "motor.F" ? result.given.FL : result.given.Fm);
      result.nominal_fit.push_back({name, nominal[which] - held, polished.sigma[which]});
    }
  }
  auto as_parameters = [&](const Theta& m) {
    numeric::Parameters out = result.given;
    for (const auto& [name, which] : free_names) {
      if (name == "motor.J") out.Jm = m[kJ] - out.JL;
      if (name == "load.J") out.JL = m[kJ] - out.Jm;
      if (name == "motor.F") out.Fm = m[kF] - out.FL;
      if (name == "load.F") out.FL = m[kF] - out.Fm;
    }
    return out;
  };
  result.nominal = as_parameters(nominal);
  const std::vector<double> r_nominal = residuals_of(p, drive_torque(p, band, nominal[kL], nominal[kTau]), nominal);
  result.rms_before = rms_of(r_nominal);
  result.tau_int_before = measurements::integrated_autocorrelation_time(r_nominal).tau;
  result.noise = noise_level(fs, band, result.drive_noise, result.position_noise, nominal);

  // Rounds: every remaining candidate added to the current model, fitted on the fitted blocks.
  Theta current = nominal;
  FreeSet current_free = nominal_free;
  std::vector<std::string> remaining;
  for (const std::string& e : options.candidates) {
    const int which = index_of_effect(e);
    if (which < 0) throw std::invalid_argument("candidate " + e + ": not an effect of a rigid measured drive");
    const bool present = (which == kTc && given[kTc] > 0) || (which == kT0 && given[kT0] != 0) ||
                         (which == kL && std::isfinite(given[kL])) || (which == kTau && given[kTau] > 0);
    if (!present) remaining.push_back(e);
  }
  constexpr double noise_factor = 1.15;
  while (result.rms_before > noise_factor * result.noise && static_cast<int>(result.effects.size()) < options.max_effects &&
         !remaining.empty()) {
    const Linear base = fit(w, current, current_free, p.fit);
    if (!base.ok) break;
    const std::vector<double> U_base = drive_torque(p, band, base.m[kL], base.m[kTau]);
    const double base_holdout = std::sqrt(sse_on(p, U_base, base.m, p.holdout) / p.holdout.size());
    const std::vector<double> r_base = residuals_of(p, U_base, base.m);
    const double tau_int = std::max(1.0, measurements::integrated_autocorrelation_time(r_base).tau);
    const double n_eff = static_cast<double>(p.fit.size()) / tau_int;
    struct Trial {
      Candidate c;
      Theta m;
      FreeSet free;
    };
    std::vector<Trial> trials;
    for (const std::string& effect : remaining) {
      const auto t0 = std::chrono::steady_clock::now();
      const int before = w.least_squares;
      Trial trial;
      trial.c.effect = effect;
      trial.free = current_free;
      const int which = index_of_effect(effect);
      if (which < 0) continue;  // checked when the list was made
      trial.free.on[which] = true;
      Theta start = base.m;
      if (which == kL) start[kL] = w.ranges.L_max;
      const Linear l = fit(w, start, trial.free, p.fit);
      if (l.ok) {
        trial.m = l.m;
        const std::vector<double> U = drive_torque(p, band, l.m[kL], l.m[kTau]);
        trial.c.parameters = {{kEffectParameter[which], l.m[which], NAN}};
        trial.c.rms = rms_of(residuals_of(p, U, l.m));
        trial.c.rms_fit = std::sqrt(l.sse / p.fit.size());
        trial.c.rms_holdout = std::sqrt(sse_on(p, U, l.m, p.holdout) / p.holdout.size());
        trial.c.delta_bic = n_eff * std::log(std::max(l.sse, 1e-300) / std::max(base.sse, 1e-300)) + std::log(n_eff);
        trial.c.bic = n_eff * std::log(std::max(l.sse, 1e-300) / p.fit.size()) +
                      (trial.free.count() + 0.0) * std::log(n_eff);
        trial.c.at_range_edge = at_edge(w, l.m, trial.free, l.clamped);
        const bool confirmed = trial.c.rms_holdout <= options.decisive_holdout * base_holdout ||
                               (base_holdout <= noise_factor * result.noise && trial.c.rms_holdout <= 1.02 * base_holdout);
        trial.c.decisive = trial.c.delta_bic < -options.decisive_bic && confirmed && !trial.c.at_range_edge;
      } else {
        trial.c.failure = "the least-squares fit gave no physical drive (J <= 0 or F < 0)";
        trial.c.rms = trial.c.rms_fit = trial.c.rms_holdout = trial.c.bic = INFINITY;
        trial.c.delta_bic = INFINITY;
      }
      trial.c.simulations = w.least_squares - before;
      trial.c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      trials.push_back(trial);
    }
    std::stable_sort(trials.begin(), trials.end(), [](const Trial& a, const Trial& b) { return a.c.delta_bic < b.c.delta_bic; });
    std::vector<Candidate> round;
    for (const Trial& trial : trials) round.push_back(trial.c);
    result.rounds.push_back(round);
    const auto winner = std::find_if(trials.begin(), trials.end(), [](const Trial& trial) { return trial.c.decisive; });
    if (winner == trials.end()) break;
    // The winner with everything free so far, refitted on the whole record.
    const Linear whole = fit(w, winner->m, winner->free, p.all);
    current = whole.ok ? whole.m : winner->m;
    current_free = winner->free;
    result.effects.push_back(winner->c);
    remaining.erase(std::remove(remaining.begin(), remaining.end(), winner->c.effect), remaining.end());
  }

  // The corrected model: everything free polished together; uncertainties.
  if (!result.effects.empty()) {
    const Polished polished = polish(w, current, current_free);
    current = polished.m;
    for (Candidate& c : result.effects) {
      const int which = index_of_effect(c.effect);
      c.parameters = {{kEffectParameter[which], current[which], polished.sigma[which]}};
    }
    for (const auto& [name, which] : free_names) {
      const double held = which == kJ ? (name == "motor.J" ? result.given.JL : result.given.Jm)
                                      : (name == "motor.F" ? result.given.FL : result.given.Fm);
      result.corrected_nominal.push_back({name, current[which] - held, polished.sigma[which]});
    }
  }
  result.parameters = as_parameters(current);
  result.corrected_effects = file_effects;
  result.corrected_effects.coulomb_motor = current[kTc] - file_effects.coulomb_load;
  result.corrected_effects.torque_offset = current[kT0];
  result.corrected_effects.saturation = current[kL];
  result.corrected_effects.delay = current[kTau];
  const std::vector<double> U_after = drive_torque(p, band, current[kL], current[kTau]);
  const std::vector<double> r_after = residuals_of(p, U_after, current);
  result.rms_after = rms_of(r_after);
  result.tau_int_after = measurements::integrated_autocorrelation_time(r_after).tau;
  result.classes = classes_of(p, r_nominal, r_after);
  result.stretches = stretches_of(p, r_nominal, r_after);
  if (!result.effects.empty()) result.status = Status::EffectFound;
  else if (result.rms_before <= noise_factor * result.noise) result.status = Status::NoDiscrepancy;
  else result.status = Status::Unexplained;

  // Figures' traces and the position over windows.
  result.t = p.t;
  result.velocity = p.v;
  const std::vector<double> U_nominal = drive_torque(p, band, nominal[kL], nominal[kTau]);
  result.torque_measured.resize(p.size());
  result.torque_nominal.resize(p.size());
  result.torque_corrected.resize(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    result.torque_measured[k] = p.drive_f[k];
    result.torque_nominal[k] = p.drive_f[k] - r_nominal[k];
    result.torque_corrected[k] = p.drive_f[k] - r_after[k];
  }
  const WindowPrediction wn = predict_windows(p, nominal, gain, options.window, band.rest_speed);
  const WindowPrediction wc = predict_windows(p, current, gain, options.window, band.rest_speed);
  result.position = p.q;
  result.position_nominal = wn.x;
  result.position_corrected = wc.x;
  result.window_starts = wn.starts;
  result.estimation = {p.name, static_cast<int>(p.size()), result.rms_before, result.rms_after, wn.rms, wc.rms, wn.windows};

  if (validation) {
    double fs_validation = 0;
    try {
      fs_validation = measurements::uniform_sample_rate(validation->t);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(validation->source.string() + ": t: " + error.what());
    }
    if (std::fabs(fs_validation - fs) > 1e-6 * fs)
      throw std::invalid_argument(validation->source.string() + ": sampled at " + std::to_string(fs_validation) +
                                  " Hz, the estimation record at " + std::to_string(fs) + " Hz: the filter would differ");
    const Prepared pv = prepare(validation->source.filename().string(), *validation, gain, INFINITY, band, fs, 0);
    if (pv.size() < 200) throw std::invalid_argument(validation->source.string() + ": fewer than 200 samples");
    const double rn = rms_of(residuals_of(pv, drive_torque(pv, band, nominal[kL], nominal[kTau]), nominal));
    const double rc = rms_of(residuals_of(pv, drive_torque(pv, band, current[kL], current[kTau]), current));
    const WindowPrediction vn = predict_windows(pv, nominal, gain, options.window, band.rest_speed);
    const WindowPrediction vc = predict_windows(pv, current, gain, options.window, band.rest_speed);
    result.validation = DriveScores{pv.name, static_cast<int>(pv.size()), rn, rc, vn.rms, vc.rms, vn.windows};
    result.validation_t = pv.t;
    result.validation_position = pv.q;
    result.validation_nominal = vn.x;
    result.validation_corrected = vc.x;
    result.validation_window_starts = vn.starts;
  }
  result.least_squares = w.least_squares;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace backlash::discrepancy
