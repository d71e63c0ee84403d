// backlash/numeric/first_crossing.hpp — the first time a closed-form signal
// reaches a level, found so that no earlier crossing can be missed.
//
// Witness functions (after Drake): every event of the hybrid model is the
// first zero of a witness w(t) = eᵀx(t) − level, where x(t) is a segment's
// exact state and x' = A x + c its linear ODE:
//   gap closure   w = θL − θm − (±b or 0)     (free mode)
//   separation    w = Tc = JL·θ̈ + FL·θ̇         (contact mode)
// Sampling alone cannot guarantee the first zero (a grazing approach or a
// double crossing can hide between two samples, the failure of scipy's
// solve_ivp), so the search is certified.  Each sample gives w, w' = eᵀA x + eᵀc and
// w'' = eᵀA² x + eᵀA c from one closed-form evaluation.  With z = x' (which obeys z' = A z, so
// ‖D z(t)‖∞ ≤ e^{μ(t−a)}‖D z(a)‖∞, μ the logarithmic norm μ∞(D A D⁻¹) of the balanced A: a fast
// decaying mode does not shrink the intervals), on [a, b] (h = b − a) it bounds
//   |w'''| = |eᵀA²z| ≤ M3 = ‖eᵀA²D⁻¹‖₁ E(μ⁺h) ‖D z(a)‖∞,   E(x) ≥ e^x (an upper bound, no exp),
// then |w''| ≤ M2 and |w'| ≤ M1 on [a, b] from the end values, and
//   – excludes the interval when w(a), w(b) have one sign and either |w(a)| + |w(b)| > h·M1
//     (mean value), or, by Taylor's theorem from each end over its half, the quadratics
//     w(a) + w'(a)s + w''(a)s²/2 and w(b) − w'(b)s + w''(b)s²/2 (s ∈ [0, h/2]) keep that sign
//     clear of the remainder M3 (h/2)³/6 (the curvature is used: an interval passes at about
//     (|w|/M3)^{1/3});
//   – accepts it as monotone when w'(a), w'(b) have one sign and (|w'(a)| + |w'(b)| − h·M2)/2 > 0,
//     or the lines w'(a) + w''(a)s and w'(b) − w''(b)s keep it clear of M3 (h/2)²/2; its single
//     root (if w changes sign) is then polished by Halley's iteration on w, w', w'' inside the
//     bracket (bisection when a step leaves it), to a step whose cubic error bound
//     ((w''/2w')² + M3/(6|w'|))·|δ|³ is below a quarter of time_tolerance;
//   – otherwise bisects, always examining the left half first.
// Each test is a bound on w over the whole interval, so an interval passed over holds no zero and
// the first root found is the first root: the certificate does not depend on where the samples
// fall.  An interval that can be neither excluded nor certified down to `min_interval` is a
// grazing contact (w touches the level): it is reported as such.
//
// Cost (docs/design.md, "The event loop"): the mode's constants (eᵀA, eᵀA², μ∞, the balancing D,
// the first window) are a WitnessMode, built once per mode and parameter set; a search samples the
// closed form once per point (WitnessSample: the state and the witness's value together); the
// bisection's stack is inline.  The search runs over windows: the first has the mode's own time
// scale (WitnessMode::first_window, 4 over the mode's fastest rate), each later one twice the one
// before, so an event costs what the mode's time scale asks, whatever t_end − t_begin is; an
// interval too long for either test to pass — decided from its left end alone, with the bounds
// above — is halved without sampling its right end.  Event times agree with the earlier TOMS 748
// search (which stopped at a bracket of time_tolerance) to within that tolerance.
#pragma once

#include <Eigen/Dense>

#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace backlash::numeric {

/// Small fixed-capacity Eigen types (at most the free mode's 4 states): no heap allocation
/// in the witness searches, which evaluate states hundreds of times per event.
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;
using SmallRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 4>;

/// w(t) = eᵀx(t) − level for a linear segment x' = A x + c with exact x(t).
struct LinearWitness {
  SmallMatrix A;
  SmallVector c;
  SmallRow e;
  double level = 0;
  std::function<SmallVector(double)> state;  ///< exact x(t) (a validated closed form)
  /// Optional: w(t) + level computed directly by the closed form (e.g. the gap,
  /// free of the cancellation in θL − θm); otherwise eᵀx(t).
  std::function<double(double)> value;
  /// Optional: a bound on sup|w'''| over [a, b] tighter than ‖eᵀA²‖₁ e^{‖A‖(b−a)} ‖x'(a)‖∞ — for
  /// a stiff segment known as a sum of exponentials Σ c_j e^{λ_j t}: Σ |c_j||λ_j|³ times the
  /// larger of e^{Re λ_j t} at the ends (a decayed fast mode then bounds nothing).
  std::function<double(double, double)> third_derivative_bound;
  /// The system's time unit (segment_dynamics.hpp, servo_time_unit: √(J/K), 1 s for the thesis's
  /// cases): the floor of the root's relative tolerance and the unit of min_interval, so that a
  /// servo a million times faster is resolved as finely in its own time.
  double time_unit = 1;
};

/// A non-owning reference to a callable (like C++26 std::function_ref): no allocation, no copy.
/// The callable must outlive the reference (pass lambdas straight to the call that uses them).
template <class Signature>
class FunctionRef;
template <class R, class... Args>
class FunctionRef<R(Args...)> {
 public:
  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
  FunctionRef(const F& f) noexcept  // NOLINT: implicit, like std::function_ref
      : object_(&f), call_([](const void* o, Args... args) -> R { return (*static_cast<const F*>(o))(args...); }) {}
  R operator()(Args... args) const { return call_(object_, args...); }

 private:
  const void* object_;
  R (*call_)(const void*, Args...);
};

/// One point of a witness: the exact state x(t) and w(t) + level, from one closed-form evaluation.
struct WitnessSample {
  SmallVector x;
  double value = 0;
};

/// The constants of a witness w = eᵀx − level on a mode x' = A x + c that the certified bounds use
/// (eᵀA, eᵀA², eᵀA³, μ∞ of the balanced A, ‖eᵀA²D⁻¹‖₁ …): computed once per mode and parameter
/// set, not per search.
struct WitnessMode {
  WitnessMode(const SmallMatrix& A, const SmallVector& c, const SmallRow& e, double time_unit = 1);
  /// The forcing c and the constants that depend on it (eᵀc, eᵀA c, eᵀA² c); the rest come
  /// from A and e alone, so a mode kept for its (A, e) serves another forcing.
  void set_forcing(const SmallVector& forcing);
  SmallMatrix A;
  SmallVector c;
  SmallRow e, eA, eA2, eA3;
  SmallVector scale;  ///< D (powers of two): the bounds are in ‖D·‖∞
  double ec, eAc, eA2c;  ///< eᵀc, eᵀA c, eᵀA² c
  double mu_A;           ///< μ∞(D A D⁻¹), the growth rate of ‖D x'‖∞
  double norm_e, norm_eA2, norm_eA3;  ///< ‖eᵀD⁻¹‖₁, ‖eᵀA²D⁻¹‖₁, ‖eᵀA³D⁻¹‖₁
  double norm_e_plain, norm_eA, norm_A;  ///< ‖eᵀ‖₁, ‖eᵀA‖₁, ‖D A‖∞ (rounding scales)
  double norm_A_plain, norm_c;           ///< ‖A‖∞, ‖c‖∞ (the rounding of w''(0) at a departure)
  double inverse_scale;  ///< max 1/D_i
  double time_unit;  ///< as LinearWitness::time_unit
  double first_window;  ///< the length of a search's first window (the mode's time scale), s
};

struct Crossing {
  double t = 0;
  bool grazing = false;     ///< touched the level without crossing it
  long intervals = 0;       ///< intervals examined (cost)
};

struct CrossingOptions {
  double time_tolerance = 1e-14;  ///< the root's tolerance (Halley's last step), relative to max(t, time_unit)
  double min_interval = 1e-11;    ///< in time units: below this an uncertified interval is a grazing contact
  long max_intervals = 2'000'000; ///< guard: then SearchBudgetExhausted (never a hang)
};

/// A certified search that examined CrossingOptions::max_intervals intervals without an answer
/// (a witness oscillating far faster than the span searched).  The simulators turn it into the
/// status work_limit.
class SearchBudgetExhausted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  SearchBudgetExhausted(const std::string& what, double certified_until)
      : std::runtime_error(what), certified_until(certified_until) {}
  /// The search's own guarantee when it stopped: no crossing in (t_begin, certified_until]
  /// (−∞ when the thrower did not say).
  double certified_until = -INFINITY;
};

/// For a witness that starts at zero, w(0) = w'(0) = 0 (a gap leaving a face:
/// with w''(0) ≠ 0 after a bounce, or w''(0) = 0 and w'''(0) ≠ 0 on the
/// separation line): a time t0 > 0 such that w is certified non-zero on
/// (0, t0] (its first non-vanishing derivative keeps its sign there) and
/// |w(t0)| ≈ noise; nothing when both vanish.  A w''(0) no larger than w'''(0)
/// times 1e-12 time units is the error of the start's event time, not a leading
/// term (docs/physics.md, leaving a face).
std::optional<double> certified_departure(const LinearWitness& witness, double noise);

/// First t in (t_begin, t_end] with w(t) = 0, or nothing.
std::optional<Crossing> first_crossing(const LinearWitness& witness, double t_begin, double t_end,
                                       const CrossingOptions& options = {});

/// The same search on a mode built once: `sample(t)` gives x(t) and w(t) + `level` together
/// (one closed-form evaluation per point).  Same answers, bit for bit, as the LinearWitness form
/// with state = x and value = w + level (and no third_derivative_bound).
std::optional<Crossing> first_crossing(const WitnessMode& mode, FunctionRef<WitnessSample(double)> sample, double level,
                                       double t_begin, double t_end, const CrossingOptions& options = {});

/// certified_departure on a mode built once, from the start state x(0).
std::optional<double> certified_departure(const WitnessMode& mode, const SmallVector& x0, double noise);

/// With w(0) = w'(0) = 0 (certified_departure's t0 from the same `noise`): a time t1 ≥ t0 up to
/// which w keeps clear of zero by its leading term — |w(t)| ≥ |w''(0)| t²/4 when w''(0) leads
/// (t1·sup|w'''| ≤ 1.5 |w''(0)|), |w(t)| ≥ |w'''(0)| t³/12 on the separation line (t1·sup|w''''| ≤
/// |w'''(0)|, w''(0) within rounding of 0) — so w has no zero on [t0, t1], by at least noise/8 over
/// the closed forms' rounding; 0 when neither term is resolved.
double certified_clearance(const WitnessMode& mode, const SmallVector& x0, double t0, double noise);

/// The search from a certified departure t0 with w ≠ 0 known on [t0, clear_until]
/// (certified_clearance): the first zero in (t0, t_end], searched from clear_until (w has none
/// before it).
std::optional<Crossing> first_crossing_after_departure(const WitnessMode& mode, FunctionRef<WitnessSample(double)> sample,
                                                       double t0, double clear_until, double t_end,
                                                       const CrossingOptions& options = {});

}  // namespace backlash::numeric
