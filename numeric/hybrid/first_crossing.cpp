#include "backlash/numeric/first_crossing.hpp"

#include "hybrid/balancing.hpp"
#include "hybrid/certified_search.hpp"
#include "hybrid/gap_events.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>

namespace backlash::numeric {

using detail::growth_bound;
using detail::kSampleNoise;
using detail::Sampler;
using detail::search;
using detail::StartRates;

namespace {

// The logarithmic norm μ∞(A) = max_i (a_ii + Σ_{j≠i} |a_ij|): ‖e^{At}‖∞ ≤ e^{μ∞(A) t} for t ≥ 0
// (Dahlquist).  It is never larger than ‖A‖∞ and, unlike it, is not inflated by a fast decaying
// mode (a load whose friction stops it in microseconds has a_33 = −FL/JL ≪ 0): the growth bound
// of a stiff segment then allows intervals on the slow time scale instead of the fast one.
double log_norm(const SmallMatrix& A) {
  double mu = -INFINITY;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    double row = A(i, i);
    for (Eigen::Index j = 0; j < A.cols(); ++j)
      if (j != i) row += std::fabs(A(i, j));
    mu = std::max(mu, row);
  }
  return A.rows() > 0 ? mu : 0.0;
}

// The first window of a search (WitnessMode::first_window): kWindowRates over the mode's fastest
// rate, estimated as max_i |a_ii| + max_{i≠j} √|a_ij a_ji| — unchanged by a diagonal scaling of the
// state (the units of θ and θ̇), ω for an oscillator's [[0, 1], [−ω², −2α]] plus its 2α.
constexpr double kWindowRates = 4;

double window_of(const SmallMatrix& A) {
  double diagonal = 0, coupling = 0;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    diagonal = std::max(diagonal, std::fabs(A(i, i)));
    for (Eigen::Index j = 0; j < i; ++j) coupling = std::max(coupling, std::sqrt(std::fabs(A(i, j) * A(j, i))));
  }
  const double rate = diagonal + coupling;
  return rate > 0 ? kWindowRates / rate : INFINITY;
}

// A stiff segment's state mixes scales: in contact x = (θ, θ̇) with θ̇ ~ √(K/J)·θ, and A has
// the entry K/J.  Measured in ‖·‖∞ the growth bound e^{μ∞(A) h} then allows intervals of
// 1/μ∞(A) ~ J/K (1e-12 s for K = 1e12) where the motion's time scale is √(J/K) (1e-6 s): the
// search bisects a million times too deep, and stops at min_interval as a false "grazing".
// The same bound holds in any diagonally scaled norm ‖D·‖∞ (ẑ = D z obeys ẑ' = D A D⁻¹ ẑ), and
// with D balancing A (Osborne's iteration, the LAPACK gebal rule, powers of two: exact) μ∞ is
// √(K/J) again.  The scaling is taken only when it lowers μ∞ by more than kBalanceGain: for
// matrices with entries of one scale (the thesis's cases) the bound, and so every interval
// and event time, stays exactly the unscaled one.
constexpr double kBalanceGain = 16;

// Whether w''(0) is resolved from the error of the start's time.  The flight starts at an event
// located to a tolerance δt (CrossingOptions::time_tolerance relative to the time unit, times
// the segment's length in units): a start shifted by δt along the motion has w''(0) moved by
// w'''·δt.  On the separation line w''(0) = 0 exactly, and what is computed there is that shift,
// of order 0.1 rad/s² for K = 1e12 (w''' ~ 1e19 rad/s³, δt ~ 1e-20 s).  Taken as the leading
// term it certifies a departure of only ~|w''/w'''| (5e-21 s), and the search from there finds
// the spurious zero of w''t²/2 + w'''t³/6 at −3w''/w''' as a return to the face just left: a
// flight of no length (docs/physics.md, leaving a face).  A bounce's w''(0) (the torque after
// the impact) is a genuine leading term however small, as long as it exceeds that shift.
constexpr double kStartTimeUncertainty = 1e-12;  // in time units: 100 × time_tolerance

bool quadratic_resolved(double second, double third, double time_unit) {
  if (!std::isfinite(third)) return true;
  return std::fabs(second) > std::fabs(third) * kStartTimeUncertainty * time_unit;
}


// The LinearWitness form as a sampler: x = state(t), value = value(t) or eᵀx.
WitnessSample sample_of(const LinearWitness& witness, double t) {
  WitnessSample s{witness.state(t), 0};
  s.value = witness.value ? witness.value(t) : witness.e.dot(s.x);
  return s;
}

}  // namespace

namespace {

// A per-thread memo of the last N values of a pure function, kept by the bits of its inputs (Key,
// compared with ==): a kept value is what computing again would give.  The least recently used
// goes.  kept_matrix_scales and kept_witness_mode use it.
template <class Key, class Value, std::size_t N>
class RecentlyKept {
 public:
  template <class Compute>
  const Value& get(const Key& key, const Compute& compute) {
    std::optional<Slot>* oldest = &slots_[0];
    for (std::optional<Slot>& s : slots_) {
      if (s && s->key == key) {
        s->used = ++clock_;
        return s->value;
      }
      if (!s || (*oldest && s->used < (*oldest)->used)) oldest = &s;  // an empty slot, else the least recently used
    }
    oldest->emplace(Slot{key, compute(), ++clock_});
    return (*oldest)->value;
  }

 private:
  struct Slot {
    Key key;
    Value value;
    long used = 0;
  };
  std::array<std::optional<Slot>, N> slots_;
  long clock_ = 0;
};

// The bits of a matrix of at most 16 entries, with its shape.
struct MatrixKey {
  std::array<double, 16> bits{};
  Eigen::Index rows = -1, cols = -1;
  explicit MatrixKey(const SmallMatrix& A) : rows(A.rows()), cols(A.cols()) {
    std::copy(A.data(), A.data() + A.size(), bits.data());
  }
  bool operator==(const MatrixKey& o) const {
    return rows == o.rows && cols == o.cols && std::memcmp(bits.data(), o.bits.data(), sizeof bits) == 0;
  }
};

// What a witness's constants take from its matrix A alone (μ∞ and the balancing D, the first
// window, ‖D A‖∞, ‖A‖∞, max 1/D_i): the same for every witness on one mode matrix.
struct MatrixScales {
  double mu_A, first_window, norm_A, norm_A_plain, inverse_scale;
  SmallVector scale;
};

MatrixScales matrix_scales(const SmallMatrix& A) {
  MatrixScales m;
  m.mu_A = log_norm(A);
  m.first_window = window_of(A);
  m.scale = SmallVector::Ones(A.rows());
  if (m.mu_A > 0) {
    const SmallVector d = detail::balancing(A);
    const SmallMatrix balanced = d.asDiagonal() * A * d.cwiseInverse().asDiagonal();
    const double mu_balanced = log_norm(balanced);
    if (mu_balanced * kBalanceGain < m.mu_A) {
      m.scale = d;
      m.mu_A = mu_balanced;
    }
  }
  m.norm_A = (m.scale.asDiagonal() * A).cwiseAbs().rowwise().sum().maxCoeff();
  m.norm_A_plain = A.cwiseAbs().rowwise().sum().maxCoeff();
  m.inverse_scale = m.scale.cwiseInverse().maxCoeff();
  return m;
}

// matrix_scales(A), kept by A's bits (this thread's last four matrices): a parameter set's gap
// and velocity witnesses share the free mode's A, a map's points the contact mode's (docs/design.md,
// "Design-space maps") — the same function of the same bits, computed once.
const MatrixScales& kept_matrix_scales(const SmallMatrix& A) {
  thread_local RecentlyKept<MatrixKey, MatrixScales, 4> kept;
  return kept.get(MatrixKey(A), [&A] { return matrix_scales(A); });
}

}  // namespace

WitnessMode::WitnessMode(const SmallMatrix& A_, const SmallVector& c_, const SmallRow& e_, double time_unit_)
    : A(A_), e(e_), time_unit(time_unit_) {
  eA = e * A;
  eA2 = eA * A;
  eA3 = eA2 * A;
  set_forcing(c_);
  const MatrixScales& m = A.size() <= 16 ? kept_matrix_scales(A) : matrix_scales(A);
  mu_A = m.mu_A;
  first_window = m.first_window;
  scale = m.scale;
  norm_e = e.cwiseQuotient(scale.transpose()).cwiseAbs().sum();
  norm_eA2 = eA2.cwiseQuotient(scale.transpose()).cwiseAbs().sum();
  norm_eA3 = eA3.cwiseQuotient(scale.transpose()).cwiseAbs().sum();
  norm_e_plain = e.cwiseAbs().sum();
  norm_eA = eA.cwiseAbs().sum();
  norm_A = m.norm_A;
  norm_A_plain = m.norm_A_plain;
  inverse_scale = m.inverse_scale;
}

void WitnessMode::set_forcing(const SmallVector& forcing) {
  c = forcing;
  ec = e.dot(c);
  eAc = eA.dot(c);
  eA2c = eA2.dot(c);
  norm_c = c.cwiseAbs().maxCoeff();
}

namespace {

// start_rates (gap_events.hpp) for the modes' sizes by the Sampler's unrolled products (Eigen's
// order of operations, the same bits), otherwise by Eigen.
template <int N>
StartRates start_rates_of(const WitnessMode& W, const double* x) {
  double z[N];
  const double size = detail::rate_of<N>(W, x, z);
  double z0 = 0;
  for (int i = 0; i < N; ++i) z0 = std::max(z0, std::fabs(z[i] * W.scale(i)));
  return {z0, detail::dot_of<N>(W.eA, z), detail::dot_of<N>(W.eA2, z), size};
}

}  // namespace

StartRates detail::start_rates(const WitnessMode& W, const SmallVector& x0) {
  if (x0.size() == 4 && W.A.rows() == 4) return start_rates_of<4>(W, x0.data());
  if (x0.size() == 2 && W.A.rows() == 2) return start_rates_of<2>(W, x0.data());
  const SmallVector z = W.A * x0 + W.c;
  return {z.cwiseProduct(W.scale).cwiseAbs().maxCoeff(), W.eA.dot(z), W.eA2.dot(z), x0.cwiseAbs().maxCoeff()};
}

std::optional<double> certified_departure(const WitnessMode& W, const SmallVector& x0, double noise) {
  return detail::certified_departure(W, detail::start_rates(W, x0), noise);
}

std::optional<double> detail::certified_departure(const WitnessMode& W, const StartRates& r, double noise) {
  const double z0 = r.z0;          // ‖D x'(0)‖∞, ‖D x'(t)‖∞ ≤ e^{μ t} z0
  const double second = r.second;  // w''(0) = eA x'(0)
  const double third = r.third;    // w'''(0) = eA² x'(0)
  const double scale = std::max(std::fabs(second), 1e-300);
  const double growth = std::max(0.0, W.mu_A);  // ‖D x'(t)‖∞ ≤ e^{μ∞(DAD⁻¹) t} z0
  // w'' dominant: |w''(0)| > t0 sup|w'''|, sup|w'''| ≤ ‖eA²‖ e^{μ t0} z0.
  if (std::fabs(second) > 1e-12 * std::max(1.0, z0) && quadratic_resolved(second, third, W.time_unit)) {
    double t0 = std::sqrt(2 * noise / scale);
    for (int attempt = 0; attempt < 60; ++attempt, t0 *= 0.5)
      if (std::fabs(second) > t0 * W.norm_eA2 * growth_bound(growth * t0) * z0) return t0;
    return std::nullopt;
  }
  if (third == 0 || !std::isfinite(third)) return std::nullopt;
  // w''' dominant (w'' = 0): |w'''(0)| > t0 sup|w''''|, sup|w''''| ≤ ‖eA³‖ e^{μ t0} z0.
  double t0 = std::cbrt(6 * noise / std::fabs(third));
  for (int attempt = 0; attempt < 60; ++attempt, t0 *= 0.5)
    if (std::fabs(third) > t0 * W.norm_eA3 * growth_bound(growth * t0) * z0) return t0;
  return std::nullopt;
}

// The last t ≤ first_guess (halving it) with t·bound·e^{μ⁺t}·z0 ≤ limit, or 0 when it falls below t0.
double last_within(double first_guess, double t0, double bound, double growth, double z0, double limit) {
  double t1 = first_guess;
  for (int attempt = 0; attempt < 60 && t1 > t0; ++attempt, t1 *= 0.5)
    if (t1 * bound * growth_bound(growth * t1) * z0 <= limit) return t1;
  return 0;
}

namespace {

// certified_clearance's judgement of the leading term of w at the start: w''(0) (order 2) or, on
// the separation line, w'''(0) (order 3), resolved from the rounding and the noise; order 0 when
// neither is.
struct LeadingTerm {
  int order = 0, sign = 0;
};

LeadingTerm leading_term(const WitnessMode& W, const StartRates& r, double t0, double noise) {
  const double second = std::fabs(r.second), third = std::fabs(r.third);
  // The computed w''(0) is within `rounding` of the exact one (a million times its ulps).
  const double rounding = kSampleNoise * W.norm_eA * (W.norm_A_plain * r.x_size + W.norm_c);
  if (second > 1e-12 * std::max(1.0, r.z0) && quadratic_resolved(second, third, W.time_unit)) {
    if (!(second > rounding) || !(second * t0 * t0 / 4 >= noise / 8)) return {};
    return {2, r.second > 0 ? 1 : -1};
  }
  if (!std::isfinite(third) || !(third > 0) || !((second + rounding) / (2 * t0) <= third / 24) ||
      !(third * t0 * t0 * t0 / 12 >= noise / 8))
    return {};
  return {3, r.third > 0 ? 1 : -1};
}

}  // namespace

double certified_clearance(const WitnessMode& W, const SmallVector& x0, double t0, double noise) {
  return detail::certified_clearance(W, detail::start_rates(W, x0), t0, noise);
}

double detail::certified_clearance(const WitnessMode& W, const StartRates& r, double t0, double noise) {
  const double z0 = r.z0;
  const double second = std::fabs(r.second), third = std::fabs(r.third);
  const double growth = std::max(0.0, W.mu_A);
  switch (leading_term(W, r, t0, noise).order) {
    case 2:
      // w'' leads (certified_departure's first case; resolved: above its rounding, and
      // |w''(0)| t0²/4 ≥ noise/8): |w(t) − w''(0)t²/2| ≤ sup|w'''| t³/6, so |w(t)| ≥ |w''(0)| t²/4
      // while t·sup|w'''| ≤ 1.5|w''(0)|, sup|w'''| ≤ ‖eA²D⁻¹‖₁ e^{μ⁺t} z0.
      return last_within(1.5 * second / (W.norm_eA2 * z0), t0, W.norm_eA2, growth, z0, 1.5 * second);
    case 3:
      // w''' leads (the separation line, w''(0) = 0 up to rounding): |w(t) − w'''(0)t³/6| ≤
      // |w''(0)| t²/2 + sup|w''''| t⁴/24, so |w(t)| ≥ |w'''(0)| t³/12 on [t0, t] when
      // (|w''(0)| + rounding)/(2 t0) ≤ |w'''(0)|/24 and t·sup|w''''| ≤ |w'''(0)|, sup|w''''| ≤ ‖eA³D⁻¹‖₁ e^{μ⁺t} z0.
      return last_within(third / (W.norm_eA3 * z0), t0, W.norm_eA3, growth, z0, third);
    default: return 0;
  }
}

int detail::departure_sign(const WitnessMode& W, const StartRates& r, double t0, double noise) {
  return leading_term(W, r, t0, noise).sign;
}

namespace {

// The bits of a kept mode's inputs: A's shape, A, c, e and the time unit.
struct ModeKey {
  std::array<double, 16 + 4 + 4 + 1> bits{};
  Eigen::Index rows = -1, cols = -1, forcing = -1, row = -1;
  ModeKey(const SmallMatrix& A, const SmallVector& c, const SmallRow& e, double time_unit)
      : rows(A.rows()), cols(A.cols()), forcing(c.size()), row(e.size()) {
    double* at = bits.data();
    at = std::copy(A.data(), A.data() + A.size(), at);
    at = std::copy(c.data(), c.data() + c.size(), at);
    at = std::copy(e.data(), e.data() + e.size(), at);
    *at = time_unit;
  }
  bool operator==(const ModeKey& o) const {
    return rows == o.rows && cols == o.cols && forcing == o.forcing && row == o.row &&
           std::memcmp(bits.data(), o.bits.data(), sizeof bits) == 0;
  }
};

}  // namespace

WitnessMode detail::kept_witness_mode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e, double time_unit) {
  if (A.size() > 16 || c.size() > 4 || e.size() > 4) return WitnessMode(A, c, e, time_unit);
  thread_local RecentlyKept<ModeKey, WitnessMode, 4> kept;
  return kept.get(ModeKey(A, c, e, time_unit), [&] { return WitnessMode(A, c, e, time_unit); });
}

std::optional<double> certified_departure(const LinearWitness& witness, double noise) {
  return certified_departure(detail::kept_witness_mode(witness.A, witness.c, witness.e, witness.time_unit),
                             witness.state(0), noise);
}

std::optional<Crossing> first_crossing(const WitnessMode& mode, FunctionRef<WitnessSample(double)> sample, double level,
                                       double t_begin, double t_end, const CrossingOptions& options) {
  return detail::certified_first_crossing(mode, sample, level, t_begin, t_end, options);
}

std::optional<Crossing> first_crossing_after_departure(const WitnessMode& mode, FunctionRef<WitnessSample(double)> sample,
                                                       double t0, double clear_until, double t_end,
                                                       const CrossingOptions& options) {
  return detail::certified_crossing_after_departure(mode, sample, t0, clear_until, t_end, options);
}

std::optional<Crossing> first_crossing(const LinearWitness& witness, double t_begin, double t_end,
                                       const CrossingOptions& options) {
  if (!(t_end > t_begin)) return std::nullopt;
  const WitnessMode mode = detail::kept_witness_mode(witness.A, witness.c, witness.e, witness.time_unit);
  const auto sample = [&witness](double t) { return sample_of(witness, t); };
  const std::function<double(double, double)>* bound =
      witness.third_derivative_bound ? &witness.third_derivative_bound : nullptr;
  return search(Sampler<decltype(sample)>(mode, sample, witness.level), bound, t_begin, t_end, options);
}

}  // namespace backlash::numeric
