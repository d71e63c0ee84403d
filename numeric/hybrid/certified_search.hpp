// numeric/hybrid/certified_search.hpp (internal) — the certified first-crossing search of
// first_crossing.hpp, as a template over the sampler: the event loop's own samplers (a flight's
// gap, a contact's torque) are called directly, without a FunctionRef per sample.  The search,
// its bounds and its root steps are first_crossing.hpp's (the documentation is there); the
// public first_crossing() instantiates the same template with its FunctionRef, so both give
// the same answers bit for bit.
#pragma once

#include "backlash/numeric/first_crossing.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace backlash::numeric::detail {

struct Sample {
  double t, w, w1, w2, rate_norm, x_norm;  // w and its first two derivatives, ‖D x'(t)‖∞, ‖x(t)‖∞
};

// The relative size allowed for the rounding of the closed forms and of the samples' arithmetic
// when an interval is judged too long to decide from its left end (must_halve): far above the
// few ulps (times the closed forms' cancellation) they carry, so that the judgement never comes
// near the tests it anticipates.
constexpr double kSampleNoise = 1e-6;

// An upper bound on e^x for x ≥ 0, rounding included, without exp: with y = x/2^k ≤ 1/4,
// e^y ≤ 1 + y + y²/2 + 0.22 y³ (Taylor's remainder y³e^y/6 ≤ 0.214 y³), squared k times; each
// squaring at most doubles the relative rounding (≈ 2^k · 3 ulps ≤ 1.4e-15 (1 + x) in all), and
// the factor 1 + 1e-14 (1 + x) covers it.  The search's bounds only need an upper bound of the
// growth; overflow (x > 700) gives infinity, which fails every test (the interval is halved).
inline double growth_bound(double x) {
  if (!(x > 0)) return 1;
  if (!(x <= 700)) return INFINITY;
  // y = x/2^k with the fewest halvings that bring it to ≤ 1/4 (exact: powers of two).
  int k = 0;
  double y = x;
  if (y > 0.25) {  // x = (1 + f)·2^E (normal): k = E + 2, or E + 3 when f > 0; y in (1/8, 1/4]
    std::uint64_t bits;  // (std::memcpy, not std::bit_cast: the explorer's libc++ has none)
    std::memcpy(&bits, &x, sizeof bits);
    const int E = static_cast<int>(bits >> 52) - 1023;
    k = (bits & ((std::uint64_t{1} << 52) - 1)) == 0 ? E + 2 : E + 3;
    bits -= static_cast<std::uint64_t>(k) << 52;
    std::memcpy(&y, &bits, sizeof y);
  }
  double e = 1 + y * (1 + y * (0.5 + 0.22 * y));
  for (int i = 0; i < k; ++i) e *= e;
  return e * (1 + 1e-14 * (1 + x));
}

// The mode's products for its sizes, unrolled, with Eigen's own order of operations for these
// expressions (bit for bit the same: a dot product of 4 sums the products pairwise,
// (a0b0 + a2b2) + (a1b1 + a3b3); A x sums each row's products left to right, then adds c).
template <int N>
[[gnu::always_inline]] inline double dot_of(const SmallRow& row, const double* x) {
  const double* r = row.data();
  if constexpr (N == 4) return (r[0] * x[0] + r[2] * x[2]) + (r[1] * x[1] + r[3] * x[3]);
  else return r[0] * x[0] + r[1] * x[1];
}

// z = A x + c (x' at x) into z; returns ‖x‖∞.  `A` column-major N × N (Eigen's storage).  Each
// z_i sums its row's products left to right, then adds c_i; two rows at a time in one vector
// register where the compiler has them (the same operations on each lane: the same bits).
template <int N>
[[gnu::always_inline]] inline double rate_of(const double* A, const double* c, const double* x, double* z) {
#if defined(__GNUC__)
  if constexpr (N % 2 == 0) {
    typedef double Pair __attribute__((vector_size(16)));
    const auto load = [](const double* p) {
      Pair v;
      std::memcpy(&v, p, sizeof v);
      return v;
    };
    for (int i = 0; i < N; i += 2) {
      Pair zi = load(A + i) * x[0];
      for (int j = 1; j < N; ++j) zi += load(A + i + N * j) * x[j];
      zi += load(c + i);
      std::memcpy(z + i, &zi, sizeof zi);
    }
  } else
#endif
    for (int i = 0; i < N; ++i) {
      double zi = A[i] * x[0];
      for (int j = 1; j < N; ++j) zi += A[i + N * j] * x[j];
      z[i] = zi + c[i];
    }
  double size = 0;
  for (int i = 0; i < N; ++i) size = std::max(size, std::fabs(x[i]));
  return size;
}
template <int N>
[[gnu::always_inline]] inline double rate_of(const WitnessMode& m, const double* x, double* z) {
  return rate_of<N>(m.A.data(), m.c.data(), x, z);
}

// A witness on a mode, sampled through one closed-form evaluation per point: `sample(t)` (any
// callable) gives x(t) and w(t) + level.
template <class F>
class Sampler {
 public:
  Sampler(const WitnessMode& mode, const F& sample, double level) : m_(mode), sample_(sample), level_(level) {}

  const WitnessMode& mode() const { return m_; }

  // ‖D z‖∞
  double rate_norm(const SmallVector& z) const { return z.cwiseProduct(m_.scale).cwiseAbs().maxCoeff(); }

  Sample at(double t) const {
    const auto s = sample_(t);  // a WitnessSample, or any {x, value} (a view of a kept state)
    const double w = s.value - level_;
    if (s.x.size() == 4) return fixed_size<4>(t, w, s.x.data());
    if (s.x.size() == 2) return fixed_size<2>(t, w, s.x.data());
    const double w1 = m_.eA.dot(s.x) + m_.ec;
    const double w2 = m_.eA2.dot(s.x) + m_.eAc;
    const SmallVector z = m_.A * s.x + m_.c;  // x' obeys z' = A z
    return {t, w, w1, w2, rate_norm(z), s.x.cwiseAbs().maxCoeff()};
  }
  template <int N>
  Sample fixed_size(double t, double w, const double* x) const {
    double z[N];
    const double size = rate_of<N>(m_.A.data(), m_.c.data(), x, z);
    const double* scale = m_.scale.data();
    double rate = 0;
    for (int i = 0; i < N; ++i) {
      const double scaled = std::fabs(z[i] * scale[i]);
      rate = i == 0 ? scaled : std::max(rate, scaled);
    }
    return {t, w, dot_of<N>(m_.eA, x) + m_.ec, dot_of<N>(m_.eA2, x) + m_.eAc, rate, size};
  }

  double value(double t) const { return sample_(t).value - level_; }

  // An upper bound on e^{μ⁺h} (growth_bound): a few flops, no exp, for the lengths of a search.
  // The last length asked is remembered: an interval's halving test and its bounds, and the two
  // halves of a bisection, ask for the same h (the same bits, computed once).
  double growth(double h) const {
    if (h != last_h_) {
      last_h_ = h;
      last_growth_ = growth_bound(std::max(0.0, m_.mu_A) * h);
    }
    return last_growth_;
  }

  // sup |w'''| on [a.t, a.t + h]: w''' = eA² z = (eA² D⁻¹)(D z) and ‖D z(t)‖∞ ≤
  // e^{μ∞(DAD⁻¹)(t−a)} ‖D z(a)‖∞ (the supremum of e^{μ s} over s ∈ [0, h] is 1 when μ ≤ 0).
  double third_bound(const Sample& a, double h) const {
    return m_.norm_eA2 * growth(h) * a.rate_norm;
  }

  // Whether [a.t, a.t + h] is certain to be halved by the search below — neither excluded nor
  // certified monotone, whatever w does at its right end — judged from its left end alone.  With
  // E = e^{μ⁺h} and ‖D z‖ ≤ E ‖D z(a)‖ on the interval: |w'| ≤ U1 = ‖eD⁻¹‖₁ E ‖D z(a)‖∞ and
  // |w(b)| ≤ |w(a)| + h U1, while the search's own bounds are at least M2 ≥ h M3/2 and
  // M1 ≥ h² M3/4 (M3 as third_bound).  Monotone needs |w'(a)| + |w'(b)| > h M2, excluded needs
  // |w(a)| + |w(b)| > h M1: both are out of reach when twice the upper bounds (plus the samples'
  // rounding, kSampleNoise of their scale) stay below those products.  Never for an interval the
  // search would decide by its length (min_interval) or with a caller's third-derivative bound.
  // Where e^{μh} overflows the search's own bounds are infinite (or NaN) and it halves too.
  bool must_halve(const Sample& a, double h, double min_length) const {
    if (!(h >= min_length)) return false;
    const double E = growth(h);
    const double M3 = m_.norm_eA2 * E * a.rate_norm;
    if (!(M3 < INFINITY)) return true;  // the search's M2 and M1 are then infinite or NaN: no test passes
    const double rate_bound = a.rate_norm + kSampleNoise * m_.norm_A * a.x_norm;  // rounding of z = A x + c
    const double U1 = m_.norm_e * E * rate_bound;
    const double x_bound = a.x_norm + h * E * rate_bound * m_.inverse_scale;  // ≥ ‖x(t)‖∞ on the interval
    const double noise1 = kSampleNoise * (m_.norm_eA * x_bound + std::fabs(m_.ec));
    const double noise0 = kSampleNoise * (std::fabs(level_) + std::fabs(a.w) + m_.norm_e_plain * x_bound);
    const double monotone_reach = h * (0.5 * (h * M3));
    const double exclusion_reach = h * (0.5 * (h * (0.5 * (h * M3))));
    return 2 * (std::fabs(a.w1) + U1 + noise1) < monotone_reach &&
           2 * (2 * std::fabs(a.w) + h * U1 + noise0) < exclusion_reach;
  }

 private:
  const WitnessMode& m_;
  const F& sample_;
  double level_;
  mutable double last_h_ = NAN, last_growth_ = NAN;  // growth(): NaN never equals a length
};

inline bool same_sign(double x, double y) { return (x > 0 && y > 0) || (x < 0 && y < 0); }

// Whether q(s) = w0 + w1 s + w2 s²/2 keeps the sign of w0 on [0, L] with |q| > r: its smallest
// value (times that sign) is at an end or at its vertex −w1/w2.
inline bool quadratic_clear(double w0, double w1, double w2, double L, double r) {
  const double sign = w0 > 0 ? 1 : -1;
  if (!(sign * w0 > r)) return false;
  const double at_end = sign * (w0 + L * (w1 + 0.5 * L * w2));
  if (!(at_end > r)) return false;
  const double vertex = w2 != 0 ? -w1 / w2 : -1;
  return !(vertex > 0 && vertex < L) || sign * (w0 + 0.5 * vertex * w1) > r;  // q(s*) = w0 + s* w1/2
}

// The second pair of tests, by Taylor's theorem with |w'''| ≤ M3 on [a, b] (h = b − a), each half
// from its own end: on [a, a + h/2] w(a + s) = w(a) + w'(a) s + w''(a) s²/2 + ρ, |ρ| ≤ M3 (h/2)³/6,
// and w'(a + s) = w'(a) + w''(a) s + ρ', |ρ'| ≤ M3 (h/2)²/2; on [a + h/2, b] the same from b
// with s → −s.  No zero in [a, b] when both quadratics keep one sign clear of ρ; w monotone when
// both lines do.  The curvature is used, so an interval passes at about (|w|/M3)^{1/3}, where
// the mean-value tests above need |w| > h·M1 with M1 ≳ |w'| + h|w''|.
inline bool taylor_excluded(const Sample& a, const Sample& b, double h, double M3) {
  const double L = 0.5 * h, rho = M3 * L * L * L / 6;
  return same_sign(a.w, b.w) && quadratic_clear(a.w, a.w1, a.w2, L, rho) && quadratic_clear(b.w, -b.w1, b.w2, L, rho);
}

inline bool taylor_monotone(const Sample& a, const Sample& b, double h, double M3) {
  const double L = 0.5 * h, rho = M3 * L * L / 2;
  const auto clear = [rho, L](double d, double dd) {
    const double sign = d > 0 ? 1 : -1;
    return sign * d > rho && sign * (d + L * dd) > rho;
  };
  return same_sign(a.w1, b.w1) && clear(a.w1, a.w2) && clear(b.w1, -b.w2);
}

// A right end of the search's intervals; a lazy one (known = false) has only its time, and is
// sampled when a test needs it.
struct End {
  Sample s;
  bool known;
};

inline Sample lazy(double t) { return {t, 0, 0, 0, 0, 0}; }

// The search's stack of right ends: 96 inline (a bisection 96 levels below a window), a heap
// vector only beyond — no allocation and no out-of-line growth check per interval.
class EndStack {
 public:
  bool empty() const { return size_ == 0; }
  End& back() { return size_ <= kInline ? inline_[size_ - 1] : spill_.back(); }
  [[gnu::always_inline]] void push_back(const End& end) {
    if (size_ < kInline) inline_[size_] = end;
    else spill_.push_back(end);
    ++size_;
  }
  void pop_back() {
    if (size_ > kInline) spill_.pop_back();
    --size_;
  }

 private:
  static constexpr std::size_t kInline = 96;
  std::size_t size_ = 0;
  End inline_[kInline];
  std::vector<End> spill_;
};

// The root of w in [a, b]: a sign change, w monotone there (certified: the root is unique) or the
// interval at the resolution.  Halley's iteration on the samples' w, w', w'' (one closed-form
// evaluation per step), from the end nearer the root, kept inside the bracket (bisection when a
// step leaves it).  A Halley step δ from t leaves an error of at most about K|δ|³ with
// K = (w''/2w')² + sup|w'''|/(6|w'|) near t (the cubic term of its error), so the step is taken
// without a further sample once 2K|δ|³ is below a quarter of the tolerance (time_tolerance
// relative to max(t, time_unit)), or once |δ| itself is (the witness's rounding then decides).
template <class F>
double root_in(const Sampler<F>& W, const Sample& a, const Sample& b, const CrossingOptions& options) {
  const double tolerance = options.time_tolerance, unit = W.mode().time_unit;
  double lo = a.t, hi = b.t;
  const bool rising = a.w < 0;  // w < 0 left of the root when rising
  Sample s = std::fabs(a.w) <= std::fabs(b.w) ? a : b;
  for (int iteration = 0; iteration < 200; ++iteration) {
    double step = NAN;
    if (s.w1 != 0) {
      const double newton = -s.w / s.w1;
      const double correction = 1 + 0.5 * newton * s.w2 / s.w1;  // Halley: 1 − w w″/(2w′²)
      step = correction > 0.5 && correction < 2 ? newton / correction : newton;
    }
    const double width = tolerance * std::max(unit, std::fabs(s.t));
    if (std::fabs(step) <= 0.25 * width) return s.t + step;
    const double next = s.t + step;
    if (next > lo && next < hi) {
      // The test is monotone in K (each rounded operation is): when it fails on K's first term
      // alone it fails on K, and sup|w'''| (its growth bound) is not needed.
      const auto within = [step, width](double K) { return 2 * K * std::fabs(step) * step * step <= 0.25 * width; };
      const double curvature = 0.5 * s.w2 / s.w1;
      if (within(curvature * curvature) &&
          within(curvature * curvature + W.third_bound(s, std::fabs(step)) / (6 * std::fabs(s.w1))))
        return next;
    } else {
      const double mid = 0.5 * (lo + hi);
      if (hi - lo <= width) return mid;
      step = mid - s.t;
    }
    s = W.at(s.t + step);
    if (s.w == 0) return s.t;
    ((s.w < 0) == rising ? lo : hi) = s.t;
  }
  return 0.5 * (lo + hi);
}

// Depth-first, left half first, over windows: the first from t_begin has the mode's own length
// (WitnessMode::first_window), each later one twice the one before, the last ending at t_end, so
// a search's cost depends on the mode's time scale, not on t_end − t_begin (a search that meets
// no crossing spends log₂ of the span over the first window on windows).  Within a window the
// intervals still to examine tile [a, window's end] from the left, so they are kept as their right
// ends (a stack whose top is the nearest) and the current left end a: an interval decided hands its
// right end on as the next left end; a halved one pushes its midpoint.  Inline storage: no
// allocation unless the bisection goes deeper than 96 levels.  With `clear_until`
// (certified_clearance: w ≠ 0 on [t_begin, clear_until]) the search starts at clear_until.
template <class F>
std::optional<Crossing> search(const Sampler<F>& W, const std::function<double(double, double)>* third_derivative_bound,
                               double t_begin, double t_end, const CrossingOptions& options,
                               double clear_until = -INFINITY) {
  if (clear_until > t_begin) t_begin = std::min(clear_until, t_end);
  if (!(t_end > t_begin)) return std::nullopt;
  const double min_length = options.min_interval * W.mode().time_unit;
  long examined = 0;
  EndStack ends;
  Sample a = W.at(t_begin);
  double window = W.mode().first_window;
  while (a.t < t_end) {
    ends.push_back({lazy(t_end - a.t <= window ? t_end : a.t + window), false});
    window *= 2;
    while (!ends.empty()) {
      if (++examined > options.max_intervals)
        throw SearchBudgetExhausted("the certified event search exhausted its budget of " +
                                        std::to_string(options.max_intervals) + " intervals",
                                    a.t);  // every interval left of a is decided: no crossing there
      End& end = ends.back();
      Sample& b = end.s;
      const double h = b.t - a.t;
      const bool halve = !end.known && !third_derivative_bound && std::isfinite(a.w) && W.must_halve(a, h, min_length);
      if (!halve && !end.known) {
        b = W.at(b.t);
        end.known = true;
      }
      if (!std::isfinite(a.w) || (!halve && !std::isfinite(b.w))) throw std::runtime_error("first_crossing: non-finite witness");
      // (a is never a root after t_begin: it is t_begin's sample or a right end passed on, and an
      // end is passed on only without a sign change, so with w ≠ 0 there.)
      if (halve) {
        ends.push_back({lazy(a.t + 0.5 * h), false});
        continue;
      }
      const double M3 = third_derivative_bound ? (*third_derivative_bound)(a.t, b.t) : W.third_bound(a, h);
      const double M2 = 0.5 * (std::fabs(a.w2) + std::fabs(b.w2) + h * M3);
      const double M1 = 0.5 * (std::fabs(a.w1) + std::fabs(b.w1) + h * M2);
      const bool sign_change = !same_sign(a.w, b.w);
      const bool excluded =
          !sign_change && (std::fabs(a.w) + std::fabs(b.w) > h * M1 || taylor_excluded(a, b, h, M3));
      const bool monotone = !excluded && same_sign(a.w1, b.w1) &&
                            (0.5 * (std::fabs(a.w1) + std::fabs(b.w1) - h * M2) > 0 || taylor_monotone(a, b, h, M3));
      if (!excluded && (monotone || h < min_length)) {
        if (sign_change) {
          if (b.w == 0) return Crossing{b.t, false, examined};
          return Crossing{root_in(W, a, b, options), false, examined};
        }
        // Uncertified down to the resolution: the witness touches the level here.
        if (!monotone) return Crossing{std::fabs(a.w) <= std::fabs(b.w) ? a.t : b.t, true, examined};
      }
      if (excluded || monotone) {  // no root in [a, b] (monotone without a sign change): on to the next interval
        a = b;
        ends.pop_back();
        continue;
      }
      ends.push_back({W.at(a.t + 0.5 * h), true});
    }
  }
  return std::nullopt;
}

/// first_crossing(mode, sample, level, t_begin, t_end) with `sample` any callable (double) → WitnessSample.
template <class F>
std::optional<Crossing> certified_first_crossing(const WitnessMode& mode, const F& sample, double level, double t_begin,
                                                 double t_end, const CrossingOptions& options = {}) {
  return search(Sampler<F>(mode, sample, level), nullptr, t_begin, t_end, options);
}

/// first_crossing_after_departure(mode, sample, t0, clear_until, t_end) with `sample` any callable.
template <class F>
std::optional<Crossing> certified_crossing_after_departure(const WitnessMode& mode, const F& sample, double t0,
                                                           double clear_until, double t_end,
                                                           const CrossingOptions& options = {}) {
  return search(Sampler<F>(mode, sample, 0), nullptr, t0, t_end, options, clear_until);
}

}  // namespace backlash::numeric::detail
