// The discrepancy workflow on a measured drive (measured_drive.hpp): inverse dynamics in
// the torque domain, effects named one after another by the decisive rule, the position
// checked over windows restarted from the measured state.
#include "backlash/discrepancy/measured_drive.hpp"

#include "drive_internal.hpp"
#include "quiet_ceres.hpp"
#include "two_body_signals.hpp"

#include "backlash/measurements/inverse_dynamics_signals.hpp"
#include "backlash/discrepancy/measured_drive_simulation.hpp"
#include "backlash/model/effect_table.hpp"

#include <Eigen/Dense>
#include <boost/math/tools/minima.hpp>
#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace backlash::discrepancy {

const std::vector<std::string>& drive_vocabulary() {  // the table of effects' DRIVE_RANK order
  static const std::vector<std::string> vocabulary = model::ranked_effects(&model::EffectInfo::drive_rank);
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

// One record, prepared for inverse dynamics.
//
// What the comparison is exact for.  The second difference of the position is the triangle
// average of its second derivative, (x[k+1] − 2x[k] + x[k−1])/T² = ∫ Λ(s)·x''(t_k + s) ds with
// Λ(s) = (T − |s|)/T² on |s| < T, and the zero-phase filter, linear and time-invariant, commutes
// with it.  So J·â[k] equals, exactly, the filtered triangle average of J·x'' = u + T0 − F·x' −
// friction: every force term is compared as its triangle average at t_k, filtered —
//   the drive: logged sample j acts on [t_j + τ, t_{j+1} + τ) (the zero-order hold), so its
//     triangle average at t_k is Σ_j w((t_k − t_j − τ)/T)·sat(u_j), w the hold's weights (the
//     quadratic B-spline, w(0) = w(1) = ½: without a delay the average of u[k−1] and u[k], i.e.
//     the drive half a period later than its time stamp);
//   the friction: its average s̄[k] of sgn(v) (a reversal between two samples located by
//     linear interpolation of v̂), and at rest the force that holds the drive (below);
//   the viscous term: F·v̂, the central difference (the box average of x' over ±T, which differs
//     from the triangle average by O(T²·x''') — below 10⁻⁵ of F·v in the filter's band).
// Then both sides go through the same filter (the Coulomb column included: the standard IDIM
// practice of filtering the whole linear-in-parameters equation identically).
struct Prepared {
  std::string name;
  std::vector<double> t, q;        // as measured
  double fs = 0;
  std::vector<double> v, a;        // filtered derivatives
  std::vector<double> qf;          // filtered position (window starts)
  std::vector<double> drive;       // gain·drive, as logged
  std::vector<double> drive_raw;   // the drive column itself (the simulator applies the gain)
  std::vector<signed char> sign;   // sgn v̂, 0 at rest
  std::vector<double> slip;        // s̄: sgn v averaged by Λ around t_k (moving samples)
  std::size_t begin = 0, end = 0;  // [begin, end): the filter's end transients left out
  std::vector<char> in;            // compared: in [begin, end) and not near a start or stop
  std::vector<std::size_t> fit, holdout, all;
  std::size_t size() const { return t.size(); }
  bool compared(std::size_t k) const { return in[k] != 0; }
};

using Band = detail::DriveBand;

// The filter's effective length: the smallest m such that the zero-phase impulse response
// outside ±m samples holds at most 10⁻⁴ of its absolute sum — the end transients of the
// forward–backward filter (a start from the odd extension that does not continue a moving,
// quantised position) decay with the same poles, so m samples from an end they are down to that
// fraction; two more samples for the difference stencils and the hold's weights.
std::size_t edge_samples(const measurements::ButterworthLowPass& filter) {
  const std::size_t n = 4097, middle = n / 2;
  std::vector<double> impulse(n, 0.0);
  impulse[middle] = 1;
  const std::vector<double> h = measurements::zero_phase_filter(impulse, filter);
  double total = 0;
  for (double x : h) total += std::fabs(x);
  double outside = total - std::fabs(h[middle]);
  std::size_t m = 0;
  while (outside > 1e-4 * total && m + 1 < middle) {
    ++m;
    outside -= std::fabs(h[middle - m]) + std::fabs(h[middle + m]);
  }
  return m + 2;
}

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
  p.sign.resize(n);
  // At rest: the position did not change across the sample (the same encoder count at k − 1, k
  // and k + 1), or |v̂| is below the rest speed.  The first rule matters at stick and slip: the
  // filter spreads an abrupt stop over its length, so v̂ rings around 0 for a few samples while
  // the drive is stuck, and its sign there is noise.
  for (std::size_t i = 0; i < n; ++i) {
    const bool changed = (i > 0 && p.q[i] != p.q[i - 1]) || (i + 1 < n && p.q[i + 1] != p.q[i]);
    p.sign[i] = !changed || std::fabs(p.v[i]) <= band.rest_speed ? 0 : p.v[i] > 0 ? 1 : -1;
  }
  // s̄: a reversal between moving samples k and k+1 at t_k + θ·T (θ by linear interpolation of
  // v̂) changes sign on the far side of each one's triangle: by (1 − θ)² at k, θ² at k + 1.
  p.slip.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) p.slip[i] = p.sign[i];
  for (std::size_t i = 0; i + 1 < n; ++i)
    if (p.sign[i] != 0 && p.sign[i + 1] == -p.sign[i]) {
      const double theta = p.v[i] / (p.v[i] - p.v[i + 1]);
      p.slip[i] -= p.sign[i] * (1 - theta) * (1 - theta);
      p.slip[i + 1] -= p.sign[i + 1] * theta * theta;
    }
  // What is compared.  The filter's end transients are not: the first and last `band.edge`
  // samples (the filter's effective length).  Nor are the samples within that length (and two
  // more) of a start, a stop or a reversal (a change of the sign of the motion, rest included):
  // where the friction changes there is known only to a few samples — a stop lies somewhere
  // after the last change of the encoder's count, and the filter moves the zero of v̂ at a
  // reversal, where v̂ has a kink — and a sample given the wrong friction is off by up to 2·Tc,
  // spread over the filter's length.
  p.begin = std::min(band.edge, n / 4);
  p.end = n - p.begin;
  p.in.assign(n, 0);
  for (std::size_t i = p.begin; i < p.end; ++i) p.in[i] = 1;
  const std::size_t reach = band.edge + 2;
  for (std::size_t i = 0; i + 1 < n; ++i)
    if (p.sign[i] != p.sign[i + 1])
      for (std::size_t j = i >= reach ? i - reach : 0; j <= std::min(n - 1, i + 1 + reach); ++j) p.in[j] = 0;
  const std::size_t m = p.end - p.begin;
  const int every = holdout_fraction > 0 ? std::max(2, static_cast<int>(std::lround(1 / holdout_fraction))) : 0;
  for (std::size_t i = p.begin; i < p.end; ++i) {
    if (!p.in[i]) continue;
    const int block = static_cast<int>(10 * (i - p.begin) / m);
    (every > 0 && block % every == every - 1 ? p.holdout : p.fit).push_back(i);
    p.all.push_back(i);
  }
  return p;
}

// The hold's weight of a sample acting on [0, 1) (in sample periods) in the triangle average
// at d periods after its start: C(1 − d) − C(−d), C the integral of Λ (unit period).  The
// quadratic B-spline on (−1, 2); w(0) = w(1) = ½.
double hold_weight(double d) {
  auto C = [](double x) {
    if (x <= -1) return 0.0;
    if (x <= 0) return 0.5 * (1 + x) * (1 + x);
    if (x <= 1) return 1 - 0.5 * (1 - x) * (1 - x);
    return 1.0;
  };
  return C(1 - d) - C(-d);
}

// Ū[k]: the clipped, delayed, held drive averaged by Λ around t_k (before the filter).  Before
// the record's start the first sample acts, after its end the last.
std::vector<double> held_drive(const Prepared& p, double L, double tau) {
  const std::size_t n = p.size();
  std::vector<double> out(n);
  const double mu = tau * p.fs;
  const bool clip = std::isfinite(L);
  std::vector<double> u(p.drive);
  if (clip)
    for (double& x : u) x = std::clamp(x, -L, L);
  // Sample j = k − shift − i weighs hold_weight(frac + i) at k, the same for every k.
  const double shift = std::floor(mu), frac = mu - shift;  // mu = shift + frac, 0 ≤ frac < 1
  double w[4];
  for (int i = -1; i < 3; ++i) w[i + 1] = hold_weight(static_cast<double>(i) - frac);
  const long offset = static_cast<long>(shift);
  const long last = static_cast<long>(n) - 1;
  for (std::size_t k = 0; k < n; ++k) {
    double sum = 0;
    for (int i = -1; i < 3; ++i) {
      const long j = std::clamp(static_cast<long>(k) - offset - i, 0L, last);
      sum += w[i + 1] * u[static_cast<std::size_t>(j)];
    }
    out[k] = sum;
  }
  return out;
}

// The residual, linear in J, F, Tc, T0 once it is known which samples at rest are held (the
// friction cancels the drive: |Ū + T0| ≤ Tc) and which slip (the friction is Tc against the
// net drive).  With the raw friction force φ[k] = Tc·s̄[k] moving, Ū[k] + T0 held, Tc·sgn(Ū[k] +
// T0) slipping at rest,
//   r = filter(Ū − φ) + T0 − J·â − F·v̂ = y + T0·c_T0 − J·â − F·v̂ − Tc·c_Tc
// with y = filter(Ū·(1 − held)), c_T0 = 1 − filter(held), c_Tc = filter(c), c = s̄ moving,
// sgn(Ū + T0) slipping, 0 held.  (At rest deep inside a stuck stretch r = 0: a stuck drive
// holds whatever it is given.)
struct Linearised {
  std::vector<double> y, c_t0, c_tc;
  std::vector<signed char> state;  // 0 moving, 1 held, 2 slipping at rest
};

Linearised linearise(const Prepared& p, const Band& band, const std::vector<double>& U, const Theta& m) {
  const std::size_t n = p.size();
  Linearised out;
  out.state.resize(n);
  std::vector<double> free_drive(n), held(n), c(n);
  const double tc = std::max(0.0, m[kTc]);
  for (std::size_t k = 0; k < n; ++k) {
    if (p.sign[k] != 0) {
      out.state[k] = 0, free_drive[k] = U[k], held[k] = 0, c[k] = p.slip[k];
      continue;
    }
    const double z = U[k] + m[kT0];
    if (std::fabs(z) <= tc) out.state[k] = 1, free_drive[k] = 0, held[k] = 1, c[k] = 0;
    else out.state[k] = 2, free_drive[k] = U[k], held[k] = 0, c[k] = z > 0 ? 1 : z < 0 ? -1 : 0;
  }
  out.y = measurements::zero_phase_filter(free_drive, band.filter);
  out.c_tc = measurements::zero_phase_filter(c, band.filter);
  out.c_t0.assign(n, 1.0);
  if (std::find(out.state.begin(), out.state.end(), 1) != out.state.end()) {  // else filter(held) = 0
    const std::vector<double> fh = measurements::zero_phase_filter(held, band.filter);
    for (std::size_t k = 0; k < n; ++k) out.c_t0[k] = 1 - fh[k];
  }
  return out;
}

double residual(const Prepared& p, const Linearised& l, const Theta& m, std::size_t k) {
  return l.y[k] + m[kT0] * l.c_t0[k] - m[kJ] * p.a[k] - m[kF] * p.v[k] - m[kTc] * l.c_tc[k];
}

std::vector<double> residuals_of(const Prepared& p, const Linearised& l, const Theta& m) {
  std::vector<double> r(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) r[k] = residual(p, l, m, k);
  return r;
}

double sse_on(const std::vector<double>& r, const std::vector<std::size_t>& samples) {
  double s = 0;
  for (std::size_t k : samples) s += r[k] * r[k];
  return s;
}

// Ū for the model's limit and delay, linearised at the model: the residual at every sample.
std::vector<double> residuals_of(const Prepared& p, const Band& band, const Theta& m) {
  const std::vector<double> U = held_drive(p, m[kL], m[kTau]);
  return residuals_of(p, linearise(p, band, U, m), m);
}

// The RMS over the compared samples.
double rms_compared(const Prepared& p, const std::vector<double>& r) {
  return std::sqrt(sse_on(r, p.all) / static_cast<double>(std::max<std::size_t>(1, p.all.size())));
}

// τ_int of the compared samples' residuals, joined across the gaps left out.
double tau_int_compared(const Prepared& p, const std::vector<double>& r) {
  std::vector<double> inner;
  inner.reserve(p.all.size());
  for (std::size_t k : p.all) inner.push_back(r[k]);
  return measurements::integrated_autocorrelation_time(inner).tau;
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

// The linear parameters (J, F, Tc, T0 where free) by least squares on `samples`, the others
// held.  Which samples at rest are held depends on Tc and T0: solved for the pattern of the
// starting point, the pattern recomputed at the solution, and again, until it no longer changes
// (at most 8 times; the best point seen is kept).  Tc < 0 is refitted at Tc = 0 (then `clamped`).
struct Linear {
  Theta m;
  bool ok = false;
  bool clamped = false;
  double sse = INFINITY;
};

Linear solve_linear(Work& w, const std::vector<double>& U, const Theta& start, const FreeSet& free,
                    const std::vector<std::size_t>& samples) {
  ++w.least_squares;
  Linear out;
  std::vector<int> columns;
  for (int i : {kJ, kF, kTc, kT0})
    if (free.on[i]) columns.push_back(i);
  // With Tc free and not yet estimated (0), the first pattern holds every sample at rest (as an
  // infinite Tc would): the moving samples then fix Tc, and the samples at rest whose drive
  // exceeds it slip.  (From Tc = 0 instead, every sample at rest would pull Tc towards its own
  // holding force, and the pattern would creep up over many iterations.)
  Theta pattern_from = start;
  if (free.on[kTc] && !(start[kTc] > 0)) pattern_from[kTc] = INFINITY;
  Linearised l = linearise(w.p, w.band, U, pattern_from);
  if (columns.empty()) {
    if (!(start[kJ] > 0) || start[kF] < 0) return out;
    out.m = start, out.ok = true, out.sse = sse_on(residuals_of(w.p, l, start), samples);
    return out;
  }
  if (samples.size() < columns.size() + 2) return out;
  Theta m = start;
  for (int iteration = 0; iteration < 8; ++iteration) {
    bool clamped = false;
    std::vector<int> cols = columns;
    Theta x = m;
    for (int attempt = 0; attempt < 2; ++attempt) {
      Eigen::MatrixXd A(samples.size(), cols.size());
      Eigen::VectorXd y(samples.size());
      std::size_t row = 0;
      for (std::size_t k : samples) {
        // r = y + T0·c_T0 − J·â − F·v̂ − Tc·c_Tc: the held terms into the right-hand side.
        const double col[4] = {-w.p.a[k], -w.p.v[k], -l.c_tc[k], l.c_t0[k]};
        double rhs = l.y[k];
        for (int i : {kJ, kF, kTc, kT0})
          if (std::find(cols.begin(), cols.end(), i) == cols.end()) rhs += x[i] * col[i];
        for (std::size_t c = 0; c < cols.size(); ++c) A(row, c) = col[cols[c]];
        y(row++) = -rhs;
      }
      const Eigen::VectorXd solution = A.colPivHouseholderQr().solve(y);
      if (!solution.allFinite()) return out;
      for (std::size_t c = 0; c < cols.size(); ++c) x[cols[c]] = solution(c);
      if (free.on[kTc] && x[kTc] < 0) {
        x[kTc] = 0;
        cols.erase(std::find(cols.begin(), cols.end(), static_cast<int>(kTc)));
        clamped = true;
        if (cols.empty()) break;
        continue;
      }
      break;
    }
    if (!free.on[kTc] && !free.on[kT0] && iteration == 0) {  // the pattern is fixed
      if (x[kJ] > 0 && x[kF] >= 0) out.m = x, out.ok = true, out.clamped = clamped, out.sse = sse_on(residuals_of(w.p, l, x), samples);
      break;
    }
    Linearised next = linearise(w.p, w.band, U, x);
    if (x[kJ] > 0 && x[kF] >= 0) {
      const double sse = sse_on(residuals_of(w.p, next, x), samples);
      if (sse < out.sse) out.m = x, out.ok = true, out.clamped = clamped, out.sse = sse;
    }
    const bool same = next.state == l.state;
    l = std::move(next);
    m = x;
    if (same) break;
  }
  return out;  // ok = false: not a physical drive (J ≤ 0 or F < 0), a failed fit
}

// The whole fit: the nonlinear parameters (τ, L) by a scan and Brent's minimisation of the
// profiled least-squares cost, the linear ones by least squares at each point.
Linear fit(Work& w, Theta start, const FreeSet& free, const std::vector<std::size_t>& samples) {
  auto at = [&](const Theta& m) {
    const std::vector<double> U = held_drive(w.p, m[kL], m[kTau]);
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
    set_num_residuals(static_cast<int>(w->p.all.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(order.size()));
  }
  Theta theta(const double* x) const {
    Theta m = fixed;
    for (std::size_t j = 0; j < order.size(); ++j) m[order[j]] = x[j];
    return m;
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Theta m = theta(parameters[0]);
    const Prepared& p = w->p;
    const Linearised l = linearise(p, w->band, held_drive(p, m[kL], m[kTau]), m);
    const std::size_t n = p.all.size(), k = order.size();
    for (std::size_t i = 0; i < n; ++i) residuals[i] = residual(p, l, m, p.all[i]);
    if (!jacobians || !jacobians[0]) return true;
    double* J = jacobians[0];
    for (std::size_t c = 0; c < k; ++c) {
      const int which = order[c];
      if (which == kTau || which == kL) {  // central differences through the hold, the clipping and the filter
        const double h = which == kTau ? 0.25 / p.fs : 1e-4 * m[kL];
        Theta up = m, down = m;
        up[which] += h;
        down[which] = std::max(0.0, down[which] - h);
        const double span = up[which] - down[which];
        const std::vector<double> ru = residuals_of(p, w->band, up), rd = residuals_of(p, w->band, down);
        for (std::size_t i = 0; i < n; ++i) J[i * k + c] = (ru[p.all[i]] - rd[p.all[i]]) / span;
        continue;
      }
      for (std::size_t i = 0; i < n; ++i) {  // the linear columns, for the held/slipping pattern at m
        const std::size_t s = p.all[i];
        const double col[4] = {-p.a[s], -p.v[s], -l.c_tc[s], l.c_t0[s]};
        J[i * k + c] = col[which];
      }
    }
    return true;
  }
};

// Polishes a whole-record fit with Levenberg–Marquardt (all free parameters together) and
// returns one standard deviation per parameter: Ceres's covariance scaled by the residual
// variance and by τ_int (the residuals are not independent).
struct Polished {
  Theta m;
  double sigma[kCount] = {NAN, NAN, NAN, NAN, NAN, NAN};
  double tau_int = 1;
};

Polished polish(Work& w, const Theta& start, const FreeSet& free) {
  detail::quiet_ceres();
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
  if (sse_on(residuals_of(w.p, w.band, polished), w.p.all) <= sse_on(residuals_of(w.p, w.band, start), w.p.all)) out.m = polished;
  else for (std::size_t j = 0; j < cost->order.size(); ++j) x[j] = start[cost->order[j]];
  const std::vector<double> r_all = residuals_of(w.p, w.band, out.m);
  std::vector<double> r;
  for (std::size_t k : w.p.all) r.push_back(r_all[k]);
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

RigidDrive rigid_drive(const Theta& m, double gain) {
  RigidDrive d;
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
  const RigidDrive drive = rigid_drive(m, gain);
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t first = 0; first + 1 < p.size(); first += length) {
    const std::size_t last = std::min(first + length, p.size() - 1);
    const double v0 = std::fabs(p.v[first]) <= rest_speed ? 0.0 : p.v[first];
    const MeasuredDriveRun run =
        simulate_measured_drive(drive, p.t, p.drive_raw, first, last, p.qf[first], v0);
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
  std::vector<double> sorted(abs_a.begin() + static_cast<std::ptrdiff_t>(p.begin), abs_a.begin() + static_cast<std::ptrdiff_t>(p.end));
  const std::size_t m = sorted.size();
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(9 * m / 10), sorted.end());
  const double high = sorted[9 * m / 10];
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
    for (std::size_t i = p.begin; i < p.end; ++i) {
      if (!p.compared(i) || !in(i)) continue;
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
  const std::size_t n = p.end;
  std::size_t start = p.begin;
  auto kind_of = [&](std::size_t i) { return p.sign[i] > 0 ? "forward" : p.sign[i] < 0 ? "backward" : "rest"; };
  for (std::size_t i = start + 1; i <= n; ++i) {
    if (i < n && p.sign[i] == p.sign[start]) continue;
    TorqueRegion r;
    r.kind = kind_of(start);
    r.t_start = p.t[start];
    r.t_end = p.t[i - 1];
    double sb = 0, sa = 0, mb = 0, ma = 0;
    for (std::size_t k = start; k < i; ++k) {
      if (!p.compared(k)) continue;  // the stretch's compared samples
      sb += before[k] * before[k], sa += after[k] * after[k], mb += before[k], ma += after[k];
      ++r.samples;
    }
    if (r.samples > 0) {
      r.rms_before = std::sqrt(sb / r.samples), r.rms_after = std::sqrt(sa / r.samples);
      r.mean_before = mb / r.samples, r.mean_after = ma / r.samples;
    }
    out.push_back(r);
    start = i;
  }
  return out;
}


// The torque residual's noise level: the drive's and the position's noise propagated through
// the filter and the differences (the sum of squares of each operator's impulse response), the
// drive's through the hold's weights at the model's delay.
double noise_level(double fs, const Band& band, double drive_noise, double position_noise, const Theta& m) {
  const detail::NoiseGains g = detail::noise_gains(band.filter, fs, m[kTau] * fs);
  return std::sqrt(drive_noise * drive_noise * g.hold +
                   position_noise * position_noise * (m[kJ] * m[kJ] * g.acceleration + m[kF] * m[kF] * g.velocity));
}

// The model and records a measured-drive workflow needs: a drive experiment, no backlash, the
// logged drive in every record.
void check_drive_inputs(const model::CaseSpec& spec, const std::string& where, const measurements::MeasuredRecord& data,
                        const measurements::MeasuredRecord* validation) {
  if (!spec.experiment || spec.experiment->kind != model::ExperimentKind::Drive)
    throw std::invalid_argument(where + ": the model's [experiment] is not a measured drive (kind = \"drive\")");
  if (!data.drive) throw std::invalid_argument(data.source.string() + ": no drive column: a measured-drive model needs the logged drive");
  if (validation && !validation->drive)
    throw std::invalid_argument(validation->source.string() + ": no drive column: a measured-drive model needs the logged drive");
  for (const measurements::MeasuredRecord* record : {&data, validation})
    if (record && record->theta_out.size() != record->size())
      throw std::invalid_argument(record->source.string() +
                                  ":1: theta_out: missing column: a rigid drive's record gives the measured shaft (t, theta_out, drive)");
}

// The free nominal parameters: on a rigid drive only J and F show (the names as given, with
// the parameter each one moves).
FreeSet nominal_free_of(const model::CaseSpec& spec, const std::string& where,
                        std::vector<std::pair<std::string, int>>& free_names) {
  FreeSet nominal_free;
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
  return nominal_free;
}

// The band: the cut-off (given, or from the position's spectrum), the filter, its edge, the
// noise levels and the speed below which a sample is at rest (three σ of the velocity noise the
// filter lets through).
Band band_of(const std::vector<double>& q, const std::vector<double>& u, double fs, const DriveOptions& options,
             DriveDiscrepancyResult& result) {
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
  band.edge = edge_samples(band.filter);
  result.sample_rate = fs;
  result.cutoff = band.cutoff;
  result.cutoff_from_spectrum = band.from_spectrum;
  result.spectrum_floor = band.floor;
  result.position_noise = estimate_noise(q);
  result.drive_noise = estimate_noise(u);
  std::vector<double> impulse(4096, 0.0);
  impulse[2048] = 1;
  const measurements::Derivatives d = measurements::derivatives(measurements::zero_phase_filter(impulse, band.filter), fs);
  double vv = 0;
  for (double x : d.velocity) vv += x * x;
  band.rest_speed = 3 * result.position_noise * std::sqrt(vv);
  result.rest_speed = band.rest_speed;
  return band;
}

// The nominal parameters as the file names them, from J = Jm + JL and F = Fm + FL: the free
// one takes the difference, the other is held.
numeric::Parameters as_parameters(const numeric::Parameters& given, const std::vector<std::pair<std::string, int>>& free_names,
                                  const Theta& m) {
  numeric::Parameters out = given;
  for (const auto& [name, which] : free_names) {
    if (name == "motor.J") out.Jm = m[kJ] - out.JL;
    if (name == "load.J") out.JL = m[kJ] - out.Jm;
    if (name == "motor.F") out.Fm = m[kF] - out.FL;
    if (name == "load.F") out.FL = m[kF] - out.Fm;
  }
  return out;
}

// The fitted free nominal parameters as the file names them, with their uncertainties.
std::vector<Parameter> named_nominal(const numeric::Parameters& given, const std::vector<std::pair<std::string, int>>& free_names,
                                     const Theta& m, const double* sigma) {
  std::vector<Parameter> out;
  for (const auto& [name, which] : free_names) {
    const double held = which == kJ ? (name == "motor.J" ? given.JL : given.Jm) : (name == "motor.F" ? given.FL : given.Fm);
    out.push_back({name, m[which] - held, sigma[which]});
  }
  return out;
}

// The search runs whatever the nominal model's residual: the noise level is an estimate that
// can be far too high in a closed loop (the Δ⁴ rule counts the controller's reaction to the
// encoder's quantisation, a real and logged force, as drive noise), so it does not stop the
// search; the decisive rule does, and the noise level only labels a quiet record's status.
constexpr double kNoiseFactor = 1.15;

// One trial of a round: the effects added to the current model, fitted on the fitted blocks.
struct Trial {
  Candidate c;
  std::vector<std::string> effects;
  Theta m;
  FreeSet free;
};

// One round of the search: the current model fitted on the fitted blocks (`base`), and trials
// judged against it by the decisive rule with one BIC penalty per added parameter.
struct Round {
  Work& w;
  const DriveOptions& options;
  const Linear& base;
  const FreeSet& current_free;
  double noise, base_holdout, n_eff;

  Trial trial(const std::vector<std::string>& effects) const {
    const Prepared& p = w.p;
    const auto t0 = std::chrono::steady_clock::now();
    const int before = w.least_squares;
    Trial trial;
    trial.effects = effects;
    trial.free = current_free;
    Theta start = base.m;
    for (const std::string& effect : effects) {
      trial.c.effect += (trial.c.effect.empty() ? "" : "+") + effect;
      const int which = index_of_effect(effect);
      trial.free.on[which] = true;
      if (which == kL) start[kL] = w.ranges.L_max;
    }
    const Linear l = fit(w, start, trial.free, p.fit);
    if (l.ok) {
      trial.m = l.m;
      judge(l, effects, trial);
    } else {
      trial.c.failure = "the least-squares fit gave no physical drive (J <= 0 or F < 0)";
      trial.c.rms = trial.c.rms_fit = trial.c.rms_holdout = trial.c.bic = INFINITY;
      trial.c.delta_bic = INFINITY;
    }
    trial.c.simulations = w.least_squares - before;
    trial.c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return trial;
  }

  void judge(const Linear& l, const std::vector<std::string>& effects, Trial& trial) const {
    const Prepared& p = w.p;
    const std::vector<double> r = residuals_of(p, w.band, l.m);
    for (const std::string& effect : effects) {
      const int which = index_of_effect(effect);
      trial.c.parameters.push_back({kEffectParameter[which], l.m[which], NAN});
    }
    const double added = static_cast<double>(effects.size());
    trial.c.rms = rms_compared(p, r);
    trial.c.rms_fit = std::sqrt(l.sse / p.fit.size());
    trial.c.rms_holdout = std::sqrt(sse_on(r, p.holdout) / p.holdout.size());
    trial.c.delta_bic = n_eff * std::log(std::max(l.sse, 1e-300) / std::max(base.sse, 1e-300)) + added * std::log(n_eff);
    trial.c.bic = n_eff * std::log(std::max(l.sse, 1e-300) / p.fit.size()) + (trial.free.count() + 0.0) * std::log(n_eff);
    trial.c.at_range_edge = at_edge(w, l.m, trial.free, l.clamped);
    const bool confirmed = trial.c.rms_holdout <= options.decisive_holdout * base_holdout ||
                           (base_holdout <= kNoiseFactor * noise && trial.c.rms_holdout <= 1.02 * base_holdout);
    trial.c.decisive = trial.c.delta_bic < -options.decisive_bic && confirmed && !trial.c.at_range_edge;
  }
};

// The candidates not already in the model.
std::vector<std::string> remaining_candidates(const DriveOptions& options, const Theta& given) {
  std::vector<std::string> remaining;
  for (const std::string& e : options.candidates) {
    const int which = index_of_effect(e);
    if (which < 0) throw std::invalid_argument("candidate " + e + ": not an effect of a rigid measured drive");
    const bool present = (which == kTc && given[kTc] > 0) || (which == kT0 && given[kT0] != 0) ||
                         (which == kL && std::isfinite(given[kL])) || (which == kTau && given[kTau] > 0);
    if (!present) remaining.push_back(e);
  }
  return remaining;
}

// One round: every remaining effect tried alone and, when none is decisive, in pairs (two
// effects can each be too weak alone — the nominal parameters absorb part of each, a viscous
// friction raised by a missing Coulomb friction — and decisive together).  The round's
// candidates go to the result; the winner, if any, is named.  False: no winner, the search ends.
bool search_round(Work& w, const DriveOptions& options, double noise, Theta& current, FreeSet& current_free,
                  std::vector<std::string>& remaining, DriveDiscrepancyResult& result) {
  const Prepared& p = w.p;
  const Linear base = fit(w, current, current_free, p.fit);
  if (!base.ok) return false;
  const std::vector<double> r_base = residuals_of(p, w.band, base.m);
  const double base_holdout = std::sqrt(sse_on(r_base, p.holdout) / p.holdout.size());
  const double tau_int = std::max(1.0, tau_int_compared(p, r_base));
  const Round round{w, options, base, current_free, noise, base_holdout, static_cast<double>(p.fit.size()) / tau_int};
  auto by_delta_bic = [](const Trial& a, const Trial& b) { return a.c.delta_bic < b.c.delta_bic; };
  std::vector<Trial> trials;
  for (const std::string& effect : remaining) trials.push_back(round.trial({effect}));
  std::stable_sort(trials.begin(), trials.end(), by_delta_bic);
  auto winner = std::find_if(trials.begin(), trials.end(), [](const Trial& trial) { return trial.c.decisive; });
  if (winner == trials.end() && remaining.size() >= 2 && static_cast<int>(result.effects.size()) + 2 <= options.max_effects) {
    std::vector<Trial> pairs;
    for (std::size_t i = 0; i < trials.size(); ++i)  // in the order of the single trials
      for (std::size_t j = i + 1; j < trials.size(); ++j) pairs.push_back(round.trial({trials[i].effects[0], trials[j].effects[0]}));
    std::stable_sort(pairs.begin(), pairs.end(), by_delta_bic);
    const std::size_t singles = trials.size();
    trials.insert(trials.end(), pairs.begin(), pairs.end());
    winner = std::find_if(trials.begin() + static_cast<std::ptrdiff_t>(singles), trials.end(),
                          [](const Trial& trial) { return trial.c.decisive; });
  }
  std::vector<Candidate> candidates;
  for (const Trial& trial : trials) candidates.push_back(trial.c);
  result.rounds.push_back(candidates);
  if (winner == trials.end()) return false;
  // The winner with everything free so far, refitted on the whole record.
  const Linear whole = fit(w, winner->m, winner->free, p.all);
  current = whole.ok ? whole.m : winner->m;
  current_free = winner->free;
  for (std::size_t e = 0; e < winner->effects.size(); ++e) {
    Candidate named = winner->c;
    named.effect = winner->effects[e];
    named.parameters = {winner->c.parameters[e]};
    result.effects.push_back(named);
    remaining.erase(std::remove(remaining.begin(), remaining.end(), winner->effects[e]), remaining.end());
  }
  return true;
}

// The figures' traces: velocity, the torque measured (the held drive, no delay, no limit,
// through the filter) and what each model needs, and the position predicted over windows.
void estimation_traces(const Prepared& p, const Band& band, const std::vector<double>& r_nominal,
                       const std::vector<double>& r_after, const Theta& nominal, const Theta& current, double gain,
                       const DriveOptions& options, DriveDiscrepancyResult& result) {
  result.t = p.t;
  result.velocity = p.v;
  const std::vector<double> drive_f = measurements::zero_phase_filter(held_drive(p, INFINITY, 0), band.filter);
  result.torque_measured.resize(p.size());
  result.torque_nominal.resize(p.size());
  result.torque_corrected.resize(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    result.torque_measured[k] = drive_f[k];
    result.torque_nominal[k] = drive_f[k] - r_nominal[k];
    result.torque_corrected[k] = drive_f[k] - r_after[k];
  }
  const WindowPrediction wn = predict_windows(p, nominal, gain, options.window, band.rest_speed);
  const WindowPrediction wc = predict_windows(p, current, gain, options.window, band.rest_speed);
  result.position = p.q;
  result.position_nominal = wn.x;
  result.position_corrected = wc.x;
  result.window_starts = wn.starts;
  result.estimation = {p.name, static_cast<int>(p.size()), result.rms_before, result.rms_after, wn.rms, wc.rms, wn.windows};
}

// The validation record (not fitted): sampled as the estimation record, scored with both models.
void score_validation(const measurements::MeasuredRecord& validation, const Band& band, double fs, double gain,
                      const Theta& nominal, const Theta& current, const DriveOptions& options,
                      DriveDiscrepancyResult& result) {
  double fs_validation = 0;
  try {
    fs_validation = measurements::uniform_sample_rate(validation.t);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(validation.source.string() + ": t: " + error.what());
  }
  if (std::fabs(fs_validation - fs) > 1e-6 * fs)
    throw std::invalid_argument(validation.source.string() + ": sampled at " + std::to_string(fs_validation) +
                                " Hz, the estimation record at " + std::to_string(fs) + " Hz: the filter would differ");
  const Prepared pv = prepare(validation.source.filename().string(), validation, gain, INFINITY, band, fs, 0);
  if (pv.size() < 200) throw std::invalid_argument(validation.source.string() + ": fewer than 200 samples");
  const double rn = rms_compared(pv, residuals_of(pv, band, nominal));
  const double rc = rms_compared(pv, residuals_of(pv, band, current));
  const WindowPrediction vn = predict_windows(pv, nominal, gain, options.window, band.rest_speed);
  const WindowPrediction vc = predict_windows(pv, current, gain, options.window, band.rest_speed);
  result.validation = DriveScores{pv.name, static_cast<int>(pv.size()), rn, rc, vn.rms, vc.rms, vn.windows};
  result.validation_t = pv.t;
  result.validation_position = pv.q;
  result.validation_nominal = vn.x;
  result.validation_corrected = vc.x;
  result.validation_window_starts = vn.starts;
}

// The model as given in the file, in the workflow's parameters.
Theta given_theta(const numeric::Parameters& given, const numeric::Effects& file_effects) {
  Theta m;
  m[kJ] = given.Jm + given.JL;
  m[kF] = given.Fm + given.FL;
  m[kTc] = file_effects.coulomb_motor + file_effects.coulomb_load;
  m[kT0] = file_effects.torque_offset;
  m[kL] = file_effects.saturation;
  m[kTau] = file_effects.delay;
  return m;
}

// The estimation record up to t_end, uniformly sampled.
std::size_t samples_before(const measurements::MeasuredRecord& data, double t_end, double& fs) {
  std::size_t n = data.size();
  while (n > 0 && data.t[n - 1] > t_end) --n;
  if (n < 200) throw std::invalid_argument(data.source.string() + ": fewer than 200 samples before t_end: too short for inverse dynamics");
  const std::vector<double> t(data.t.begin(), data.t.begin() + static_cast<std::ptrdiff_t>(n));
  try {
    fs = measurements::uniform_sample_rate(t);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(data.source.string() + ": t: " + error.what());
  }
  return n;
}

}  // namespace

detail::DriveBand detail::drive_band(const std::vector<double>& q, const std::vector<double>& u, double fs,
                                     const DriveOptions& options, DriveDiscrepancyResult& result) {
  return band_of(q, u, fs, options, result);
}

std::size_t detail::drive_filter_edge(const measurements::ButterworthLowPass& filter) { return edge_samples(filter); }

namespace {

// The rigid drive (backlash 0).
DriveDiscrepancyResult find_rigid_drive(const model::CaseSpec& spec, const measurements::MeasuredRecord& data,
                                        const DriveOptions& options, const measurements::MeasuredRecord* validation) {
  const auto started = std::chrono::steady_clock::now();
  const std::string where = spec.source.filename().string();
  check_drive_inputs(spec, where, data, validation);
  const double gain = model::to_double(spec.experiment->drive_gain);
  const double t_end = spec.experiment->t_end ? model::to_double(*spec.experiment->t_end) : INFINITY;
  DriveDiscrepancyResult result;
  result.given = numeric::parameters_of(spec);
  const numeric::Effects file_effects = numeric::effects_of(spec);
  (void)rigid_drive_of(result.given, file_effects, gain);  // refuses effects that need a gap
  std::vector<std::pair<std::string, int>> free_names;
  const FreeSet nominal_free = nominal_free_of(spec, where, free_names);

  double fs = 0;
  const std::size_t n = samples_before(data, t_end, fs);
  const std::vector<double> q(data.theta_out.begin(), data.theta_out.begin() + static_cast<std::ptrdiff_t>(n));
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = gain * (*data.drive)[i];
  const Band band = band_of(q, u, fs, options, result);
  const Prepared p = prepare(data.source.filename().string(), data, gain, t_end, band, fs, options.holdout_fraction);
  Work w{p, band, ranges_of(p)};

  // The model as given, then the best nominal model.
  const Theta given = given_theta(result.given, file_effects);
  result.rms_given = rms_compared(p, residuals_of(p, band, given));
  Theta nominal = given;
  if (nominal_free.count() > 0) {
    const Linear l = fit(w, given, nominal_free, p.all);
    if (!l.ok)
      throw std::invalid_argument(where + ": fit.free: the free nominal parameters do not fit the record to a physical drive (J > 0, F >= 0)");
    const Polished polished = polish(w, l.m, nominal_free);
    nominal = polished.m;
    result.nominal_fit = named_nominal(result.given, free_names, nominal, polished.sigma);
  }
  result.nominal = as_parameters(result.given, free_names, nominal);
  const std::vector<double> r_nominal = residuals_of(p, band, nominal);
  result.rms_before = rms_compared(p, r_nominal);
  result.tau_int_before = tau_int_compared(p, r_nominal);
  result.noise = noise_level(fs, band, result.drive_noise, result.position_noise, nominal);

  // Rounds: every remaining candidate added to the current model, fitted on the fitted blocks.
  Theta current = nominal;
  FreeSet current_free = nominal_free;
  std::vector<std::string> remaining = remaining_candidates(options, given);
  while (static_cast<int>(result.effects.size()) < options.max_effects && !remaining.empty())
    if (!search_round(w, options, result.noise, current, current_free, remaining, result)) break;

  // The corrected model: everything free polished together; uncertainties.
  if (!result.effects.empty()) {
    const Polished polished = polish(w, current, current_free);
    current = polished.m;
    for (Candidate& c : result.effects) {
      const int which = index_of_effect(c.effect);
      c.parameters = {{kEffectParameter[which], current[which], polished.sigma[which]}};
    }
    result.corrected_nominal = named_nominal(result.given, free_names, current, polished.sigma);
  }
  result.parameters = as_parameters(result.given, free_names, current);
  result.corrected_effects = file_effects;
  result.corrected_effects.coulomb_motor = current[kTc] - file_effects.coulomb_load;
  result.corrected_effects.torque_offset = current[kT0];
  result.corrected_effects.saturation = current[kL];
  result.corrected_effects.delay = current[kTau];
  const std::vector<double> r_after = residuals_of(p, band, current);
  result.rms_after = rms_compared(p, r_after);
  result.tau_int_after = tau_int_compared(p, r_after);
  result.classes = classes_of(p, r_nominal, r_after);
  result.stretches = stretches_of(p, r_nominal, r_after);
  if (!result.effects.empty()) result.status = Status::EffectFound;
  else if (result.rms_before <= kNoiseFactor * result.noise) result.status = Status::NoDiscrepancy;
  else result.status = Status::Unexplained;

  estimation_traces(p, band, r_nominal, r_after, nominal, current, gain, options, result);
  if (validation) score_validation(*validation, band, fs, gain, nominal, current, options, result);
  result.least_squares = w.least_squares;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace

DriveDiscrepancyResult find_drive_discrepancy(const model::CaseSpec& spec, const measurements::MeasuredRecord& data,
                                              const DriveOptions& options, const measurements::MeasuredRecord* validation) {
  if (!spec.experiment || spec.experiment->kind != model::ExperimentKind::Drive || spec.backlash == 0)
    return find_rigid_drive(spec, data, options, validation);
  // A drive with a gap: two bodies (two_body_drive.hpp).
  const auto started = std::chrono::steady_clock::now();
  if (validation)
    throw std::invalid_argument(validation->source.string() + ": a validation record is not yet scored on a drive with a gap (backlash > 0)");
  DriveDiscrepancyResult result = two_body::find(spec, data, options);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

namespace detail {

NoiseGains noise_gains(const measurements::ButterworthLowPass& filter, double fs, double delay_samples) {
  const std::size_t n = 4096, middle = n / 2;
  std::vector<double> impulse(n, 0.0), held(n, 0.0);
  impulse[middle] = 1;
  for (std::size_t k = 0; k < n; ++k) held[k] = hold_weight(static_cast<double>(k) - delay_samples - static_cast<double>(middle));
  const std::vector<double> h = measurements::zero_phase_filter(impulse, filter);
  const std::vector<double> hu = measurements::zero_phase_filter(held, filter);
  const measurements::Derivatives d = measurements::derivatives(h, fs);
  NoiseGains g;
  for (std::size_t i = 0; i < n; ++i) {
    g.hold += hu[i] * hu[i], g.velocity += d.velocity[i] * d.velocity[i], g.acceleration += d.acceleration[i] * d.acceleration[i];
    g.high += (impulse[i] - h[i]) * (impulse[i] - h[i]);
  }
  return g;
}

}  // namespace detail

}  // namespace backlash::discrepancy
