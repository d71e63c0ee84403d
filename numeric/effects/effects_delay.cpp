// The delayed model (docs/effects.md §delay): the drive is D(t) = sat(K(θR − θo(t − τ))) + T0
// with θo(t − τ) read from the history of the simulation itself (θo(s) = θo(0) for s < 0).
// No closed form exists, so every mode is integrated by the method of steps:
//   – runge_kutta_dopri5 with step control, each step ≤ τ (so D on the step needs only the
//     history already computed) and ≤ 0.1/(fastest rate), landing exactly on the
//     breakpoints t_event + τ, t_event + 2τ where the delayed signal's derivatives jump,
//     and on the times where the delayed demand K(θR − θo(t − τ)) crosses ±L;
//   – the history is stored as quintic Hermite pieces (θo, θ̇o, θ̈o at each step's ends:
//     O(h⁶) between them, below the integrator's own error), and only as far back as the
//     delay reaches (t − τ): memory does not grow with t_end;
//   – a segment keeps at most max_segment_steps steps (a longer one ends there and the engine
//     starts the next, as at a breakpoint), and a run at most EffectsEngineOptions::
//     max_delay_steps (then work_limit): the cost is about t_end/min(τ, 0.1/rate) steps;
//   – guards are the engine's witnesses with the drive as an input (w = row·z + c + k·D(t)),
//     sampled inside each step on the step's quintic Hermite interpolant and refined with
//     Boost.Math's toms748.
// The mode logic — static rules, impacts, restitution, transitions — is the engine's, the
// same as for the closed forms (effects_engine.cpp).  The odeint simulator
// (odeint_effects_simulation.cpp) is an independent implementation of the same model.
#include "effects/effects_engine.hpp"

#include "backlash/numeric/scales.hpp"

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace backlash::numeric::detail {

namespace {

namespace odeint = boost::numeric::odeint;

constexpr double tolerance = 1e-13;  // dopri5 absolute = relative error per step (1e-11 drifted 1e-10 s per s)
constexpr int samples_per_step = 6;  // witness samples inside each step (plus its end)
// Steps kept by one segment (for its states and extremes): 65536 steps of 464 bytes, 30 MB.
constexpr std::size_t max_segment_steps = 1 << 16;

struct Jet {
  double value = 0, rate = 0, acceleration = 0;
};

// The quintic Hermite interpolant on [t0, t0 + h] matching value, rate and acceleration at
// both ends (error O(h⁶)).
class Quintic {
 public:
  Quintic() = default;
  Quintic(double t0, double t1, const Jet& y0, const Jet& y1) : t0_(t0), h_(t1 - t0) {
    const double h = h_;
    a_[0] = y0.value;
    a_[1] = h * y0.rate;
    a_[2] = h * h * y0.acceleration / 2;
    const double r0 = y1.value - a_[0] - a_[1] - a_[2];
    const double r1 = h * y1.rate - a_[1] - 2 * a_[2];
    const double r2 = h * h * y1.acceleration - 2 * a_[2];
    a_[3] = 10 * r0 - 4 * r1 + r2 / 2;
    a_[4] = -15 * r0 + 7 * r1 - r2;
    a_[5] = 6 * r0 - 3 * r1 + r2 / 2;
  }
  double start() const { return t0_; }
  double end() const { return t0_ + h_; }
  /// at(t).value alone (the same operations, so the same bits).
  double value(double t) const { return h_ <= 0 ? a_[0] : value_at_fraction((t - t0_) / h_); }
  /// The value at t0 + s·h (h > 0): value(t) with s = (t − t0)/h formed once for pieces that
  /// share t0 and h.
  double value_at_fraction(double s) const {
    double v = a_[5];
    for (int k = 4; k >= 0; --k) v = v * s + a_[k];
    return v;
  }
  double length() const { return h_; }
  /// The coefficient of s^k in value_at_fraction(s).
  double coefficient(int k) const { return a_[static_cast<std::size_t>(k)]; }
  Jet at(double t) const {
    if (h_ <= 0) return {a_[0], 0, 0};
    const double s = (t - t0_) / h_;
    double v = a_[5], d = 5 * a_[5], dd = 20 * a_[5];
    for (int k = 4; k >= 0; --k) v = v * s + a_[k];
    for (int k = 4; k >= 1; --k) d = d * s + k * a_[k];
    for (int k = 4; k >= 2; --k) dd = dd * s + k * (k - 1) * a_[k];
    return {v, d / h_, dd / (h_ * h_)};
  }

 private:
  double t0_ = 0, h_ = 0;
  std::array<double, 6> a_{};
};

// One integration step of a segment: z on [t0, t1], each coordinate a quintic.
struct Step {
  double t0, t1;
  std::array<Quintic, 4> z;  // all on the same [t0, t0 + h]
  /// z[i]'s coefficient of s^k at 4k + i (pack()): values() sums the four Horner schemes side by
  /// side, each with the operations of z[i].value_at_fraction(s) in its order (the same bits).
  alignas(16) std::array<double, 24> by_power{};

  /// Fills by_power from z (once the step's quintics are set).
  void pack() {
    for (int k = 0; k < 6; ++k)
      for (int i = 0; i < 4; ++i) by_power[static_cast<std::size_t>(4 * k + i)] = z[static_cast<std::size_t>(i)].coefficient(k);
  }
  /// The first n coordinates at t, each z[i].value(t) (the fraction (t − t0)/h formed once).
  void values(double t, int n, SmallVector& out) const {
    if (!(z[0].length() > 0)) {
      for (int i = 0; i < n; ++i) out(i) = z[i].value(t);
      return;
    }
    const double s = (t - z[0].start()) / z[0].length();
    alignas(16) std::array<double, 4> v;
    for (int i = 0; i < 4; ++i) v[i] = by_power[20 + i];
    for (int k = 4; k >= 0; --k)
      for (int i = 0; i < 4; ++i) v[i] = v[i] * s + by_power[static_cast<std::size_t>(4 * k + i)];
    for (int i = 0; i < n; ++i) out(i) = v[i];
  }
  /// Coordinate i of values(t, n, ·) alone.
  double value(double t, int i) const {
    if (!(z[0].length() > 0)) return z[static_cast<std::size_t>(i)].value(t);
    return z[static_cast<std::size_t>(i)].value_at_fraction((t - z[0].start()) / z[0].length());
  }
};

// Whether each witness is armed at the start (valid side), exits at once, departs from its
// boundary inward with a non-zero rate (armed from its first positive sample: a tiny
// bounce's return is an event however small), or waits until it is clearly inside.
enum class Arming { Armed, ExitNow, Departing, Waiting };

// A witness's row·z + c on a fixed array (a Functional's row, constant and drive weight).
struct WitnessRow {
  explicit WitnessRow(const Functional& f) : constant(f.constant), drive_weight(f.drive_weight) {
    for (Eigen::Index i = 0; i < f.row.size(); ++i) row[i] = f.row(i);
  }
  /// row·z + c summed from c in the order of the coordinates; N = z.size(), or 0 for a size known
  /// only at run time.
  template <int N>
  double sum(const SmallVector& z) const {
    const int n = N > 0 ? N : static_cast<int>(z.size());
    double s = constant;
    for (int i = 0; i < n; ++i) s += row[i] * z(i);
    return s;
  }
  std::array<double, 4> row{};
  double constant, drive_weight;
};

// A segment's working storage, handed on from segment to segment (DelayLine::take_buffers).
struct SegmentBuffers {
  std::vector<Step> steps;
  std::vector<Witness> witnesses;
  std::vector<WitnessRow> witness_rows;  // witnesses[i].f as a WitnessRow
  std::vector<double> witness_values;  // check_step's witness values at the sample before
  std::vector<double> tolerances;      // each witness's boundary tolerance (DelayedSegment::arm)
  std::vector<Arming> arming;
};

// The history of θo and the delayed drive read from it.
class DelayLine {
 public:
  DelayLine(const Parameters& p, const Effects& e, double theta_o0, long max_steps)
      : p_(p),
        e_(e),
        initial_(theta_o0),
        max_steps_(max_steps),
        saturating_(e.saturating()),
        offset_(drive_constant(e, 0)),
        high_(saturating_ ? drive_constant(e, 1) : 0),
        low_(saturating_ ? drive_constant(e, -1) : 0) {}

  /// Counts one integration step against the run's budget (SearchBudgetExhausted beyond it).
  void count_step(double t, double dt_max) {
    if (++steps_ <= max_steps_) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  "the delayed model used its budget of %ld integration steps (of at most %.3g s: the delay or "
                  "0.1 of the fastest time scale) by t = %.6g s",
                  max_steps_, dt_max, t);
    throw SearchBudgetExhausted(text);
  }

  double end() const { return empty() ? 0.0 : pieces_.back().end(); }
  double last_motion() const { return last_motion_; }

  /// Appends θo on [t0, t1]; anything recorded beyond t0 is dropped first.
  void append(double t0, double t1, const Jet& y0, const Jet& y1) {
    while (!empty() && pieces_.back().start() >= t0) pieces_.pop_back();
    forget_before(t0 - e_.delay);
    if (!(t1 > t0)) return;
    pieces_.emplace_back(t0, t1, y0, y1);
    if (y0.rate != 0 || y1.rate != 0 || y0.value != y1.value) last_motion_ = std::max(last_motion_, t1);
    schedule_regime_changes(pieces_.back());
  }

  Jet theta_o(double s) const {
    if (s <= 0 || empty()) return {initial_, 0, 0};
    const Quintic& piece = locate(s);
    return piece.at(std::min(s, piece.end()));
  }
  /// theta_o(s).value alone.
  double theta_o_value(double s) const {
    if (s <= 0 || empty()) return initial_;
    const Quintic& piece = locate(s);
    return piece.value(std::min(s, piece.end()));
  }

  double demand(double t) const { return p_.K * (p_.theta_R - theta_o(t - e_.delay).value); }
  int regime(double t) const {
    if (!e_.saturating()) return 0;
    const double d = demand(t);
    return d > e_.saturation ? 1 : d < -e_.saturation ? -1 : 0;
  }
  /// D(t) and its first two derivatives.
  Jet drive(double t) const {
    const Jet y = theta_o(t - e_.delay);
    const double d = p_.K * (p_.theta_R - y.value);
    if (saturating_ && std::fabs(d) > e_.saturation) return {d > 0 ? high_ : low_, 0, 0};
    return {d + offset_, -p_.K * y.rate, -p_.K * y.acceleration};
  }
  /// drive(t).value alone (the integrator's right-hand side and the witnesses need no more).
  double drive_value(double t) const {
    const double d = p_.K * (p_.theta_R - theta_o_value(t - e_.delay));
    if (saturating_ && std::fabs(d) > e_.saturation) return d > 0 ? high_ : low_;
    return d + offset_;
  }

  /// Storage for a segment: the one the last segment gave back (steps cleared), so that a run
  /// allocates for its largest segment only.
  SegmentBuffers take_buffers() {
    SegmentBuffers b = std::move(spare_);
    b.steps.clear();
    return b;
  }
  void give_back(SegmentBuffers&& b) { spare_ = std::move(b); }

  /// The times where the delayed demand crosses ±L, with the regime after each.
  const std::map<double, int>& regime_changes() const { return changes_; }
  /// The first such time after t (infinity if none is known yet: the history may add some).
  double next_change_after(double t) const {
    const auto c = changes_.upper_bound(t + 1e-12 * std::max(1.0, std::fabs(t)));
    return c == changes_.end() ? INFINITY : c->first;
  }

 private:
  // Nothing before `s` is read again: the drive at t ≥ t0 reads θo at t − τ ≥ t0 − τ, and the
  // regime changes before t0 have been reported.
  void forget_before(double s) {
    std::size_t dropped = 0;
    while (pieces_.size() - first_ > 1 && pieces_[first_].end() < s) {
      ++first_;
      ++dropped;
    }
    cursor_ = cursor_ > dropped ? cursor_ - dropped : 0;
    // The dropped pieces leave the buffer once they are half of it (no allocation per piece).
    if (first_ >= 64 && 2 * first_ >= pieces_.size()) {
      pieces_.erase(pieces_.begin(), pieces_.begin() + static_cast<std::ptrdiff_t>(first_));
      first_ = 0;
    }
    changes_.erase(changes_.begin(), changes_.lower_bound(s));
  }

  // The piece that holds s, searched from the last one found: on a boundary shared by two pieces
  // the one found depends on the side the search comes from (kept as it is: the same bits).
  const Quintic& locate(double s) const {
    const Quintic* kept = pieces_.data() + first_;
    const std::size_t n = pieces_.size() - first_;
    std::size_t k = std::min(cursor_, n - 1);
    while (k > 0 && kept[k].start() > s) --k;
    while (k + 1 < n && kept[k].end() < s) ++k;
    cursor_ = k;
    return kept[k];
  }
  bool empty() const { return pieces_.size() == first_; }

  // θo crossing θR ∓ L/K at s makes the demand at s + τ cross ±L.
  void schedule_regime_changes(const Quintic& piece) {
    if (!e_.saturating()) return;
    for (int level_sign : {1, -1}) {
      const double level = p_.theta_R - level_sign * e_.saturation / p_.K;  // demand = level_sign·L there
      auto f = [&](double s) { return piece.value(s) - level; };
      double a = piece.start(), fa = f(a);
      for (int k = 1; k <= 8; ++k) {
        const double b = piece.start() + (piece.end() - piece.start()) * k / 8, fb = f(b);
        if ((fa < 0 && fb >= 0) || (fa > 0 && fb <= 0)) {
          std::uintmax_t iterations = 100;
          const auto r = boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(50),
                                                           iterations);
          const double s = 0.5 * (r.first + r.second);
          // θo falling through θR − L/K: the demand rises through +L (clipped high), and so on.
          const bool entering = level_sign > 0 ? fb < fa : fb > fa;
          changes_[s + e_.delay] = entering ? level_sign : 0;
        }
        a = b;
        fa = fb;
      }
    }
  }

  const Parameters& p_;
  const Effects& e_;
  double initial_;
  long max_steps_, steps_ = 0;
  bool saturating_;
  double offset_, high_, low_;  // drive_constant(e, 0), and (1), (−1) when saturating
  std::vector<Quintic> pieces_;  // the history is pieces_[first_], pieces_[first_ + 1], …
  std::size_t first_ = 0;
  mutable std::size_t cursor_ = 0;  // counted from first_
  double last_motion_ = 0;
  std::map<double, int> changes_;
  SegmentBuffers spare_;
};

using Vector = std::array<double, 4>;

// z' = A z + c + b·D(t) as the integrator's right-hand side, on fixed arrays (sized at compile
// time for the two dimensions, 2 in contact and 4 otherwise): each row summed in the same order.
struct FlatSystem {
  FlatSystem() = default;
  explicit FlatSystem(const ModeSystem& sys) : n(static_cast<int>(sys.segment.A.rows())) {
    for (int i = 0; i < n; ++i) {
      c[i] = sys.segment.c(i);
      b[i] = sys.drive_column(i);
      for (int j = 0; j < n; ++j) A[4 * i + j] = sys.segment.A(i, j);
    }
  }
  /// dx = A x + c + b·drive; N = n, or 0 for a size known only at run time.
  template <int N>
  void apply(const Vector& x, Vector& dx, double drive) const {
    const int m = N > 0 ? N : n;
    for (int i = 0; i < m; ++i) {
      double sum = c[i] + b[i] * drive;
      for (int j = 0; j < m; ++j) sum += A[4 * i + j] * x[j];
      dx[i] = sum;
    }
    for (int i = m; i < 4; ++i) dx[i] = 0;
  }
  /// Row i of A·z in Eigen's order for a small product of dynamic size (its packet loop,
  /// ProductEvaluators.h etor_product_packet_impl: from 0, adding A(i, j)·z(j) for j = 0, 1, …).
  /// N = n, or 0 for a size known only at run time.
  template <int N>
  double product(int i, const SmallVector& z) const {
    const int m = N > 0 ? N : n;
    double sum = 0;
    for (int j = 0; j < m; ++j) sum += A[4 * i + j] * z(j);
    return sum;
  }
  int n = 0;
  std::array<double, 16> A{};  // row i at 4i
  std::array<double, 4> c{}, b{};
};

// One mode integrated from the engine's state, with its guards.
class DelayedSegment final : public Segment {
 public:
  DelayedSegment(const Parameters& p, const Effects& e, const Mode& m, const HybridState& start, double t0,
                 double horizon, double stop_at, DelayLine& line, int left_zone, double rest_velocity)
      : p_(p), e_(e), m_(m), start_(start), t0_(t0), line_(line), rest_velocity_(rest_velocity),
        buffers_(line.take_buffers()) {
    sys_ = mode_system(p, e, m, start, true);
    flat_ = FlatSystem(sys_);
    n_ = static_cast<int>(sys_.segment.A.rows());
    functionals_.dimension = n_;
    functionals_.theta_o_error = theta_o_error();
    functionals_.gap = gap();
    functionals_.drive = Functional{SmallRow::Zero(n_), 0, 0, 1};
    functionals_.left_zone = left_zone;
    mode_witnesses(p, e, m, functionals_, false, witnesses_);
    witness_rows_.clear();
    for (const Witness& w : witnesses_) witness_rows_.emplace_back(w.f);
    witness_buffer_.resize(witnesses_.size());
    const double stop = std::min(t0 + horizon, stop_at);
    const bool stuck = m.kind == ModeKind::Contact ? m.slip_motor == 0 : (m.slip_motor == 0 && m.slip_load == 0);
    if (stuck) {
      hold_still(stop);
      finish_at(stop);
    } else {
      finish_at(integrate(stop));
    }
  }

  ~DelayedSegment() override { line_.give_back(std::move(buffers_)); }
  DelayedSegment(const DelayedSegment&) = delete;
  DelayedSegment& operator=(const DelayedSegment&) = delete;

  HybridState state(double tau) const override { return state_of(z_at(t0_ + tau)); }
  /// measured(p, state(τ)) from θo's coordinate alone (its one quintic, not the state's n).
  double measured_at(const Parameters&, double tau) const override {
    return measured(p_, start_) + z_at(t0_ + tau, theta_o_index());
  }

  void extremes(double until, Extremes& x) const override {
    include(state(0), x);
    include(state(until), x);
    const int rows[] = {1, 3};  // the velocities: ω in contact, θ̇m and θ̇L in flight
    const int row_count = m_.kind == ModeKind::Contact ? 1 : 2;
    for (const Step& step : steps_) {
      const double b_end = std::min(step.t1, t0_ + until);
      if (!(b_end > step.t0)) break;
      for (int r = 0; r < row_count; ++r) {
        const int row = rows[r];
        auto v = [&](double t) { return step.z[row].value(t); };
        double a = step.t0, va = v(a);
        for (int k = 1; k <= samples_per_step; ++k) {
          const double b = step.t0 + (b_end - step.t0) * k / samples_per_step, vb = v(b);
          if ((va < 0 && vb >= 0) || (va > 0 && vb <= 0)) {
            std::uintmax_t iterations = 100;
            const auto r = boost::math::tools::toms748_solve(v, a, b, va, vb, boost::math::tools::eps_tolerance<double>(50),
                                                             iterations);
            include(state(0.5 * (r.first + r.second) - t0_), x);
          }
          a = b;
          va = vb;
        }
      }
    }
  }

 private:

  Functional theta_o_error() const {
    Functional f{SmallRow::Zero(n_), measured(p_, start_) - p_.theta_R,
                 std::fabs(measured(p_, start_)) + std::fabs(p_.theta_R), 0};
    f.row(m_.kind == ModeKind::Contact ? 0 : (p_.measured_at == model::MeasuredAt::Motor ? 0 : 2)) = 1;
    return f;
  }
  Functional gap() const {
    Functional f{SmallRow::Zero(n_), 0, 0, 0};
    if (m_.kind == ModeKind::Contact) {
      f.constant = m_.face * p_.backlash / 2;
      f.magnitude = p_.backlash / 2;
    } else {
      f.row(0) = -1;
      f.row(2) = 1;
      f.constant = start_.theta_L - start_.theta_m;
      f.magnitude = std::fabs(start_.theta_L) + std::fabs(start_.theta_m);
      for (int face : {-1, 1})  // a flight placed on a face starts exactly there (effect_modes.cpp)
        if (std::fabs(f.constant - face * p_.backlash / 2) <= 8 * std::numeric_limits<double>::epsilon() * f.magnitude)
          f.constant = face * p_.backlash / 2;
    }
    return f;
  }

  // z' and z'' from z at time t: z' = A z + c + b D(t), z'' = A z' + b D'(t).  Summed as Eigen
  // sums these products of at most 4 (FlatSystem::product): the bits of the Eigen expressions
  // (A z + c) + b D and A z' + b D'.
  std::pair<SmallVector, SmallVector> derivatives(const SmallVector& z, double t) const {
    const Jet d = line_.drive(t);
    return n_ == 4 ? derivatives<4>(z, d) : n_ == 2 ? derivatives<2>(z, d) : derivatives<0>(z, d);
  }
  template <int N>
  std::pair<SmallVector, SmallVector> derivatives(const SmallVector& z, const Jet& d) const {
    const int n = N > 0 ? N : n_;
    SmallVector z1(n), z2(n);
    for (int i = 0; i < n; ++i) z1(i) = (flat_.product<N>(i, z) + flat_.c[i]) + flat_.b[i] * d.value;
    for (int i = 0; i < n; ++i) z2(i) = flat_.product<N>(i, z1) + flat_.b[i] * d.rate;
    return {z1, z2};
  }

  // Witness i's value at z and t.
  double witness_value(std::size_t i, const SmallVector& z, double t) const {
    const double sum = witness_sum(i, z);
    const double k = witness_rows_[i].drive_weight;
    return k != 0 ? sum + k * line_.drive_value(t) : sum;
  }
  // Witness i without its drive term, row·z + c.
  double witness_sum(std::size_t i, const SmallVector& z) const {
    const WitnessRow& w = witness_rows_[i];
    return n_ == 4 ? w.sum<4>(z) : n_ == 2 ? w.sum<2>(z) : w.sum<0>(z);
  }

  SmallVector z_at(double t) const {
    if (steps_.empty() || t <= steps_.front().t0) return sys_.z0;
    const Step& step = steps_[std::min(step_after(t), steps_.size() - 1)];
    SmallVector z(n_);
    step.values(std::min(t, step.t1), n_, z);
    return z;
  }
  /// z_at(t)(i) alone (the same step found, the same operations).
  double z_at(double t, int i) const {
    if (steps_.empty() || t <= steps_.front().t0) return sys_.z0(i);
    const Step& step = steps_[std::min(step_after(t), steps_.size() - 1)];
    return step.value(std::min(t, step.t1), i);
  }

  // The first step whose end is beyond t (steps_.size() if none): std::upper_bound on the ends,
  // which never decrease, searched from the step found last (states are read in order of time).
  std::size_t step_after(double t) const {
    std::size_t k = std::min(step_cursor_, steps_.size());
    while (k > 0 && t < steps_[k - 1].t1) --k;
    while (k < steps_.size() && !(t < steps_[k].t1)) ++k;
    step_cursor_ = k;
    return k;
  }

  HybridState state_of(const SmallVector& z) const {
    HybridState h;
    if (m_.kind == ModeKind::Contact) {
      h = state_on_face(p_, m_.face, measured(p_, start_) + z(0), z(1), true);
      h.motor_stuck = h.load_stuck = m_.slip_motor == 0;
    } else {
      h.theta_m = start_.theta_m + z(0);
      h.dtheta_m = z(1);
      h.theta_L = start_.theta_L + z(2);
      h.dtheta_L = z(3);
      h.in_contact = m_.kind == ModeKind::Mesh;
      h.face = m_.face;
      h.motor_stuck = m_.slip_motor == 0;
      h.load_stuck = m_.slip_load == 0;
    }
    h.drive_regime = start_.drive_regime;
    return h;
  }

  // The coordinate of z that is θo less its start.
  int theta_o_index() const {
    return m_.kind == ModeKind::Contact ? 0 : (p_.measured_at == model::MeasuredAt::Motor ? 0 : 2);
  }
  Jet theta_o_jet(const SmallVector& z, const SmallVector& z1, const SmallVector& z2) const {
    const int i = theta_o_index();
    return {measured(p_, start_) + z(i), z1(i), z2(i)};
  }

  // Arms a witness at the segment's start (Arming).
  Arming arm(std::size_t i, double& tolerance_out) const {
    const Witness& w = witnesses_[i];
    const auto [z1, z2] = derivatives(sys_.z0, t0_);
    const Jet d = line_.drive(t0_);
    const double w0 = witness_value(i, sys_.z0, t0_);
    const double w1 = w.f.row.dot(z1) + w.f.drive_weight * d.rate;
    // On the boundary: within the rounding of its terms, or what the previous event's time
    // tolerance moves it (as the closed-form engine, effects_simulation.cpp).
    const double tol = 64 * std::numeric_limits<double>::epsilon() *
                           (w.f.row.cwiseAbs().dot(sys_.z0.cwiseAbs().transpose()) + w.f.magnitude +
                            std::fabs(w.f.drive_weight * d.value)) +
                       32 * w.f.row.cwiseAbs().dot(sys_.z0_noise.transpose()) + std::fabs(w1) * 4e-14 * std::max(1.0, t0_);
    tolerance_out = tol;
    if (w0 > tol) return Arming::Armed;
    if (w0 < -tol) return Arming::ExitNow;
    const double s1 = w.f.row.cwiseAbs().dot((sys_.segment.A.cwiseAbs() * (sys_.z0.cwiseAbs() + sys_.z0_noise) +
                                              sys_.c_magnitude + sys_.drive_column.cwiseAbs() * std::fabs(d.value))
                                                 .transpose()) +
                      std::fabs(w.f.drive_weight * d.rate);
    if (std::fabs(w1) > 1e-9 * s1) return w1 < 0 ? Arming::ExitNow : Arming::Departing;
    const double w2 = w.f.row.dot(z2) + w.f.drive_weight * d.acceleration;
    if (w2 < 0 && std::fabs(w2) > 1e-9 * (s1 + std::fabs(w.f.drive_weight * d.acceleration))) return Arming::ExitNow;
    return Arming::Waiting;
  }

  // The motor stuck and the load coasting without Coulomb friction (docs/effects.md, "Rest"):
  // once the coast has lasted a delay, the drive ahead is fed θo between θL(t − τ) and where the
  // load ends, θL + θ̇L·JL/FL (a viscous coast is monotone).  When the drive over that range
  // keeps one regime inside the motor's band and the gap stays open on both sides, nothing can
  // happen any more: at rest once θ̇L is below the rest velocity, as the nominal rule.
  bool coasts_to_rest(double t, const SmallVector& z) const {
    if (m_.kind != ModeKind::Free || m_.slip_motor != 0 || m_.slip_load == 0 || e_.coulomb_load > 0 || !(p_.FL > 0))
      return false;
    if (t - e_.delay < t0_ || !(std::fabs(z(3)) < rest_velocity_)) return false;
    const double travel = z(3) * p_.JL / p_.FL, theta_L = start_.theta_L + z(2);
    const double gap = theta_L - start_.theta_m;
    if (!(std::max(std::fabs(gap), std::fabs(gap + travel)) < p_.backlash / 2)) return false;
    if (p_.measured_at == model::MeasuredAt::Motor) return true;  // θo = θm: the drive is constant
    const double from = start_.theta_L + z_at(t - e_.delay)(2), to = theta_L + travel;
    if (drive_regime(p_, e_, from) != drive_regime(p_, e_, to)) return false;
    return std::fabs(drive_torque(p_, e_, from)) < e_.coulomb_motor && std::fabs(drive_torque(p_, e_, to)) < e_.coulomb_motor;
  }

  // Everything stuck: only the delayed drive moves; the history stays at the current θo.
  void hold_still(double stop) {
    const double quiet = line_.last_motion() + e_.delay;
    std::vector<double>& tolerances = buffers_.tolerances;
    tolerances.resize(witnesses_.size());
    for (std::size_t i = 0; i < witnesses_.size(); ++i) {
      if (arm(i, tolerances[i]) == Arming::ExitNow) {
        exit = Exit{0, witnesses_[i], false};
        return;
      }
    }
    const double until = std::min(stop, std::max(quiet, t0_));
    const int samples = std::max(8, static_cast<int>(std::ceil((until - t0_) / (0.02 * std::max(e_.delay, 1e-6)))));
    double a = t0_;
    for (int k = 1; k <= samples && until > t0_; ++k) {
      const double b = t0_ + (until - t0_) * k / samples;
      for (std::size_t i = 0; i < witnesses_.size(); ++i) {
        const Witness& w = witnesses_[i];
        auto f = [&](double t) { return witness_value(i, sys_.z0, t); };
        const double fa = f(a), fb = f(b);
        if (fa >= 0 && fb < 0) {
          std::uintmax_t iterations = 100;
          const auto r = boost::math::tools::toms748_solve(f, a, b, fa, fb, boost::math::tools::eps_tolerance<double>(50),
                                                           iterations);
          const double t = 0.5 * (r.first + r.second);
          if (!exit || t - t0_ < exit->tau) exit = Exit{t - t0_, w, false};
        }
      }
      if (exit) break;
      a = b;
    }
    const double end = exit ? t0_ + exit->tau : stop;
    const Jet still{measured(p_, start_), 0, 0};
    line_.append(t0_, end, still, still);
    if (!exit && quiet <= stop) rest = true;
  }

  // Returns where the segment ends: `stop`, an exit, or the end of its last kept step.
  double integrate(double stop) {
    const double dt_max = std::min(e_.delay, 0.1 / fastest_mode_rate(p_, e_));
    std::vector<Arming>& arming = buffers_.arming;
    std::vector<double>& tolerances = buffers_.tolerances;
    arming.resize(witnesses_.size());
    tolerances.resize(witnesses_.size());
    for (std::size_t i = 0; i < witnesses_.size(); ++i) {
      arming[i] = arm(i, tolerances[i]);
      if (arming[i] == Arming::ExitNow) {
        exit = Exit{0, witnesses_[i], false};
        return stop;
      }
    }
    const FlatSystem& flat = flat_;
    auto rhs = [this, &flat](const Vector& x, Vector& dx, double t) {
      const double drive = line_.drive_value(t);
      if (flat.n == 4) flat.apply<4>(x, dx, drive);
      else if (flat.n == 2) flat.apply<2>(x, dx, drive);
      else flat.apply<0>(x, dx, drive);
    };
    auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<Vector>());
    Vector x{};
    for (int i = 0; i < n_; ++i) x[i] = sys_.z0(i);
    SmallVector za = sys_.z0;
    auto [za1, za2] = derivatives(za, t0_);
    // A witness that leaves its boundary inward but curves back (w' > 0 > w'') returns after
    // about 2w'/|w''|: the first step is kept well below that, so its samples see the flight.
    double dt = std::min(dt_max, std::max(1e-6, 1e-3 * dt_max));
    for (std::size_t i = 0; i < witnesses_.size(); ++i) {
      if (arming[i] != Arming::Departing && arming[i] != Arming::Waiting) continue;
      double w1 = witnesses_[i].f.drive_weight * line_.drive(t0_).rate, w2 = witnesses_[i].f.drive_weight * line_.drive(t0_).acceleration;
      for (int j = 0; j < n_; ++j) w1 += witnesses_[i].f.row(j) * za1(j), w2 += witnesses_[i].f.row(j) * za2(j);
      if (w1 > 0 && w2 < 0) dt = std::min(dt, 0.25 * w1 / -w2);
    }
    double t = t0_;
    while (t < stop && !exit) {
      const double ta = t;
      // Stop on a change of the delayed drive's regime the history has just revealed.
      const double end = std::min(stop, line_.next_change_after(t));
      double trial = std::min({dt, dt_max, end - t});
      if (end - t - trial < 1e-12 * std::max(1.0, end)) trial = end - t;
      if (stepper.try_step(rhs, x, t, trial) != odeint::success) {
        dt = trial;
        continue;
      }
      dt = trial;  // the stepper proposes the next step in `trial`
      if (t > end || end - t < 1e-12 * std::max(1.0, end)) t = end;
      SmallVector zb(n_);
      for (int i = 0; i < n_; ++i) zb(i) = x[i];
      const auto [zb1, zb2] = derivatives(zb, t);
      Step& step = steps_.emplace_back();  // built in place (464 bytes)
      step.t0 = ta;
      step.t1 = t;
      for (int i = 0; i < n_; ++i) step.z[i] = Quintic(ta, t, {za(i), za1(i), za2(i)}, {zb(i), zb1(i), zb2(i)});
      step.pack();
      const double kept_until = check_step(steps_.back(), arming, tolerances);
      const Step& kept = steps_.back();
      const Jet je = kept.z[theta_o_index()].at(kept_until);  // θo's coordinate alone is recorded
      line_.append(ta, kept_until, theta_o_jet(za, za1, za2),
                   {measured(p_, start_) + je.value, je.rate, je.acceleration});
      za = zb;
      za1 = zb1;
      za2 = zb2;
      if (!exit && t == end && end < stop) regime_change(end);
      line_.count_step(t, dt_max);
      if (!exit && t < stop && steps_.size() >= max_segment_steps) return t;  // the engine goes on from here
      if (!exit && t < stop && coasts_to_rest(t, zb)) {
        rest = true;
        rest_after = t - t0_;
        return t;
      }
    }
    return stop;
  }

  // The delayed drive enters or leaves its limit at t: an exit of this segment.
  void regime_change(double t) {
    const auto change = line_.regime_changes().find(t);
    if (change == line_.regime_changes().end()) return;
    const int regime = change->second;
    const Guard guard = regime > 0 ? Guard::DriveHigh : regime < 0 ? Guard::DriveLow : Guard::DriveLeave;
    exit = Exit{t - t0_, Witness{guard, 0, Functional{SmallRow::Zero(n_), 0, 0, 0}}, false};
  }

  // Witness exits inside a step, on its interpolant; returns the end of the step that is kept.
  double check_step(const Step& step, std::vector<Arming>& arming, const std::vector<double>& tolerances) {
    auto z_of = [&step, this](double t) {
      SmallVector z(n_);
      step.values(t, n_, z);
      return z;
    };
    // The drive at a sample is read once for all witnesses, as reading it again at the same time
    // returns it again; it is read afresh after a refinement has read the history elsewhere
    // (DelayLine::locate's cursor: the same reads in the same order, the same bits).
    double drive = 0;
    bool drive_read = false;
    auto value = [&](std::size_t i, const SmallVector& z, double t) {
      const double sum = witness_sum(i, z);
      const double k = witness_rows_[i].drive_weight;
      if (k == 0) return sum;
      if (!drive_read) drive = line_.drive_value(t), drive_read = true;
      return sum + k * drive;
    };
    double a = step.t0;
    std::vector<double>& wa = witness_buffer_;
    const std::size_t count = witnesses_.size();
    const SmallVector z_a = z_of(a);
    for (std::size_t i = 0; i < count; ++i) wa[i] = value(i, z_a, a);
    std::optional<Exit> first;  // empty at every sample: the first exit ends the search
    for (int k = 1; k <= samples_per_step; ++k) {
      const double b = k == samples_per_step ? step.t1 : step.t0 + (step.t1 - step.t0) * k / samples_per_step;
      const SmallVector zb = z_of(b);
      drive_read = false;
      for (std::size_t i = 0; i < count; ++i) {
        const Witness& w = witnesses_[i];
        const double wb = value(i, zb, b);
        if (arming[i] == Arming::Armed && wa[i] >= 0 && wb < 0) {
          auto f = [&](double t) { return witness_value(i, z_of(t), t); };
          std::uintmax_t iterations = 100;
          const auto r = boost::math::tools::toms748_solve(f, a, b, wa[i], wb,
                                                           boost::math::tools::eps_tolerance<double>(50), iterations);
          const double t = 0.5 * (r.first + r.second);
          if (!first || t - t0_ < first->tau) first = Exit{t - t0_, w, false};
          drive_read = false;
        }
        if ((arming[i] == Arming::Waiting && wb > tolerances[i]) || (arming[i] == Arming::Departing && wb > 0))
          arming[i] = Arming::Armed;
        wa[i] = wb;
      }
      if (first) {
        exit = first;
        steps_.back().t1 = t0_ + first->tau;
        return steps_.back().t1;
      }
      a = b;
    }
    return step.t1;
  }

  void finish_at(double stop) {
    if (exit) {
      duration = exit->tau;
      return;
    }
    duration = stop - t0_;
    if (rest) return;
    regime_change(stop);
    if (exit) duration = exit->tau;
  }

  void include(const HybridState& h, Extremes& x) const { include_extremes(p_, h, x); }

  const Parameters& p_;
  const Effects& e_;
  Mode m_;
  HybridState start_;
  double t0_;
  DelayLine& line_;
  double rest_velocity_;
  ModeSystem sys_;
  FlatSystem flat_;  // sys_ on fixed arrays
  int n_ = 4;
  ModeFunctionals functionals_;
  SegmentBuffers buffers_;  // line_'s, given back at the end
  std::vector<Witness>& witnesses_ = buffers_.witnesses;
  std::vector<WitnessRow>& witness_rows_ = buffers_.witness_rows;
  std::vector<double>& witness_buffer_ = buffers_.witness_values;
  std::vector<Step>& steps_ = buffers_.steps;
  mutable std::size_t step_cursor_ = 0;  // step_after's last answer
};

class DelayedEngine final : public Engine {
 public:
  DelayedEngine(const Parameters& p, const Effects& e, const SimulationOptions& options,
                const EffectsEngineOptions& engine, double theta_o0)
      : Engine(p, e, options, engine), line_(p, e, theta_o0, engine.max_delay_steps) {
    breakpoints_.insert(e.delay);
    breakpoints_.insert(2 * e.delay);
  }

 protected:
  double drive_now() const override { return line_.drive(t_).value; }

  std::unique_ptr<Segment> next_segment(const Mode& mode, double remaining) override {
    for (; events_seen_ < result_.events.size(); ++events_seen_) {
      const double t = result_.events[events_seen_].t;
      breakpoints_.insert(t + e_.delay);
      breakpoints_.insert(t + 2 * e_.delay);
    }
    // The regime the drive is in now (a change at exactly t_ has been reported already).
    const Mode m = mode;
    double stop = t_ + remaining;
    const double slack = 1e-12 * std::max(1.0, t_);
    breakpoints_.erase(breakpoints_.begin(), breakpoints_.lower_bound(t_ - e_.delay));  // behind us
    if (auto b = breakpoints_.upper_bound(t_ + slack); b != breakpoints_.end()) stop = std::min(stop, *b);
    const auto& changes = line_.regime_changes();
    if (auto c = changes.upper_bound(t_ + slack); c != changes.end()) stop = std::min(stop, c->first);
    return std::make_unique<DelayedSegment>(p_, e_, m, state_, t_, remaining, stop, line_, left_zone(), o_.rest_velocity);
  }

 private:
  DelayLine line_;
  std::set<double> breakpoints_;
  std::size_t events_seen_ = 0;
};

}  // namespace

SimulationResult simulate_delayed(const Parameters& p, const Effects& e, const HybridState& start,
                                  const SimulationOptions& options, const EffectsEngineOptions& engine) {
  HybridState s = start;
  s.drive_regime = drive_regime(p, e, measured(p, start));
  return DelayedEngine(p, e, options, engine, measured(p, start)).run(s);
}

}  // namespace backlash::numeric::detail
