// The measured-drive workflow on a drive with a gap (two_body_drive.hpp): the record prepared,
// the load's parameters and the frictions from the summed equation, the effects named by the
// decisive rule, the backlash from the gap (both encoders) or from the load observer (the motor
// encoder alone), the lost motion at each reversal.
#include "two_body_signals.hpp"

#include "drive_internal.hpp"

#include "backlash/numeric/effects.hpp"
#include "backlash/numeric/parameters.hpp"

#include <Eigen/Dense>
#include <boost/math/tools/minima.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace backlash::discrepancy::two_body {

namespace {

constexpr double kNoiseFactor = 1.15;  // as the rigid workflow's: a residual within it is noise

}  // namespace

void filter_signals(Signals& s, const measurements::ButterworthLowPass& filter, std::size_t edge) {
  const std::size_t n = s.size();
  s.filter = filter;
  s.reach = edge + 2;
  s.begin = std::min(edge, n / 4);
  s.end = n - s.begin;
  s.qmf = measurements::zero_phase_filter(s.qm, s.filter);
  const measurements::Derivatives d = measurements::derivatives(s.qmf, s.fs);
  s.vm = d.velocity;
  s.am = d.acceleration;
  s.sm = signs_of(s.qm, s.vm, s.rest_speed, true);
  s.sm_f = measurements::zero_phase_filter(std::vector<double>(s.sm.begin(), s.sm.end()), s.filter);
  std::vector<double> held(n);
  for (std::size_t k = 0; k < n; ++k) held[k] = 0.5 * (s.u[k] + s.u[k == 0 ? 0 : k - 1]);  // the zero-order hold's average
  s.Uf = measurements::zero_phase_filter(held, s.filter);
}

namespace {

// The record: uniform sampling, the band (the cut-off from the motor position's spectrum unless
// given), the filtered motor signals and the held drive.
Signals prepare(const model::CaseSpec& spec, const measurements::MeasuredRecord& data, const DriveOptions& options,
                DriveDiscrepancyResult& result) {
  Signals s;
  s.name = data.source.filename().string();
  const double gain = model::to_double(spec.experiment->drive_gain);
  const double t_end = spec.experiment->t_end ? model::to_double(*spec.experiment->t_end) : INFINITY;
  std::size_t n = data.size();
  while (n > 0 && data.t[n - 1] > t_end) --n;
  if (n < 200) throw std::invalid_argument(data.source.string() + ": fewer than 200 samples before t_end: too short for inverse dynamics");
  auto head = [n](const std::vector<double>& v) { return std::vector<double>(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n)); };
  s.t = head(data.t);
  s.qm = head(*data.theta_motor);
  if (data.theta_load) s.qL = head(*data.theta_load);
  s.u = head(*data.drive);
  for (double& x : s.u) x *= gain;
  try {
    s.fs = measurements::uniform_sample_rate(s.t);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(data.source.string() + ": t: " + error.what());
  }
  const detail::DriveBand band = detail::drive_band(s.qm, s.u, s.fs, options, result);
  s.rest_speed = band.rest_speed;
  if (s.qL.empty() && !std::isfinite(options.cutoff)) {
    // The motor encoder alone: the load observer's contact is rigid, which holds below the mesh's
    // resonance; the band is cut at a quarter of the spectrum's cut-off (docs/discrepancy.md).
    result.cutoff = band.cutoff / 4;
    const measurements::ButterworthLowPass filter = measurements::design_butterworth_low_pass(result.cutoff, s.fs);
    filter_signals(s, filter, detail::drive_filter_edge(filter));
    return s;
  }
  filter_signals(s, band.filter, band.edge);
  return s;
}

// The model as the file gives it.
Theta given_theta(const numeric::Parameters& p, const numeric::Effects& e) {
  return {p.Jm, p.Fm, p.JL, p.FL, e.coulomb_motor, e.coulomb_load, e.torque_offset};
}

// The nominal parameters fitted: the load's inertia and viscous friction always, the motor's when
// the file marks them free ([fit] free); anything else is refused, naming the key.
FreeSet nominal_free_of(const model::CaseSpec& spec, const std::string& where) {
  FreeSet free{};
  free[kJL] = free[kFL] = true;
  for (const std::string& name : spec.fit_free) {
    if (name == "motor.J") free[kJm] = true;
    else if (name == "motor.F") free[kFm] = true;
    else if (name != "load.J" && name != "load.F" && name != "backlash")
      throw std::invalid_argument(where + ": fit.free: " + name +
                                  (name == "K" ? " is not part of a measured-drive model (the loop is open)"
                                               : " cannot be fitted on a measured drive"));
  }
  return free;
}

// The samples of the fitted blocks (seven of ten: the third, sixth and ninth held out) and the
// held-out ones.
void split_blocks(const Signals& s, const std::vector<std::size_t>& all, std::vector<std::size_t>& fit,
                  std::vector<std::size_t>& holdout) {
  const std::size_t m = std::max<std::size_t>(1, s.end - s.begin);
  for (std::size_t k : all) {
    const std::size_t block = 10 * (k - s.begin) / m;
    (block % 3 == 2 ? holdout : fit).push_back(k);
  }
}

double sse_on(const std::vector<double>& r, const std::vector<std::size_t>& samples) {
  double sum = 0;
  for (std::size_t k : samples) sum += r[k] * r[k];
  return sum;
}

double rms_on(const std::vector<double>& r, const std::vector<std::size_t>& samples) {
  return std::sqrt(sse_on(r, samples) / static_cast<double>(std::max<std::size_t>(1, samples.size())));
}

double tau_int_on(const std::vector<double>& r, const std::vector<std::size_t>& samples) {
  std::vector<double> inner;
  for (std::size_t k : samples) inner.push_back(r[k]);
  return tau_int_or_one(inner);
}

// The effects the summed equation can name, in the order tried.
const std::vector<std::pair<std::string, int>>& effect_columns() {
  static const std::vector<std::pair<std::string, int>> columns{{"coulomb_motor", kTm}, {"coulomb_load", kTL}, {"torque_offset", kT0}};
  return columns;
}

}  // namespace

// ------------------------------------------------------------------ the decisive rule

namespace {

struct Search {
  const Signals& s;
  const LoadSide& l;
  std::vector<std::size_t> all, fit, holdout;
  const DriveOptions& options;
};

// One round: every remaining effect added to `current`, fitted on the fitted blocks and judged
// against it (ΔBIC with n_eff = n/τ_int, the held-out RMS, no friction pinned at 0).  Returns
// the index in effect_columns() of the winner, or −1.
int search_round(const Search& w, const Theta& current, const FreeSet& free, std::vector<Candidate>& round) {
  const LinearFit base = solve(w.s, w.l, current, free, w.fit);
  if (!base.ok) return -1;
  const std::vector<double> r_base = residuals(w.s, w.l, base.m);
  const double base_holdout = rms_on(r_base, w.holdout);
  const double n_eff = static_cast<double>(w.fit.size()) / tau_int_on(r_base, w.fit);
  int winner = -1;
  double best = INFINITY;
  for (std::size_t e = 0; e < effect_columns().size(); ++e) {
    const auto& [effect, which] = effect_columns()[e];
    if (free[which] || current[which] != 0) continue;  // named already, or in the file
    FreeSet trial = free;
    trial[which] = true;
    const LinearFit l = solve(w.s, w.l, base.m, trial, w.fit);
    Candidate c;
    c.effect = effect;
    if (!l.ok) {
      c.failure = "the least-squares fit gave no physical drive";
      c.rms = c.rms_holdout = c.delta_bic = INFINITY;
      round.push_back(c);
      continue;
    }
    const std::vector<double> r = residuals(w.s, w.l, l.m);
    c.parameters = {{"torque", l.m[which], NAN}};
    c.rms = rms_on(r, w.all);
    c.rms_fit = std::sqrt(l.sse / static_cast<double>(w.fit.size()));
    c.rms_holdout = rms_on(r, w.holdout);
    c.delta_bic = n_eff * std::log(std::max(l.sse, 1e-300) / std::max(base.sse, 1e-300)) + std::log(n_eff);
    c.at_range_edge = l.clamped && l.m[which] == 0;
    c.decisive = c.delta_bic < -w.options.decisive_bic && c.rms_holdout <= w.options.decisive_holdout * base_holdout &&
                 !c.at_range_edge;
    if (c.decisive && c.delta_bic < best) best = c.delta_bic, winner = static_cast<int>(e);
    round.push_back(c);
  }
  std::stable_sort(round.begin(), round.end(), [](const Candidate& a, const Candidate& b) { return a.delta_bic < b.delta_bic; });
  return winner;
}

// The rounds: the winner named, the model refitted on the whole record, again until none is
// decisive.  Returns the model with its free set.
Theta name_effects(const Search& w, Theta current, FreeSet& free, DriveDiscrepancyResult& result) {
  while (static_cast<int>(result.effects.size()) < w.options.max_effects) {
    std::vector<Candidate> round;
    const int winner = search_round(w, current, free, round);
    if (round.empty()) break;
    result.rounds.push_back(round);
    if (winner < 0) break;
    const auto& [effect, which] = effect_columns()[static_cast<std::size_t>(winner)];
    free[which] = true;
    const LinearFit whole = solve(w.s, w.l, current, free, w.all);
    if (whole.ok) current = whole.m;
    const auto named = std::find_if(round.begin(), round.end(), [&](const Candidate& c) { return c.effect == effect; });
    result.effects.push_back(*named);
  }
  return current;
}

}  // namespace

// ------------------------------------------------------------------ the gap (both encoders)

namespace {

// The gap's fit on the faces: x = x0 + σ·b/2 − c·R − d·ẋ over the samples in contact (c = 1/kc,
// 0 for a rigid mesh; d = cm/kc the mesh's damping over its stiffness: the mesh torque
// P = kc·δ + cm·δ̇ gives δ = P/kc − d·δ̇), R the load's inverse dynamics.
struct GapFit {
  double x0 = 0, b = 0, c = 0, d = 0;
  std::vector<double> xdot;  // ẋ of the filtered gap (compliant fits)
  double sigma_b = NAN, sigma_c = NAN;
  std::vector<std::size_t> contact;
  std::vector<signed char> face;  // at every sample: ±1 in contact, 0 in flight
  double sse = INFINITY;
  double contact_fraction = 0;
  bool raw = false;  // read on the raw gap (contact stretches shorter than the filter's length)
};

// The samples in contact needed on each face: b is the difference of the two faces (with one
// face alone it is not identified — it came out 0 on a loop closed on the load encoder).
constexpr std::size_t kMinOnFace = 5;

// The main lobe of the zero-phase filter's impulse response: the samples from its centre to its
// first change of sign.
std::size_t main_lobe(const measurements::ButterworthLowPass& filter) {
  const std::size_t n = 1025, middle = n / 2;
  std::vector<double> impulse(n, 0.0);
  impulse[middle] = 1;
  const std::vector<double> h = measurements::zero_phase_filter(impulse, filter);
  std::size_t m = 1;
  while (m < middle && h[middle + m] > 0) ++m;
  return m;
}

bool solve_gap(const Signals& s, const std::vector<double>& xf, const std::vector<double>& R, bool compliant, std::size_t margin,
               GapFit& g) {
  std::vector<std::size_t> rows;
  std::size_t on_face[2] = {0, 0};
  for (std::size_t k = s.begin + margin; k + margin < s.end; ++k) {
    bool steady = g.face[k] != 0;
    for (std::size_t j = k - margin; steady && j <= k + margin; ++j) steady = g.face[j] == g.face[k];
    if (steady) rows.push_back(k), ++on_face[g.face[k] > 0];
  }
  const int cols = compliant ? 4 : 2;
  if (rows.size() < 10 || on_face[0] < kMinOnFace || on_face[1] < kMinOnFace) return false;  // b needs both faces
  Eigen::MatrixXd A(rows.size(), cols);
  Eigen::VectorXd y(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::size_t k = rows[i];
    A(i, 0) = 1, A(i, 1) = 0.5 * g.face[k];
    if (compliant) A(i, 2) = -R[k], A(i, 3) = -g.xdot[k];
    y(i) = xf[k];
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(y);
  if (!x.allFinite()) return false;
  g.x0 = x(0), g.b = x(1), g.c = compliant ? x(2) : 0, g.d = compliant ? x(3) : 0;
  g.contact = rows;
  g.sse = (A * x - y).squaredNorm();
  return true;
}

// Contact where it is certain: the load's inverse dynamics R is the mesh torque, 0 in flight, and
// on face σ it is −σ·P with P > 0; so the samples whose |R| exceeds a tenth of its 95th percentile
// are in contact on face −sgn R, and stay so while R keeps its sign and |R| a fortieth of that
// percentile (a hysteresis: a cruise whose viscous torque sits near the tenth would otherwise
// flicker in and out of contact with the noise, and no stretch would be steady).  b, x0 (and
// 1/kc) by least squares over them, on both faces:
//  - the filtered gap xf where the face holds over the filter's whole length around the sample
//    (there the filter commutes with the face's linear model: exact);
//  - where no such stretch holds on both faces (contact stretches shorter than the filter's
//    length: a loop on the load encoder hunting in the gap, pushing the load in short strokes),
//    the raw gap x = θL − θm, which needs no filter (on a rigid face it is x0 + σ·b/2 to the
//    encoders' counts), over the samples whose face holds for the main lobe of the filter's
//    impulse response around them — the time by which the filtered R, the classifier, can
//    misplace an impact or a separation (docs/discrepancy.md).
GapFit fit_gap(const Signals& s, const std::vector<double>& xf, const std::vector<double>& x, const std::vector<double>& R,
               bool compliant) {
  std::vector<double> size;
  for (std::size_t k = s.begin; k < s.end; ++k) size.push_back(std::fabs(R[k]));
  std::nth_element(size.begin(), size.begin() + static_cast<std::ptrdiff_t>(95 * size.size() / 100), size.end());
  const double threshold = 0.1 * size[95 * size.size() / 100];
  GapFit g;
  if (compliant) g.xdot = measurements::derivatives(xf, s.fs).velocity;
  g.face.assign(s.size(), 0);
  for (std::size_t k = s.begin; k < s.end; ++k) {
    const signed char face = R[k] > 0 ? -1 : 1;
    const bool held = k > s.begin && g.face[k - 1] == face && std::fabs(R[k]) > threshold / 4;
    if (held || std::fabs(R[k]) > threshold) g.face[k] = face;
  }
  if (!solve_gap(s, xf, R, compliant, s.reach, g)) {
    g.raw = true;
    if (!solve_gap(s, x, R, compliant, main_lobe(s.filter), g)) g.sse = INFINITY;
  }
  g.contact_fraction = static_cast<double>(g.contact.size()) / static_cast<double>(std::max<std::size_t>(1, s.end - s.begin));
  return g;
}

// The uncertainties of the gap's fit (Ceres's covariance of the same linear model).
void gap_sigma(const std::vector<double>& xf, const std::vector<double>& x_raw, const std::vector<double>& R, GapFit& g) {
  const std::vector<double>& y = g.raw ? x_raw : xf;
  std::vector<double> x{g.x0, g.b, g.c, g.d};
  const std::size_t k = g.c != 0 ? 4 : 2;
  x.resize(k);
  const std::function<void(const double*, double*)> f = [&](const double* p, double* r) {
    for (std::size_t i = 0; i < g.contact.size(); ++i) {
      const std::size_t j = g.contact[i];
      r[i] = y[j] - (p[0] + 0.5 * g.face[j] * p[1] - (k == 4 ? p[2] * R[j] + p[3] * g.xdot[j] : 0.0));
    }
  };
  const std::vector<double> sigma = ceres_sigma(f, g.contact.size(), x, std::vector<double>(k, -INFINITY), false);
  g.sigma_b = sigma[1];
  if (k == 4) g.sigma_c = sigma[2];
}

}  // namespace

// ------------------------------------------------------------------ the load observer (motor encoder alone)

namespace {

// The load side the observer reconstructs for gap b and the load's parameters in m.
// The acceleration the motor would have alone, (u + T0 − Fm·v̂m − Tm·sgn v̂m)/Jm, from the held drive
// itself (unfiltered): in rigid contact the mesh torque on the load is
//   R = JL·Jm/(Jm + JL)·(a_alone + (FL·v + TL·sgn v)/JL),
// so the load leaves its face exactly where the motor alone would brake harder than the load's own
// friction brakes it — read on the logged drive at each sample, not on the filtered acceleration
// (whose impulse response smears the separation over the filter's length: the backlash came out
// up to 6 % off, docs/discrepancy.md).
std::vector<double> motor_alone_acceleration(const Signals& s, const std::vector<double>& v, const Theta& m) {
  std::vector<double> a(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double sign = s.vm[k] > 0 ? 1 : s.vm[k] < 0 ? -1 : 0;
    a[k] = (s.u[k] + m[kT0] - m[kFm] * v[k] - m[kTm] * sign) / m[kJm];
  }
  return a;
}

// The motor's velocity from the encoder's counts up to each sample (the slope at its end of the
// least-squares parabola through the last 12): the load leaves the motor with the motor's
// velocity at that instant, and the zero-phase filter's v̂m there already feels the motor's own
// sharper braking after it.
std::vector<double> causal_velocity(const Signals& s) {
  constexpr int m = 12;
  // The end-slope weights of a least-squares parabola over t = −(m−1)..0 samples.
  static const std::array<double, m> w = [] {
    Eigen::Matrix<double, m, 3> A;
    for (int i = 0; i < m; ++i) A(i, 0) = 1, A(i, 1) = i - (m - 1), A(i, 2) = std::pow(i - (m - 1), 2);
    const Eigen::Matrix<double, 3, m> pinv = (A.transpose() * A).inverse() * A.transpose();
    std::array<double, m> out{};
    for (int i = 0; i < m; ++i) out[static_cast<std::size_t>(i)] = pinv(1, i);
    return out;
  }();
  std::vector<double> v = s.vm;
  for (std::size_t k = m - 1; k < s.size(); ++k) {
    double sum = 0;
    for (int i = 0; i < m; ++i) sum += w[static_cast<std::size_t>(i)] * s.qm[k - (m - 1) + static_cast<std::size_t>(i)];
    v[k] = sum * s.fs;
  }
  return v;
}

// The observer on the raw motor encoder (the impacts where its counts meet the coasting load) with
// the separations from the drive (motor_alone_acceleration); `compliance` (1/kc, per unit load
// inertia when JL = 1) times Jm/(Jm + JL) turns the observer's push into R/kc.
std::vector<double> observe(const Signals& s, const Theta& m, double b, double JL, double FL, double TL, double compliance) {
  const double share = m[kJm] / (m[kJm] + m[kJL]);
  const std::vector<double> v = causal_velocity(s);
  return load_observer(s.qm, v, motor_alone_acceleration(s, v, m), s.fs, b, 0, JL, FL, TL, compliance * share);
}

LoadSide observed_load(const Signals& s, double b, const Theta& m, double compliance) {
  const std::vector<double> x = observe(s, m, b, m[kJL], m[kFL], m[kTL], compliance);
  std::vector<double> qL(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) qL[k] = s.qm[k] + x[k];
  return load_side(s, std::move(qL), false);
}

// With the motor encoder alone, where the load sits in the gap at the record's start is unknown
// (the observer assumes a face); once the motor has gone half its whole travel — the widest gap
// the shape's grid tries — from where it started, the load is on a face whatever gap it had.
// The samples before that are left out of the comparison.
std::size_t settled_from(const Signals& s) {
  const auto [lo, hi] = std::minmax_element(s.qm.begin(), s.qm.end());
  std::size_t k = 0;
  while (k < s.size() && std::fabs(s.qm[k] - s.qm[0]) < 0.5 * (*hi - *lo)) ++k;
  return k;
}

// The samples compared on a drive with a gap: the reversals stay in (the gap shows there, and
// with both encoders the bodies move apart there, which alone tells the two Coulomb frictions
// apart); only the rests longer than the filter's length are left out, with that length around
// them — the motor's, and the load's when `vL` is given (a body at rest may stick).
std::vector<std::size_t> observer_samples(const Signals& s, const std::vector<double>* vL = nullptr) {
  const std::size_t n = s.size();
  std::vector<char> in(n, 0);
  for (std::size_t i = s.begin; i < s.end; ++i) in[i] = 1;
  auto leave_out_rests = [&](const std::vector<double>& v) {
    for (std::size_t i = 0; i < n;) {
      std::size_t j = i;
      while (j < n && std::fabs(v[j]) <= s.rest_speed) ++j;
      if (j - i >= s.reach)
        for (std::size_t k = i >= s.reach ? i - s.reach : 0; k < std::min(n, j + s.reach); ++k) in[k] = 0;
      i = j + 1;
    }
  };
  leave_out_rests(s.vm);
  if (vL) leave_out_rests(*vL);
  else  // the motor encoder alone: where the load starts in its gap is unknown
    for (std::size_t k = 0; k < settled_from(s); ++k) in[k] = 0;
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i)
    if (in[i]) out.push_back(i);
  return out;
}

// The observer depends on the load only through its shape: the gap b and the decelerations per
// unit velocity α = FL/JL and per unit inertia β = TL/JL.  For a shape, the residual is linear in
// JL (the load's column aL + α·v̂L + β·s̄L) and in the motor's free parameters: variable projection.
struct Shape {
  double b = 0, alpha = 0, beta = 0;
  double compliance = 0;  // 1/kc per unit load inertia (JL/kc: the observer runs with JL = 1); the file's, held
};

LoadSide tied_load(const Signals& s, const Shape& z, const Theta& m) {
  const std::vector<double> x = observe(s, m, z.b, 1, z.alpha, z.beta, z.compliance);
  std::vector<double> qL(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) qL[k] = s.qm[k] + x[k];
  LoadSide l = load_side(s, std::move(qL), false);
  for (std::size_t k = 0; k < s.size(); ++k) l.aL[k] += z.alpha * l.vL[k] + z.beta * l.sL_f[k], l.vL[k] = 0, l.sL_f[k] = 0;
  return l;
}

LinearFit shape_fit(const Signals& s, const Shape& z, const Theta& start, FreeSet free, const std::vector<std::size_t>& samples) {
  Theta m = start;
  m[kFL] = m[kTL] = 0;
  free[kJL] = true, free[kFL] = free[kTL] = false;
  LinearFit f = solve(s, tied_load(s, z, m), m, free, samples);
  if (f.ok) f.m[kFL] = z.alpha * f.m[kJL], f.m[kTL] = z.beta * f.m[kJL];
  return f;
}

struct ObserverFit {
  Shape z;
  double sigma_b = NAN;
  Theta m{};
  double sse = INFINITY, sse_rigid = INFINITY;
};

// One coordinate of the shape by a scan of `grid` and Brent's minimisation in the best bracket.
void coordinate(const Signals& s, ObserverFit& f, double Shape::*which, const std::vector<double>& grid, const FreeSet& free,
                const std::vector<std::size_t>& samples) {
  auto cost = [&](double value) {
    Shape z = f.z;
    z.*which = value;
    return shape_fit(s, z, f.m, free, samples);
  };
  std::size_t arg = grid.size();
  for (std::size_t j = 0; j < grid.size(); ++j) {
    const LinearFit l = cost(grid[j]);
    if (l.ok && l.sse < f.sse) f.sse = l.sse, f.m = l.m, f.z.*which = grid[j], arg = j;
  }
  if (arg == grid.size()) {  // the current point stays the best: refine around it
    arg = static_cast<std::size_t>(std::lower_bound(grid.begin(), grid.end(), f.z.*which) - grid.begin());
    arg = std::min(arg, grid.size() - 1);
  }
  const double lo = grid[arg == 0 ? 0 : arg - 1], hi = grid[std::min(arg + 1, grid.size() - 1)];
  if (!(hi > lo)) return;
  const auto [x, c] = boost::math::tools::brent_find_minima([&](double v) { const LinearFit l = cost(v); return l.ok ? l.sse : INFINITY; }, lo, hi, 30);
  const LinearFit l = cost(x);
  if (l.ok && l.sse < f.sse) f.sse = l.sse, f.m = l.m, f.z.*which = x;
  (void)c;
}

// The grids of the shape's coordinates.  Wide (the first, coarsest band): b over 0 and 40
// logarithmic points from the encoder's step to half the motor's travel, α and β over
// [0, 4·A/V] and [0, 4·A] (A, V the 90th percentiles of |âm| and |v̂m|).  Narrow (the finer
// bands): 0 and 13 points from 1/1.5 to 1.5 times the current b, from 1/5 to 5 times α and β.
struct Grids {
  std::vector<double> b, alpha, beta;
};

std::vector<double> around(double x, double factor) {
  std::vector<double> g{0};
  if (x > 0)
    for (int j = -6; j <= 6; ++j) g.push_back(x * std::pow(factor, j / 6.0));
  return g;
}

Grids grids_of(const Signals& s, const Shape& z, bool wide) {
  if (!wide) return {around(z.b, 1.5), around(z.alpha, 5), around(z.beta, 5)};
  double step = INFINITY, lo = INFINITY, hi = -INFINITY;
  std::vector<double> A, V;
  for (std::size_t k = 0; k < s.size(); ++k) {
    lo = std::min(lo, s.qm[k]), hi = std::max(hi, s.qm[k]);
    if (k > 0 && s.qm[k] != s.qm[k - 1]) step = std::min(step, std::fabs(s.qm[k] - s.qm[k - 1]));
    A.push_back(std::fabs(s.am[k])), V.push_back(std::fabs(s.vm[k]));
  }
  std::nth_element(A.begin(), A.begin() + static_cast<std::ptrdiff_t>(9 * A.size() / 10), A.end());
  std::nth_element(V.begin(), V.begin() + static_cast<std::ptrdiff_t>(9 * V.size() / 10), V.end());
  const double a90 = A[9 * A.size() / 10], v90 = std::max(V[9 * V.size() / 10], 1e-300);
  const double b_lo = std::isfinite(step) ? step : 1e-6 * (hi - lo), b_hi = 0.5 * (hi - lo);
  Grids g;
  g.b.push_back(0);
  for (int j = 0; j <= 40; ++j) g.b.push_back(b_lo * std::pow(b_hi / b_lo, j / 40.0));
  for (int j = 0; j <= 16; ++j) g.alpha.push_back(4 * a90 / v90 * j / 16.0), g.beta.push_back(4 * a90 * j / 16.0);
  return g;
}

// The shape by coordinate descent from `f` (three sweeps over b, α, β; β only with `coulomb_load`).
void fit_shape(const Signals& s, ObserverFit& f, const FreeSet& free, bool coulomb_load, bool wide,
               const std::vector<std::size_t>& samples) {
  const Grids g = grids_of(s, f.z, wide);
  f.sse = shape_fit(s, f.z, f.m, free, samples).sse;
  for (int sweep = 0; sweep < 3; ++sweep) {
    coordinate(s, f, &Shape::b, g.b, free, samples);
    coordinate(s, f, &Shape::alpha, g.alpha, free, samples);
    if (coulomb_load) coordinate(s, f, &Shape::beta, g.beta, free, samples);
  }
  Shape rigid = f.z;
  rigid.b = 0;
  f.sse_rigid = shape_fit(s, rigid, f.m, free, samples).sse;
}

// The shape polished by Levenberg–Marquardt (Ceres, numeric derivatives through the observer and
// the projection): the coordinate scans find the valley, this follows it (b and the load's
// Coulomb friction trade against each other along it).
void polish_shape(const Signals& s, ObserverFit& f, const FreeSet& free, bool coulomb_load, const std::vector<std::size_t>& samples) {
  std::vector<double> x{f.z.b, f.z.alpha, f.z.beta};
  if (!coulomb_load) x.pop_back();
  const Theta start = f.m;
  const std::function<void(const double*, double*)> residual = [&](const double* p, double* r) {
    const Shape z{std::max(0.0, p[0]), std::max(0.0, p[1]), coulomb_load ? std::max(0.0, p[2]) : 0.0, f.z.compliance};
    const LinearFit l = shape_fit(s, z, start, free, samples);
    Theta m = l.m;
    m[kFL] = m[kTL] = 0;
    const std::vector<double> all = l.ok ? residuals(s, tied_load(s, z, m), m) : std::vector<double>(s.size(), 1e3);
    for (std::size_t i = 0; i < samples.size(); ++i) r[i] = all[samples[i]];
  };
  ceres_sigma(residual, samples.size(), x, std::vector<double>(x.size(), 0.0), true, 1e-3);
  const Shape z{x[0], x[1], coulomb_load ? x[2] : 0.0, f.z.compliance};
  const LinearFit l = shape_fit(s, z, start, free, samples);
  if (l.ok && l.sse < f.sse) f.z = z, f.m = l.m, f.sse = l.sse;
}

// Coarse to fine: the profiled cost of a wrong gap is the mismatch of the impacts' timing, whose
// basin is as wide as the filter's impulse response; so the shape is found in the band cut at
// 1/8 of the cut-off first, then refined at 1/4, 1/2 and the cut-off itself.
ObserverFit fit_shape_coarse_to_fine(const Signals& s, const Theta& start, const FreeSet& free, bool coulomb_load,
                                     double compliance, const std::vector<std::size_t>& samples) {
  ObserverFit f;
  f.m = start;
  f.z = {0, start[kFL] / start[kJL], start[kTL] / start[kJL]};
  for (int level = 3; level >= 0; --level) {
    f.z.compliance = compliance * f.m[kJL];
    Signals coarse = s;
    const double cutoff = s.filter.cutoff_hz / std::pow(2.0, level);
    if (level > 0) {
      const measurements::ButterworthLowPass filter = measurements::design_butterworth_low_pass(cutoff, s.fs);
      filter_signals(coarse, filter, detail::drive_filter_edge(filter));
    }
    const std::vector<std::size_t> inner = level > 0 ? observer_samples(coarse) : samples;
    fit_shape(level > 0 ? coarse : s, f, free, coulomb_load, level == 3, inner);
    polish_shape(level > 0 ? coarse : s, f, free, coulomb_load, inner);
  }
  return f;
}

// σ of b and of the free parameters: Ceres's covariance, numeric derivatives through the observer.
std::vector<double> observer_sigma(const Signals& s, ObserverFit& f, const FreeSet& free, bool coulomb_load,
                                   const std::vector<std::size_t>& samples) {
  std::vector<int> order;
  for (int i = 0; i < kCount; ++i)
    if (free[i] || i == kJL || i == kFL || (coulomb_load && i == kTL)) order.push_back(i);
  std::vector<double> x{f.z.b};
  for (int i : order) x.push_back(f.m[i]);
  const std::function<void(const double*, double*)> residual = [&](const double* p, double* r) {
    Theta m = f.m;
    for (std::size_t j = 0; j < order.size(); ++j) m[order[j]] = p[j + 1];
    const double JL = std::max(m[kJL], 1e-12 * f.m[kJL]);
    const Shape z{std::max(0.0, p[0]), std::max(0.0, m[kFL]) / JL, std::max(0.0, m[kTL]) / JL, f.z.compliance};
    Theta mt = m;
    mt[kJL] = JL, mt[kFL] = mt[kTL] = 0;
    const std::vector<double> all = residuals(s, tied_load(s, z, mt), mt);
    for (std::size_t i = 0; i < samples.size(); ++i) r[i] = all[samples[i]];
  };
  std::vector<double> sigma = ceres_sigma(residual, samples.size(), x, std::vector<double>(x.size(), -INFINITY), false);
  f.sigma_b = sigma[0];
  std::vector<double> out(kCount, NAN);
  for (std::size_t j = 0; j < order.size(); ++j) out[static_cast<std::size_t>(order[j])] = sigma[j + 1];
  return out;
}

// The blocks of the sandwich below: the record cut midway between the motor's reversals (in its
// quiet cruise), so that each block holds one move's events (separation, flight, impact).
std::vector<int> move_blocks(const Signals& s) {
  std::vector<std::size_t> at;
  int last = 0;
  for (std::size_t k = s.begin; k < s.end; ++k) {
    if (s.sm[k] == 0) continue;
    if (last != 0 && s.sm[k] != last) at.push_back(k);
    last = s.sm[k];
  }
  std::vector<int> block(s.size(), 0);
  for (std::size_t i = 0; i + 1 < at.size(); ++i)
    for (std::size_t k = (at[i] + at[i + 1]) / 2; k < s.size(); ++k) block[k] = static_cast<int>(i + 1);
  return block;
}

// The argument of the minimum of a cost sampled at b_j = b_0 + j·h: the parabola through the
// least sample and its neighbours (the grid's end when the least is there).
double grid_minimum(const std::vector<double>& cost, double b0, double h) {
  const std::size_t j = static_cast<std::size_t>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  if (j == 0 || j + 1 == cost.size()) return b0 + static_cast<double>(j) * h;
  const double denominator = cost[j - 1] - 2 * cost[j] + cost[j + 1];
  const double shift = denominator > 0 ? 0.5 * (cost[j - 1] - cost[j + 1]) / denominator : 0;
  return b0 + (static_cast<double>(j) + shift) * h;
}

// σ of the backlash (motor encoder alone).  The profiled observer cost S(b) (the shape's α, β held,
// the linear parameters projected out) is sharp — a wrong gap mistimes the impacts — and at its
// minimum the residual stays above the noise: the observer's model error, not the noise, limits
// the backlash, and it differs from move to move.  So σ is the jackknife over the moves (the
// record cut midway between the motor's reversals): the gap minimising S less one move's share,
// each move in turn, on a grid of 41 gaps over b ± 10 % (or ± 20 encoder counts when wider);
// Var b = (G − 1)/G·Σ (b₋ᵢ − b̄)².  Never below the white-residual bound 2·σ_r²·τ_int / S''.
double profile_sigma_b(const Signals& s, const ObserverFit& f, const FreeSet& free, const std::vector<std::size_t>& samples) {
  double count = INFINITY;
  for (std::size_t k = 1; k < s.size(); ++k)
    if (s.qm[k] != s.qm[k - 1]) count = std::min(count, std::fabs(s.qm[k] - s.qm[k - 1]));
  const double half = std::max(0.1 * f.z.b, std::isfinite(count) ? 20 * count : 0.1 * f.z.b);
  const double b0 = std::max(0.0, f.z.b - half), h = (f.z.b + half - b0) / 40;
  if (!(h > 0)) return NAN;
  const std::vector<int> block = move_blocks(s);
  const std::size_t blocks = static_cast<std::size_t>(block.back() + 1);
  std::vector<double> total(41, 0.0);
  std::vector<std::vector<double>> share(blocks, std::vector<double>(41, 0.0));
  double variance = NAN, tau = 1;
  for (std::size_t j = 0; j < 41; ++j) {
    Shape z = f.z;
    z.b = b0 + static_cast<double>(j) * h;
    const LinearFit l = shape_fit(s, z, f.m, free, samples);
    if (!l.ok) return NAN;
    Theta m = l.m;
    m[kFL] = m[kTL] = 0;
    const std::vector<double> r = residuals(s, tied_load(s, z, m), m);
    std::vector<double> inner;
    for (std::size_t k : samples) share[static_cast<std::size_t>(block[k])][j] += r[k] * r[k], total[j] += r[k] * r[k], inner.push_back(r[k]);
    if (j == 20) variance = total[j] / static_cast<double>(std::max<std::size_t>(2, samples.size()) - 1), tau = tau_int_or_one(inner);
  }
  const double curvature = (total[21] - 2 * total[20] + total[19]) / (h * h);
  double white = curvature > 0 ? 2 * variance * tau / curvature : INFINITY, jack = 0, mean = 0;
  std::vector<double> leave_out(blocks);
  for (std::size_t i = 0; i < blocks; ++i) {
    std::vector<double> cost(41);
    for (std::size_t j = 0; j < 41; ++j) cost[j] = total[j] - share[i][j];
    leave_out[i] = grid_minimum(cost, b0, h), mean += leave_out[i] / static_cast<double>(blocks);
  }
  for (double b : leave_out) jack += (b - mean) * (b - mean) * static_cast<double>(blocks - 1) / static_cast<double>(blocks);
  return std::sqrt(std::max(white, jack));
}

// The part of σ_b the jackknife cannot see (motor encoder alone): the observer places each
// separation and each impact on a sample, so every reversal's lost motion is off by what the gap
// moves in a fraction of a sample — the same way at every reversal, a bias no scatter over the
// moves shows.  Each event taken as uniform over one sample (σ = T/√12 in time): an impact
// mistimed by δt moves the gap by ẋ·δt (ẋ its rate just before the face); a separation mistimed
// by δt gives the load the motor's velocity off by ẍ·δt, which the flight (of length t_f) turns
// into ẍ·δt·t_f at the face.  σ = √(mean over the flights of (ẋ·T)² + (ẍ·T·t_f)²)/√12, not
// divided by √(flights): the bias is shared.
double timing_sigma_b(const std::vector<double>& gap, double b, std::size_t from, std::size_t to) {
  double sum = 0;
  std::size_t flights = 0;
  auto on_face = [&](std::size_t k) { return std::fabs(std::fabs(gap[k]) - b / 2) <= 1e-9 * std::max(b, 1e-300); };
  for (std::size_t k = std::max<std::size_t>(from, 2); k + 1 < to; ++k) {
    if (!(on_face(k - 1) && !on_face(k))) continue;  // a separation at k
    std::size_t e = k;
    while (e < to && !on_face(e)) ++e;
    if (e >= to || e < k + 2) continue;
    // ẋ and ẍ from the parabola through the flight's samples (the gap is read on the motor's
    // counts: a difference of samples would be the quantisation's).
    const std::size_t m = e - k + 1;
    Eigen::MatrixXd A(m, 3);
    Eigen::VectorXd y(m);
    for (std::size_t i = 0; i < m; ++i) {
      const double tau = static_cast<double>(i);
      A(i, 0) = 1, A(i, 1) = tau, A(i, 2) = tau * tau, y(i) = gap[k - 1 + i];
    }
    const Eigen::Vector3d c = A.colPivHouseholderQr().solve(y);
    const double rate = std::fabs(c(1) + 2 * c(2) * static_cast<double>(m - 1));  // ẋ·T at the face
    const double bend = std::fabs(2 * c(2)) * static_cast<double>(m - 1);          // ẍ·T·t_f
    sum += rate * rate + bend * bend, ++flights;
    k = e;
  }
  return flights > 0 ? std::sqrt(sum / static_cast<double>(flights) / 12) : 0;
}

}  // namespace

// ------------------------------------------------------------------ the result

namespace {

// The record a drive with a gap needs: the logged drive and the motor's encoder (theta_load
// optional), named by file, line 1 and column when missing.
void check_inputs(const model::CaseSpec& spec, const measurements::MeasuredRecord& data) {
  const std::string file = data.source.string() + (data.source.extension() == ".mat" ? "" : ":1");  // a CSV's header line
  if (!data.drive)
    throw std::invalid_argument(file + ": drive: missing column: a drive with a gap (backlash > 0 in " +
                                spec.source.filename().string() + ") needs the logged drive (t, theta_motor[, theta_load], drive)");
  if (!data.theta_motor)
    throw std::invalid_argument(file + ": theta_motor: missing column: a drive with a gap (backlash > 0 in " +
                                spec.source.filename().string() + ") needs the motor encoder (t, theta_motor[, theta_load], drive)");
}

// The motor's reversals (a change of the sign of its motion, rests skipped) and the lost motion
// at each: the swing of the gap between the midpoints to the neighbouring reversals.
std::vector<LostMotion> lost_motion(const Signals& s, const std::vector<double>* measured_gap, const std::vector<double>& model_gap) {
  std::vector<std::size_t> at;
  std::vector<int> direction;
  int last = 0;
  for (std::size_t k = s.begin; k < s.end; ++k) {
    if (s.sm[k] == 0) continue;
    if (last != 0 && s.sm[k] != last) at.push_back(k), direction.push_back(s.sm[k]);
    last = s.sm[k];
  }
  std::vector<LostMotion> out;
  // The face either side: the median of the gap from the midpoint to the reversal and from the
  // reversal to the next midpoint (the gap sits on a face most of each half; a max − min swing
  // would add the encoders' quantisation, two counts or more, and the filter's overshoot).
  auto median = [](const std::vector<double>& x, std::size_t a, std::size_t b) -> double {
    std::vector<double> v(x.begin() + static_cast<std::ptrdiff_t>(a), x.begin() + static_cast<std::ptrdiff_t>(b));
    if (v.empty()) return NAN;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  auto swing = [&](const std::vector<double>& x, std::size_t a, std::size_t b, std::size_t at) {
    return std::fabs(median(x, at, b) - median(x, a, at));
  };
  for (std::size_t i = 0; i < at.size(); ++i) {
    const std::size_t a = i == 0 ? s.begin : (at[i - 1] + at[i]) / 2;
    const std::size_t b = i + 1 == at.size() ? s.end : (at[i] + at[i + 1]) / 2;
    LostMotion l;
    l.t = s.t[at[i]], l.direction = direction[i];
    if (measured_gap) l.measured = swing(*measured_gap, a, b, at[i]);
    l.model = swing(model_gap, a, b, at[i]);
    out.push_back(l);
  }
  return out;
}

ParameterCorrection correction(const std::string& key, double nominal, double fitted, double sigma, bool given_free) {
  return {key, nominal, fitted, sigma, nominal != 0 ? fitted / nominal : NAN, given_free};
}

bool listed(const model::CaseSpec& spec, const std::string& key) {
  return std::find(spec.fit_free.begin(), spec.fit_free.end(), key) != spec.fit_free.end();
}

// The nominal parameters fitted, as parameter corrections (the backlash first).
void corrections_of(const model::CaseSpec& spec, const Theta& given, const Theta& m, const std::vector<double>& sigma,
                    const FreeSet& free, double b, double sigma_b, TwoBodyFindings& f) {
  f.parameter_corrections.push_back(correction("backlash", model::to_double(spec.backlash), b, sigma_b, listed(spec, "backlash")));
  for (int i : {kJL, kFL, kJm, kFm})
    if (free[i]) f.parameter_corrections.push_back(correction(kName[i], given[i], m[i], sigma[static_cast<std::size_t>(i)], listed(spec, kName[i])));
}

// σ of the summed equation's free parameters (both encoders: the load measured).
std::vector<double> summed_sigma(const Signals& s, const LoadSide& l, Theta& m, const FreeSet& free, const std::vector<std::size_t>& samples) {
  std::vector<int> order;
  for (int i = 0; i < kCount; ++i)
    if (free[i]) order.push_back(i);
  std::vector<double> x;
  for (int i : order) x.push_back(m[i]);
  const std::function<void(const double*, double*)> residual = [&](const double* p, double* r) {
    Theta t = m;
    for (std::size_t j = 0; j < order.size(); ++j) t[order[j]] = p[j];
    const std::vector<double> all = residuals(s, l, t);
    for (std::size_t i = 0; i < samples.size(); ++i) r[i] = all[samples[i]];
  };
  const std::vector<double> sigma = ceres_sigma(residual, samples.size(), x, std::vector<double>(x.size(), -INFINITY), false);
  std::vector<double> out(kCount, NAN);
  for (std::size_t j = 0; j < order.size(); ++j) out[static_cast<std::size_t>(order[j])] = sigma[j];
  return out;
}

}  // namespace

// ------------------------------------------------------------------ the two routes

namespace {

struct Fitted {
  Theta given{}, nominal{}, m{};
  FreeSet free{};
  std::vector<double> sigma;
  double given_b = 0, b = 0, sigma_b = NAN;
  double compliance = 0;  // 1/kc of the file's mesh (0: rigid), held with the motor encoder alone
  std::vector<double> r_given, r_nominal, r_after;
  std::vector<std::size_t> all;
};

// Both encoders: the two bodies move together wherever the summed equation is compared, so it
// sees only the sum of their Coulomb frictions; the load's own is read on its coasting in flight
// (flight_coulomb with α = FL/JL and the faces of the `summed` model, whose viscous friction is
// right once the sum is named) and, when decisive, named first and held in `current` (the
// summed equation's rounds are then run again, and name the motor's).
FlightFit load_coulomb_in_flight(const Signals& s, const LoadSide& l, const std::vector<double>& xf, const std::vector<double>& x,
                                 const DriveOptions& options,
                                 const Theta& summed, Theta& current, DriveDiscrepancyResult& result) {
  if (current[kTL] != 0) return {};
  std::vector<double> R(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) R[k] = summed[kJL] * l.aL[k] + summed[kFL] * l.vL[k] + (summed[kTL] + summed[kTm]) * l.sL_f[k];
  const GapFit g = fit_gap(s, xf, x, R, false);
  if (!std::isfinite(g.sse) || !(g.b > 0)) return {};
  const FlightFit flight = flight_coulomb(s, l, g.x0, g.b, summed[kFL] / summed[kJL]);
  if (!flight.ok) return flight;
  Candidate c;
  c.effect = "coulomb_load";
  c.rms = c.rms_fit = c.rms_holdout = NAN;  // judged on the load's flights (positions), not on the torque
  c.parameters = {{"torque", flight.beta * current[kJL], flight.sigma * current[kJL]}};
  c.delta_bic = flight.delta_bic;
  c.at_range_edge = !(flight.beta > 0);
  c.decisive = c.delta_bic < -options.decisive_bic && !c.at_range_edge;
  if (!c.decisive) {
    result.rounds.push_back({c});
    return flight;
  }
  result.rounds = {{c}}, result.effects = {c};  // the summed equation's rounds again, with TL held
  current[kTL] = flight.beta * summed[kJL];
  return flight;
}

// Both encoders: the summed equation with the load measured; the gap read on its faces.
void both_encoders(const Signals& s, const DriveOptions& options, Fitted& f, DriveDiscrepancyResult& result, TwoBodyFindings& two) {
  const LoadSide l = load_side(s, s.qL, true);
  Search w{s, l, observer_samples(s, &l.vL), {}, {}, options};
  split_blocks(s, w.all, w.fit, w.holdout);
  const LinearFit nominal = solve(s, l, f.given, f.free, w.all);
  if (!nominal.ok) throw std::invalid_argument(s.name + ": the record does not fit a physical drive with the load's parameters free (JL > 0, FL >= 0)");
  f.nominal = nominal.m;
  std::vector<double> x(s.size()), R(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) x[k] = s.qL[k] - s.qm[k];
  const std::vector<double> xf = measurements::zero_phase_filter(x, s.filter);
  FreeSet free = f.free;
  f.m = name_effects(w, f.nominal, free, result);
  Theta current = f.nominal;
  const FlightFit flight = load_coulomb_in_flight(s, l, xf, x, options, f.m, current, result);
  if (current[kTL] != f.nominal[kTL]) f.m = name_effects(w, current, f.free, result);
  else f.free = free;
  f.sigma = summed_sigma(s, l, f.m, f.free, w.all);
  if (flight.ok && current[kTL] != f.nominal[kTL]) {
    f.m[kTL] = flight.beta * f.m[kJL], f.sigma[kTL] = flight.sigma * f.m[kJL];
  }
  f.r_given = residuals(s, l, f.given), f.r_nominal = residuals(s, l, f.nominal), f.r_after = residuals(s, l, f.m);
  f.all = w.all;
  // The gap on its faces, with the load's inverse dynamics R of the fitted model.
  for (std::size_t k = 0; k < s.size(); ++k) R[k] = f.m[kJL] * l.aL[k] + f.m[kFL] * l.vL[k] + f.m[kTL] * l.sL_f[k];
  GapFit rigid = fit_gap(s, xf, x, R, false);
  GapFit g = rigid;
  if (!std::isfinite(g.sse)) throw std::invalid_argument(s.name + ": theta_load: the gap theta_load - theta_motor shows no contact on both faces to read the backlash on");
  GapFit compliant = fit_gap(s, xf, x, R, true);
  const double n_eff = static_cast<double>(rigid.contact.size()) / tau_int_on(xf, rigid.contact);
  Candidate c;
  c.effect = "compliance";
  c.rms = c.rms_fit = c.rms_holdout = NAN;  // judged on the gap's faces (positions), not on the torque
  if (std::isfinite(compliant.sse) && compliant.contact.size() > 10) {
    c.delta_bic = n_eff * std::log(std::max(compliant.sse, 1e-300) / std::max(rigid.sse, 1e-300)) + 2 * std::log(n_eff);  // 1/kc and cm/kc
    c.at_range_edge = !(compliant.c > 0);
    c.decisive = c.delta_bic < -options.decisive_bic && !c.at_range_edge;
    if (c.decisive) g = compliant;
  } else {
    c.failure = "too few samples in contact", c.delta_bic = INFINITY;
  }
  gap_sigma(xf, x, R, g);
  if (g.c > 0) c.parameters = {{"stiffness", 1 / g.c, g.sigma_c / (g.c * g.c)}};
  result.rounds.push_back({c});
  if (c.decisive) result.effects.push_back(c), result.corrected_effects.mesh_stiffness = 1 / g.c;
  f.b = g.b, f.sigma_b = g.sigma_b;
  two.gap_offset = g.x0, two.contact_fraction = g.contact_fraction;
  std::vector<double> model_gap = load_observer(s.qmf, s.vm, s.am, s.fs, g.b, g.x0, f.m[kJL], f.m[kFL], f.m[kTL]);
  for (std::size_t k = 0; k < s.size(); ++k) model_gap[k] -= g.c * R[k];
  // The model's lost motion as the measured one is read: the swing of the gap through the same
  // filter (whose step response overshoots at each impact: the swing exceeds b by as much).
  two.reversals = lost_motion(s, &xf, measurements::zero_phase_filter(model_gap, s.filter));
  two.loop_motor = s.qm, two.loop_load = s.qL, two.loop_model.resize(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) two.loop_model[k] = s.qm[k] + model_gap[k];
}

// The motor encoder alone: the load observed for a trial shape; the shape by the profiled cost,
// first with every friction and the offset free (so that the observer moves as the load does),
// then the effects named on the observed load, then the shape again with the named ones.
void motor_encoder(const Signals& s, const DriveOptions& options, Fitted& f, DriveDiscrepancyResult& result, TwoBodyFindings& two) {
  const std::vector<std::size_t> samples = observer_samples(s);
  FreeSet everything = f.free;
  for (const auto& [effect, which] : effect_columns()) everything[which] = which != kTL && f.given[which] == 0;
  ObserverFit first = fit_shape_coarse_to_fine(s, f.given, everything, true, f.compliance, samples);
  if (!std::isfinite(first.sse)) throw std::invalid_argument(s.name + ": the record does not fit a physical drive with the load's parameters free (JL > 0, FL >= 0)");
  Theta nominal = first.m;
  for (int i : {kTm, kTL, kT0}) nominal[i] = f.given[i];
  const LoadSide l = observed_load(s, first.z.b, first.m, f.compliance);
  const LinearFit best_nominal = solve(s, l, nominal, f.free, samples);
  f.nominal = best_nominal.ok ? best_nominal.m : nominal;
  Search w{s, l, samples, {}, {}, options};
  split_blocks(s, w.all, w.fit, w.holdout);
  name_effects(w, f.nominal, f.free, result);
  const bool coulomb_load = f.free[kTL] || f.given[kTL] > 0;
  ObserverFit final_fit = first;
  final_fit.m = f.nominal;
  fit_shape(s, final_fit, f.free, coulomb_load, false, samples);
  f.sigma = observer_sigma(s, final_fit, f.free, coulomb_load, samples);
  f.m = final_fit.m, f.b = final_fit.z.b, f.sigma_b = profile_sigma_b(s, final_fit, f.free, samples);
  // The load's parameters untied from the shape: least squares of the summed equation on the
  // load the fitted shape observes (in contact the load's viscous friction is the total less the
  // motor's; the shape's α = FL/JL only governs the brief flights).
  const LoadSide observed = observed_load(s, f.b, f.m, f.compliance);
  const LinearFit untied = solve(s, observed, f.m, f.free, samples);
  if (untied.ok) f.m = untied.m;
  f.r_given = residuals(s, observed_load(s, f.given_b, f.given, f.compliance), f.given);
  f.r_nominal = residuals(s, l, f.nominal);
  f.r_after = residuals(s, observed, f.m);
  f.all = samples;
  two.torque_rms_rigid = std::sqrt(final_fit.sse_rigid / static_cast<double>(std::max<std::size_t>(1, samples.size())));
  two.contact_fraction = NAN;
  const std::vector<double> model_gap = observe(s, f.m, f.b, f.m[kJL], f.m[kFL], f.m[kTL], f.compliance);
  two.reversals = lost_motion(s, nullptr, model_gap);
  two.backlash_sigma_moves = f.sigma_b;
  two.backlash_sigma_timing = timing_sigma_b(model_gap, f.b, samples.empty() ? s.begin : samples.front(), s.end);
  f.sigma_b = std::hypot(f.sigma_b, two.backlash_sigma_timing);
}

}  // namespace

namespace {

// The status (docs/discrepancy.md, "Statuses"): effects named or a nominal parameter corrected
// beyond three σ (and 5 %) — effect_found / parameters_corrected when the corrected model's
// torque residual is at the noise, partly_explained when it stays above; else the residual at
// the noise, or unexplained.
Status status_of(const DriveDiscrepancyResult& r, const TwoBodyFindings& two) {
  const bool closed = r.rms_after <= kNoiseFactor * r.noise;
  if (!r.effects.empty()) return closed ? Status::EffectFound : Status::PartlyExplained;
  for (const ParameterCorrection& c : two.parameter_corrections) {
    const double change = std::fabs(c.fitted - c.nominal);
    if (change > 3 * c.uncertainty && change > 0.05 * std::fabs(c.nominal))
      return closed ? Status::ParametersCorrected : Status::PartlyExplained;
  }
  return r.rms_before <= kNoiseFactor * r.noise ? Status::NoDiscrepancy : Status::Unexplained;
}

// The scores and the traces for the figures.
void fill_result(const Signals& s, const Fitted& f, DriveDiscrepancyResult& r) {
  r.rms_given = rms_on(f.r_given, f.all), r.rms_before = rms_on(f.r_nominal, f.all), r.rms_after = rms_on(f.r_after, f.all);
  r.tau_int_before = tau_int_on(f.r_nominal, f.all), r.tau_int_after = tau_int_on(f.r_after, f.all);
  for (Candidate& c : r.effects) {
    const auto it = std::find_if(effect_columns().begin(), effect_columns().end(), [&](const auto& e) { return e.first == c.effect; });
    if (it != effect_columns().end()) c.parameters = {{"torque", f.m[it->second], f.sigma[static_cast<std::size_t>(it->second)]}};
  }
  r.corrected_effects.coulomb_motor = f.m[kTm], r.corrected_effects.coulomb_load = f.m[kTL];
  r.corrected_effects.torque_offset = f.m[kT0];
  r.t = s.t, r.velocity = s.vm, r.position = s.qm;
  r.torque_measured = s.Uf;
  r.torque_nominal.resize(s.size()), r.torque_corrected.resize(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) r.torque_nominal[k] = s.Uf[k] - f.r_nominal[k], r.torque_corrected[k] = s.Uf[k] - f.r_after[k];
  r.estimation = {s.name, static_cast<int>(s.size()), r.rms_before, r.rms_after, NAN, NAN, 0};
}

}  // namespace

DriveDiscrepancyResult find(const model::CaseSpec& spec, const measurements::MeasuredRecord& data, const DriveOptions& options) {
  const std::string where = spec.source.filename().string();
  check_inputs(spec, data);
  DriveDiscrepancyResult result;
  const numeric::Parameters given = numeric::parameters_of(spec);
  const numeric::Effects file_effects = numeric::effects_of(spec);
  if (file_effects.delay > 0 || file_effects.saturating() || file_effects.restitution != 0 || file_effects.stribeck())
    throw std::invalid_argument(where + ": effects: a drive with a gap is compared with Coulomb friction on either body, a torque offset "
                                "and mesh compliance; delay, saturation, restitution and Stribeck friction are not yet part of it");
  const Signals s = prepare(spec, data, options, result);
  Fitted f;
  f.given = given_theta(given, file_effects);
  f.given_b = given.backlash;
  f.compliance = file_effects.compliant() ? 1 / file_effects.mesh_stiffness : 0;
  f.free = nominal_free_of(spec, where);
  for (int i : {kTm, kTL, kT0}) f.free[i] = false;
  result.corrected_effects = file_effects;
  TwoBodyFindings two;
  two.load_encoder = s.load_logged();
  two.method = two.load_encoder ? "gap observed (both encoders)" : "load observer (motor encoder alone)";
  if (two.load_encoder) both_encoders(s, options, f, result, two);
  else motor_encoder(s, options, f, result, two);
  corrections_of(spec, f.given, f.m, f.sigma, f.free, f.b, f.sigma_b, two);
  two.reversals_count = static_cast<int>(two.reversals.size());
  if (!two.load_encoder && two.reversals_count < 5)
    throw std::invalid_argument(data.source.string() + ": the motor reverses " + std::to_string(two.reversals_count) +
                                " times: with the motor encoder alone the backlash needs at least 5 reversals (or log theta_load)");
  two.rigid = !(f.b > 3 * f.sigma_b);
  fill_result(s, f, result);
  // The noise level: the encoders' quantisation and the drive's noise propagated (not the Δ⁴
  // rule on the residual, which is filtered: far below its noise).
  two.noise = noise_level(s, f.m);
  result.noise = two.noise.level, result.position_noise = two.noise.sigma_motor, result.drive_noise = two.noise.sigma_drive;
  result.given = given;
  result.nominal = result.parameters = given;
  result.nominal.JL = f.nominal[kJL], result.nominal.FL = f.nominal[kFL], result.nominal.Jm = f.nominal[kJm], result.nominal.Fm = f.nominal[kFm];
  result.parameters.JL = f.m[kJL], result.parameters.FL = f.m[kFL], result.parameters.Jm = f.m[kJm], result.parameters.Fm = f.m[kFm];
  result.parameters.backlash = f.b;
  result.status = status_of(result, two);
  result.two_body = std::move(two);
  return result;
}

}  // namespace backlash::discrepancy::two_body
